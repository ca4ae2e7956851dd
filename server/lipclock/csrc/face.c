/* Mouth-motion inner loops: spring integration (face/spring.py), bigram curve
 * stitching and slope limiting (face/bigram.py), node speed limit (face/models.py). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"

/* Python's max(a, b) and min(a, b): the first argument unless the second is larger
 * (smaller); kept so signed zeros come out as in the reference code. */
#define PY_MAX(a, b) ((b) > (a) ? (b) : (a))
#define PY_MIN(a, b) ((b) < (a) ? (b) : (a))

/* A node's (x, y) as one 2-lane vector: each lane does exactly the scalar arithmetic
 * (IEEE, no fused multiply-add), two coordinates per instruction. */
typedef double xy __attribute__((vector_size(16)));

/* Step the mesh; after each step record the pose for every frame whose position
 * (in steps) is at most half a step past it; frames beyond the last step hold the
 * final pose. Arrays are flat x0, y0, x1, y1, ...
 * Per viseme, the stiffness and damping of every node (closure visemes switch the lip
 * nodes) and the target offset along every edge are tabulated once, so a step only
 * reads them. */
int spring_integrate(const spring_args *a, double *out) {
    const int64_t n = a->n_nodes, n_vis = a->n_visemes, n_edges = a->n_edges;
    const size_t n_vec = (size_t)(4 * n + 3 * n * n_vis + n_edges * n_vis);
    xy *scratch = aligned_alloc(sizeof(xy), sizeof(xy) * n_vec);
    if (scratch == NULL) return -1;
    xy *x = scratch, *v = x + n, *f = v + n, *inv_m = f + n;
    xy *target = inv_m + n, *stiff = target + n * n_vis, *damp = stiff + n * n_vis;
    xy *edge_rest = damp + n * n_vis; /* target[j] - target[i] per viseme and edge */
    for (int64_t i = 0; i < n; i++) {
        x[i] = (xy){a->rest[2 * i], a->rest[2 * i + 1]};
        v[i] = (xy){0.0, 0.0};
        const double q = a->dt / a->mass[i];
        inv_m[i] = (xy){q, q};
    }
    for (int64_t vi = 0; vi < n_vis; vi++) {
        const double *t = a->targets + vi * 2 * n;
        const int closing = a->closure[vi] != 0;
        for (int64_t i = 0; i < n; i++) {
            const double k = closing && a->lips[i] ? a->k_cl : a->k[i];
            const double c = closing && a->lips[i] ? a->c_cl : a->c[i];
            target[vi * n + i] = (xy){t[2 * i], t[2 * i + 1]};
            stiff[vi * n + i] = (xy){k, k};
            damp[vi * n + i] = (xy){c, c};
        }
        for (int64_t e = 0; e < n_edges; e++) {
            const int64_t i = a->edges[2 * e], j = a->edges[2 * e + 1];
            edge_rest[vi * n_edges + e] = (xy){t[2 * j] - t[2 * i],
                                               t[2 * j + 1] - t[2 * i + 1]};
        }
    }
    const int64_t *restrict edges = a->edges, *restrict pairs = a->lip_pairs;
    const double *restrict frame_pos = a->frame_pos;
    const int64_t n_pairs = a->n_pairs, n_frames = a->n_frames, row = 2 * n;
    const xy k_nb = {a->k_nb, a->k_nb}, dt = {a->dt, a->dt};
    int64_t fi = 0;
    for (int64_t s = 0; s < a->n_steps; s++) {
        const int64_t vi = a->vis_idx[s];
        const xy *restrict t = target + vi * n, *restrict k = stiff + vi * n;
        const xy *restrict c = damp + vi * n, *restrict d = edge_rest + vi * n_edges;
        for (int64_t i = 0; i < n; i++) f[i] = k[i] * (t[i] - x[i]) - c[i] * v[i];
        for (int64_t e = 0; e < n_edges; e++) {
            const int64_t i = edges[2 * e], j = edges[2 * e + 1];
            const xy pull = k_nb * ((x[j] - x[i]) - d[e]);
            f[i] += pull;
            f[j] -= pull;
        }
        for (int64_t i = 0; i < n; i++) {
            v[i] += f[i] * inv_m[i];
            x[i] += v[i] * dt;
        }
        for (int64_t p = 0; p < n_pairs; p++) { /* the inner lips touch; never cross */
            const int64_t u = pairs[2 * p], lo = pairs[2 * p + 1]; /* [1]: the y lane */
            if (x[lo][1] > x[u][1]) {
                const double mid = 0.5 * (x[lo][1] + x[u][1]);
                x[lo][1] = mid;
                x[u][1] = mid;
                const double vm = 0.5 * (v[lo][1] + v[u][1]);
                v[lo][1] = vm;
                v[u][1] = vm;
            }
        }
        for (; fi < n_frames && frame_pos[fi] <= (double)s + 0.5; fi++)
            memcpy(out + fi * row, x, sizeof(double) * (size_t)row);
    }
    for (; fi < n_frames; fi++) memcpy(out + fi * row, x, sizeof(double) * (size_t)row);
    free(scratch);
    return 0;
}

/* Pair i spans phones i and i+1 (bounds[i]..bounds[i+2]); the left phone maps to
 * u in [0, 0.5), the right one to [0.5, 1]. Knot arrays are n_pose x n_knot per key;
 * pose_id < 0 marks padding. w is n_poses x n_fs, raised to each curve's value. */
void bigram_stitch(const double *fs, int64_t n_fs, const double *bounds, const int64_t *ids,
                   int64_t n_ids, const int64_t *pose_id, const double *ku, const double *kw,
                   const int64_t *nk, int64_t n_pose, int64_t n_knot, double *w) {
    int64_t k0 = 0;
    for (int64_t i = 0; i < n_ids; i++) {
        double a0 = bounds[i], b0 = bounds[i + 1], b1 = bounds[i + 2];
        while (k0 < n_fs && fs[k0] < a0) k0++;
        for (int64_t k = k0; k < n_fs && fs[k] < b1; k++) {
            double t = fs[k], u;
            if (t < b0)
                u = 0.5 * (t - a0) / PY_MAX(b0 - a0, 1.0);
            else
                u = 0.5 + 0.5 * (t - b0) / PY_MAX(b1 - b0, 1.0);
            for (int64_t j = 0; j < n_pose; j++) {
                int64_t row = ids[i] * n_pose + j;
                int64_t p = pose_id[row];
                if (p < 0) continue;
                const double *us = ku + row * n_knot, *ws = kw + row * n_knot;
                int64_t m = 1;
                while (m < nk[row] - 1 && us[m] < u) m++;
                double x = PY_MIN(PY_MAX((u - us[m - 1]) / (us[m] - us[m - 1]), 0.0), 1.0);
                double val = ws[m - 1] + (ws[m] - ws[m - 1]) * x;
                if (val > w[p * n_fs + k]) w[p * n_fs + k] = val;
            }
        }
    }
}

void bigram_speed_limit(double *w, int64_t n, double step) {
    for (int64_t k = 1; k < n; k++)
        w[k] = PY_MAX(w[k], w[k - 1] - step);
    for (int64_t k = n - 2; k >= 0; k--)
        w[k] = PY_MAX(w[k], w[k + 1] - step);
}

void limit_node_speed(double *nodes, int64_t n_frames, int64_t n_nodes, double max_step) {
    const int64_t row = 2 * n_nodes;
    for (int64_t k = 1; k < n_frames; k++) {
        const double *prev = nodes + (k - 1) * row;
        double *cur = nodes + k * row;
        for (int64_t i = 0; i < n_nodes; i++) {
            double dx = cur[2 * i] - prev[2 * i];
            double dy = cur[2 * i + 1] - prev[2 * i + 1];
            double d = sqrt(dx * dx + dy * dy);
            if (d > max_step) {
                double f = max_step / d;
                cur[2 * i] = prev[2 * i] + dx * f;
                cur[2 * i + 1] = prev[2 * i + 1] + dy * f;
            }
        }
    }
}
