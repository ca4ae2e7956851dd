/* Mouth-motion inner loops: spring integration (face/spring.py), bigram curve
 * stitching and slope limiting (face/bigram.py), node speed limit (face/models.py). */
#include <math.h>
#include <stdlib.h>

#include "kernels.h"

/* Python's max(a, b) and min(a, b): the first argument unless the second is larger
 * (smaller); kept so signed zeros come out as in the reference code. */
#define PY_MAX(a, b) ((b) > (a) ? (b) : (a))
#define PY_MIN(a, b) ((b) < (a) ? (b) : (a))

/* Step the mesh; after each step record the pose for every frame whose position
 * (in steps) is at most half a step past it; frames beyond the last step hold the
 * final pose. Arrays are flat x0, y0, x1, y1, ... */
int spring_integrate(const spring_args *a, double *out) {
    const int64_t n = a->n_nodes, m2 = 2 * n;
    double *scratch = malloc(sizeof(double) * (size_t)(8 * m2 + 1));
    if (scratch == NULL) return -1;
    double *x = scratch, *v = x + m2, *f = v + m2, *inv_m = f + m2;
    double *k_open = inv_m + m2, *c_open = k_open + m2;
    double *k_close = c_open + m2, *c_close = k_close + m2;
    for (int64_t i = 0; i < n; i++) {
        for (int ax = 0; ax < 2; ax++) {
            int64_t j = 2 * i + ax;
            x[j] = a->rest[j];
            v[j] = 0.0;
            inv_m[j] = a->dt / a->mass[i];
            k_open[j] = a->k[i];
            c_open[j] = a->c[i];
            k_close[j] = a->lips[i] ? a->k_cl : a->k[i];
            c_close[j] = a->lips[i] ? a->c_cl : a->c[i];
        }
    }
    /* struct fields in locals and restrict-qualified arrays: the compiler may then keep
     * them in registers instead of reloading after every store to f, x or v */
    double *restrict xr = x, *restrict vr = v, *restrict fr = f;
    const double *restrict im = inv_m;
    const int64_t *restrict edges = a->edges, *restrict vis_idx = a->vis_idx;
    const int64_t *restrict pairs = a->lip_pairs;
    const uint8_t *restrict closure = a->closure;
    const double *restrict targets = a->targets, *restrict frame_pos = a->frame_pos;
    const int64_t n_edges = a->n_edges, n_pairs = a->n_pairs, n_frames = a->n_frames;
    const double k_nb = a->k_nb, dt = a->dt;
    int64_t fi = 0;
    for (int64_t s = 0; s < a->n_steps; s++) {
        int64_t vi = vis_idx[s];
        const double *restrict t = targets + vi * m2;
        const double *restrict ks = closure[vi] ? k_close : k_open;
        const double *restrict cs = closure[vi] ? c_close : c_open;
        for (int64_t j = 0; j < m2; j++) fr[j] = ks[j] * (t[j] - xr[j]) - cs[j] * vr[j];
        for (int64_t e = 0; e < n_edges; e++) {
            int64_t i2 = 2 * edges[2 * e], j2 = 2 * edges[2 * e + 1];
            for (int ax = 0; ax < 2; ax++) {
                double stretch = (xr[j2 + ax] - xr[i2 + ax]) - (t[j2 + ax] - t[i2 + ax]);
                fr[i2 + ax] += k_nb * stretch;
                fr[j2 + ax] -= k_nb * stretch;
            }
        }
        for (int64_t j = 0; j < m2; j++) {
            vr[j] += fr[j] * im[j];
            xr[j] += vr[j] * dt;
        }
        for (int64_t p = 0; p < n_pairs; p++) { /* the inner lips touch; never cross */
            int64_t u = 2 * pairs[2 * p] + 1, lo = 2 * pairs[2 * p + 1] + 1;
            if (xr[lo] > xr[u]) {
                double mid = 0.5 * (xr[lo] + xr[u]);
                xr[lo] = mid;
                xr[u] = mid;
                double vm = 0.5 * (vr[lo] + vr[u]);
                vr[lo] = vm;
                vr[u] = vm;
            }
        }
        for (; fi < n_frames && frame_pos[fi] <= (double)s + 0.5; fi++)
            for (int64_t j = 0; j < m2; j++) out[fi * m2 + j] = xr[j];
    }
    for (; fi < a->n_frames; fi++)
        for (int64_t j = 0; j < m2; j++) out[fi * m2 + j] = x[j];
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
