/* lipclock._kernels: CPython glue for the compiled inner loops (kernels.h).
 *
 * Arrays arrive through the buffer protocol as flat, C-contiguous bytes ("y*" read,
 * "w*" written in place); shapes are derived from byte sizes. The Python wrappers
 * fix dtypes and contiguity; this layer still checks every size and index the loops
 * rely on and raises ValueError instead of reading out of bounds. The loops run with
 * the GIL released, so synthesis threads can overlap.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>

#include "kernels.h"

#define D sizeof(double)
#define I sizeof(int64_t)

static void release(Py_buffer *bufs, int n) {
    for (int i = 0; i < n; i++) PyBuffer_Release(&bufs[i]);
}

static PyObject *fail(Py_buffer *bufs, int n, const char *msg) {
    release(bufs, n);
    PyErr_SetString(PyExc_ValueError, msg);
    return NULL;
}

/* The byte length is a whole number of `item`-sized elements (item: a multiple of 8
 * bytes, or 1), and the data is aligned for 8-byte numbers. */
static int whole(const Py_buffer *b, size_t item) {
    if ((size_t)b->len % item != 0) return 0;
    return item == 1 || (uintptr_t)b->buf % 8 == 0;
}

static int indices_below(const int64_t *v, Py_ssize_t n, int64_t stride, int64_t limit) {
    for (Py_ssize_t i = 0; i < n; i += stride)
        if (v[i] < 0 || v[i] >= limit) return 0;
    return 1;
}

PyDoc_STRVAR(klatt_render_doc,
"klatt_render(frames, n_par, sample_rate, start, end, state, voice, out)\n--\n\n"
"Render samples [start, end) of float64 frames (n_frames x n_par, n_frames >= 2) into\n"
"float64 out (at least end - start items), updating the float64 state vector.");

static PyObject *py_klatt_render(PyObject *self, PyObject *args) {
    Py_buffer b[4];
    Py_ssize_t n_par;
    long long sr, start, end;
    if (!PyArg_ParseTuple(args, "y*nLLLw*y*w*", &b[0], &n_par, &sr, &start, &end, &b[1],
                          &b[2], &b[3]))
        return NULL;
    if (n_par < K_N_PARAMS || !whole(&b[0], D * (size_t)n_par))
        return fail(b, 4, "frames must be float64 with at least 28 parameters per frame");
    int64_t n_frames = b[0].len / (Py_ssize_t)(D * (size_t)n_par);
    if (n_frames < 2) return fail(b, 4, "need at least 2 frames");
    if (sr <= 0 || start < 0 || end < start) return fail(b, 4, "bad sample rate or range");
    if (!whole(&b[1], D) || b[1].len != (Py_ssize_t)(D * K_STATE_SIZE))
        return fail(b, 4, "state must be float64 of the renderer's state size");
    if (!whole(&b[2], D) || b[2].len < (Py_ssize_t)(D * K_N_VOICE))
        return fail(b, 4, "voice must be float64 (breathiness, flutter, formant scale)");
    if (!whole(&b[3], D) || b[3].len / (Py_ssize_t)D < end - start)
        return fail(b, 4, "out is shorter than end - start");
    double *state = b[1].buf;
    if (!(state[KS_SEED] >= 0.0 && state[KS_SEED] < 2147483648.0) ||
        !(state[KS_QUIET] >= 0.0 && state[KS_QUIET] < 4.0e18))
        return fail(b, 4, "corrupt renderer state");
    Py_BEGIN_ALLOW_THREADS
    klatt_render(b[0].buf, n_frames, n_par, sr, start, end, state, b[2].buf, b[3].buf);
    Py_END_ALLOW_THREADS
    release(b, 4);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(spring_integrate_doc,
"spring_integrate(vis_idx, targets, closure, rest, mass, k, c, k_cl, c_cl, lips, edges,\n"
"                 k_nb, lip_pairs, dt, frame_pos, out)\n--\n\n"
"Integrate the mouth springs (face/spring.py) into float64 out (n_frames x N x 2).\n"
"int64: vis_idx, edges (E x 2), lip_pairs (P x 2); bool: closure, lips; the rest float64.");

static PyObject *py_spring_integrate(PyObject *self, PyObject *args) {
    Py_buffer b[12];
    spring_args a;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*y*ddy*y*dy*dy*w*", &b[0], &b[1], &b[2], &b[3],
                          &b[4], &b[5], &b[6], &a.k_cl, &a.c_cl, &b[7], &b[8], &a.k_nb, &b[9],
                          &a.dt, &b[10], &b[11]))
        return NULL;
    const int nb = 12;
    if (!whole(&b[3], 2 * D) || b[3].len == 0) return fail(b, nb, "rest must be N x 2 float64");
    a.n_nodes = b[3].len / (Py_ssize_t)(2 * D);
    const size_t pose = 2 * D * (size_t)a.n_nodes;
    if (!whole(&b[1], D) || (size_t)b[1].len % pose != 0)
        return fail(b, nb, "targets must be V x N x 2 float64");
    a.n_visemes = (int64_t)((size_t)b[1].len / pose);
    if (b[2].len != a.n_visemes) return fail(b, nb, "closure must be V bools");
    for (int i = 4; i <= 6; i++)
        if (!whole(&b[i], D) || b[i].len != (Py_ssize_t)(D * (size_t)a.n_nodes))
            return fail(b, nb, "mass, k and c must be N float64");
    if (b[7].len != a.n_nodes) return fail(b, nb, "lips must be N bools");
    if (!whole(&b[0], I) || !whole(&b[8], 2 * I) || !whole(&b[9], 2 * I))
        return fail(b, nb, "vis_idx, edges and lip_pairs must be int64 (edges, pairs: E x 2)");
    a.n_steps = b[0].len / (Py_ssize_t)I;
    a.n_edges = b[8].len / (Py_ssize_t)(2 * I);
    a.n_pairs = b[9].len / (Py_ssize_t)(2 * I);
    if (!indices_below(b[0].buf, a.n_steps, 1, a.n_visemes))
        return fail(b, nb, "vis_idx out of range");
    if (!indices_below(b[8].buf, 2 * a.n_edges, 1, a.n_nodes) ||
        !indices_below(b[9].buf, 2 * a.n_pairs, 1, a.n_nodes))
        return fail(b, nb, "node index out of range in edges or lip_pairs");
    if (!whole(&b[10], D)) return fail(b, nb, "frame_pos must be float64");
    a.n_frames = b[10].len / (Py_ssize_t)D;
    if (!whole(&b[11], D) || (size_t)b[11].len != pose * (size_t)a.n_frames)
        return fail(b, nb, "out must be n_frames x N x 2 float64");
    a.vis_idx = b[0].buf;
    a.targets = b[1].buf;
    a.closure = b[2].buf;
    a.rest = b[3].buf;
    a.mass = b[4].buf;
    a.k = b[5].buf;
    a.c = b[6].buf;
    a.lips = b[7].buf;
    a.edges = b[8].buf;
    a.lip_pairs = b[9].buf;
    a.frame_pos = b[10].buf;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = spring_integrate(&a, b[11].buf);
    Py_END_ALLOW_THREADS
    release(b, nb);
    if (rc != 0) return PyErr_NoMemory();
    Py_RETURN_NONE;
}

PyDoc_STRVAR(bigram_stitch_doc,
"bigram_stitch(fs, bounds, ids, pose_id, ku, kw, nk, n_pose, w)\n--\n\n"
"Max-stitch each phone pair's warped curves into w (n_poses x len(fs), float64, in place).\n"
"fs, bounds (len(ids) + 2), ku, kw (K x n_pose x n_knot) float64; ids, pose_id, nk int64.");

static PyObject *py_bigram_stitch(PyObject *self, PyObject *args) {
    Py_buffer b[8];
    Py_ssize_t n_pose;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*y*nw*", &b[0], &b[1], &b[2], &b[3], &b[4], &b[5],
                          &b[6], &n_pose, &b[7]))
        return NULL;
    const int nb = 8;
    if (!whole(&b[0], D) || !whole(&b[1], D) || !whole(&b[4], D) || !whole(&b[5], D) ||
        !whole(&b[7], D))
        return fail(b, nb, "fs, bounds, ku, kw and w must be float64");
    if (!whole(&b[2], I) || !whole(&b[3], I) || !whole(&b[6], I))
        return fail(b, nb, "ids, pose_id and nk must be int64");
    int64_t n_fs = b[0].len / (Py_ssize_t)D, n_ids = b[2].len / (Py_ssize_t)I;
    int64_t n_rows_k = b[3].len / (Py_ssize_t)I; /* keys x n_pose */
    if (n_pose < 1 || n_rows_k % n_pose != 0 || b[6].len != b[3].len || b[4].len != b[5].len)
        return fail(b, nb, "pose_id and nk must be K x n_pose; ku and kw alike");
    int64_t n_keys = n_rows_k / n_pose;
    if (n_ids == 0 || n_fs == 0) {
        release(b, nb);
        Py_RETURN_NONE;
    }
    if (b[1].len / (Py_ssize_t)D < n_ids + 2) return fail(b, nb, "bounds needs len(ids) + 2");
    if (n_rows_k == 0 || b[4].len / (Py_ssize_t)D % n_rows_k != 0)
        return fail(b, nb, "ku must be K x n_pose x n_knot");
    int64_t n_knot = b[4].len / (Py_ssize_t)D / n_rows_k;
    if (b[7].len / (Py_ssize_t)D % n_fs != 0) return fail(b, nb, "w must be n_poses x len(fs)");
    int64_t n_w = b[7].len / (Py_ssize_t)D / n_fs;
    if (!indices_below(b[2].buf, n_ids, 1, n_keys)) return fail(b, nb, "ids out of range");
    const int64_t *pid = b[3].buf, *nk = b[6].buf;
    for (int64_t r = 0; r < n_rows_k; r++)
        if (pid[r] >= 0 && (pid[r] >= n_w || nk[r] < 2 || nk[r] > n_knot))
            return fail(b, nb, "pose_id or knot count out of range");
    Py_BEGIN_ALLOW_THREADS
    bigram_stitch(b[0].buf, n_fs, b[1].buf, b[2].buf, n_ids, pid, b[4].buf, b[5].buf, nk,
                  n_pose, n_knot, b[7].buf);
    Py_END_ALLOW_THREADS
    release(b, nb);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(bigram_speed_limit_doc,
"bigram_speed_limit(w, step)\n--\n\n"
"In place on float64 w: every weight >= its neighbour's minus step (slope-limited dilation).");

static PyObject *py_bigram_speed_limit(PyObject *self, PyObject *args) {
    Py_buffer b[1];
    double step;
    if (!PyArg_ParseTuple(args, "w*d", &b[0], &step)) return NULL;
    if (!whole(&b[0], D)) return fail(b, 1, "w must be float64");
    Py_BEGIN_ALLOW_THREADS
    bigram_speed_limit(b[0].buf, b[0].len / (Py_ssize_t)D, step);
    Py_END_ALLOW_THREADS
    release(b, 1);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(limit_node_speed_doc,
"limit_node_speed(nodes, n_nodes, max_step)\n--\n\n"
"In place on float64 nodes (n_frames x n_nodes x 2): each node moves at most max_step\n"
"between frames, following late instead.");

static PyObject *py_limit_node_speed(PyObject *self, PyObject *args) {
    Py_buffer b[1];
    Py_ssize_t n_nodes;
    double max_step;
    if (!PyArg_ParseTuple(args, "w*nd", &b[0], &n_nodes, &max_step)) return NULL;
    if (n_nodes < 1 || !whole(&b[0], D) || (size_t)b[0].len % (2 * D * (size_t)n_nodes) != 0)
        return fail(b, 1, "nodes must be n_frames x n_nodes x 2 float64");
    int64_t n_frames = b[0].len / (Py_ssize_t)(2 * D * (size_t)n_nodes);
    Py_BEGIN_ALLOW_THREADS
    limit_node_speed(b[0].buf, n_frames, n_nodes, max_step);
    Py_END_ALLOW_THREADS
    release(b, 1);
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"klatt_render", py_klatt_render, METH_VARARGS, klatt_render_doc},
    {"spring_integrate", py_spring_integrate, METH_VARARGS, spring_integrate_doc},
    {"bigram_stitch", py_bigram_stitch, METH_VARARGS, bigram_stitch_doc},
    {"bigram_speed_limit", py_bigram_speed_limit, METH_VARARGS, bigram_speed_limit_doc},
    {"limit_node_speed", py_limit_node_speed, METH_VARARGS, limit_node_speed_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "lipclock._kernels",
    "Compiled inner loops: Klatt synthesis, mouth springs, bigram curves, node speed limit.",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__kernels(void) {
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && PyModule_AddIntConstant(m, "KLATT_STATE_SIZE", K_STATE_SIZE) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
