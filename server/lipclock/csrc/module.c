/* lipclock._kernels: CPython glue for the compiled inner loops (kernels.h).
 *
 * Arrays arrive through the buffer protocol and must be C-contiguous with the exact
 * item type the loop reads (float64 'd', int64 'q'/'l', bool '?'): anything else is a
 * TypeError, a wrong size or an out-of-range index a ValueError, never an out-of-bounds
 * read. The Python wrappers convert dtypes first, so in normal use nothing is rejected.
 * The loops run with the GIL released so synthesis threads can overlap; everything a
 * loop uses as an index (renderer state, node and curve indices) is copied and checked
 * before the GIL is released, so another thread writing to the caller's arrays
 * meanwhile can change values but never send the loop out of bounds.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <string.h>

#include "kernels.h"

#define D ((Py_ssize_t)sizeof(double))
#define I ((Py_ssize_t)sizeof(int64_t))

enum { F64, I64, BOOL };
static const char *const kind_name[] = {"float64", "int64", "bool"};

/* Buffers taken so far by one call; all released together. */
typedef struct {
    Py_buffer v[16];
    int n;
} bufs;

static void release(bufs *b) {
    while (b->n > 0) PyBuffer_Release(&b->v[--b->n]);
}

static PyObject *fail(bufs *b, const char *msg) {
    release(b);
    PyErr_SetString(PyExc_ValueError, msg);
    return NULL;
}

static int native_order(char c) {
#if PY_LITTLE_ENDIAN
    return c == '@' || c == '=' || c == '<';
#else
    return c == '@' || c == '=' || c == '>' || c == '!';
#endif
}

/* Take a C-contiguous buffer of `kind` items from obj (writable if asked); returns its
 * data, or NULL with TypeError/BufferError set (and everything taken so far released). */
static void *take(bufs *b, PyObject *obj, int kind, int writable, const char *name) {
    Py_buffer *v = &b->v[b->n];
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, v, flags) < 0) {
        release(b);
        return NULL;
    }
    b->n++;
    const char *f = v->format != NULL ? v->format : "B";
    if (native_order(f[0])) f++;
    int ok = f[0] != '\0' && f[1] == '\0';
    if (ok && kind == F64) ok = f[0] == 'd' && v->itemsize == 8;
    if (ok && kind == I64) ok = (f[0] == 'q' || f[0] == 'l') && v->itemsize == 8;
    if (ok && kind == BOOL) ok = f[0] == '?' && v->itemsize == 1;
    if (!ok) {
        PyErr_Format(PyExc_TypeError, "%s must be a C-contiguous %s array (got format '%s')",
                     name, kind_name[kind], v->format != NULL ? v->format : "B");
        release(b);
        return NULL;
    }
    if (v->len > 0 && (uintptr_t)v->buf % (uintptr_t)v->itemsize != 0) {
        PyErr_Format(PyExc_ValueError, "%s is not aligned for %s", name, kind_name[kind]);
        release(b);
        return NULL;
    }
    return v->buf != NULL ? v->buf : (void *)b; /* non-NULL even when empty */
}

/* Items in the i-th buffer taken. */
static Py_ssize_t items(const bufs *b, int i) {
    return b->v[i].len / b->v[i].itemsize;
}

static int indices_below(const int64_t *v, Py_ssize_t n, int64_t limit) {
    for (Py_ssize_t i = 0; i < n; i++)
        if (v[i] < 0 || v[i] >= limit) return 0;
    return 1;
}

PyDoc_STRVAR(klatt_render_doc,
"klatt_render(frames, n_par, sample_rate, start, end, state, voice, out)\n--\n\n"
"Render samples [start, end) of float64 frames (n_frames x n_par, n_frames >= 2) into\n"
"float64 out (at least end - start items), updating the float64 state vector.");

static PyObject *py_klatt_render(PyObject *self, PyObject *args) {
    PyObject *o[4];
    Py_ssize_t n_par;
    long long sr, start, end;
    if (!PyArg_ParseTuple(args, "OnLLLOOO", &o[0], &n_par, &sr, &start, &end, &o[1], &o[2],
                          &o[3]))
        return NULL;
    bufs b = {.n = 0};
    const double *frames = take(&b, o[0], F64, 0, "frames");
    double *state = frames ? take(&b, o[1], F64, 1, "state") : NULL;
    const double *voice = state ? take(&b, o[2], F64, 0, "voice") : NULL;
    double *out = voice ? take(&b, o[3], F64, 1, "out") : NULL;
    if (out == NULL) return NULL;
    if (n_par < K_N_PARAMS || n_par > items(&b, 0) || items(&b, 0) % n_par != 0)
        return fail(&b, "frames must be float64 with at least 28 parameters per frame");
    int64_t n_frames = items(&b, 0) / n_par;
    if (n_frames < 2) return fail(&b, "need at least 2 frames");
    if (sr <= 0 || start < 0 || end < start) return fail(&b, "bad sample rate or range");
    if (items(&b, 1) != K_STATE_SIZE)
        return fail(&b, "state must be float64 of the renderer's state size");
    if (items(&b, 2) < K_N_VOICE)
        return fail(&b, "voice must be float64 (breathiness, flutter, formant scale)");
    if (items(&b, 3) < end - start) return fail(&b, "out is shorter than end - start");
    double st[K_STATE_SIZE];
    memcpy(st, state, sizeof st);
    if (!(st[KS_SEED] >= 0.0 && st[KS_SEED] < 2147483648.0) ||
        !(st[KS_QUIET] >= 0.0 && st[KS_QUIET] < 4.0e18))
        return fail(&b, "corrupt renderer state");
    Py_BEGIN_ALLOW_THREADS
    klatt_render(frames, n_frames, n_par, sr, start, end, st, voice, out);
    Py_END_ALLOW_THREADS
    memcpy(state, st, sizeof st);
    release(&b);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(spring_integrate_doc,
"spring_integrate(vis_idx, targets, closure, rest, mass, k, c, k_cl, c_cl, lips, edges,\n"
"                 k_nb, lip_pairs, dt, frame_pos, out)\n--\n\n"
"Integrate the mouth springs (face/spring.py) into float64 out (n_frames x N x 2).\n"
"int64: vis_idx, edges (E x 2), lip_pairs (P x 2); bool: closure, lips; the rest float64.");

static PyObject *py_spring_integrate(PyObject *self, PyObject *args) {
    static const int kind[12] = {I64, F64, BOOL, F64, F64, F64, F64, BOOL, I64, I64, F64, F64};
    static const char *const name[12] = {"vis_idx", "targets", "closure", "rest", "mass", "k",
                                         "c", "lips", "edges", "lip_pairs", "frame_pos",
                                         "out"};
    PyObject *o[12];
    spring_args a;
    if (!PyArg_ParseTuple(args, "OOOOOOOddOOdOdOO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5],
                          &o[6], &a.k_cl, &a.c_cl, &o[7], &o[8], &a.k_nb, &o[9], &a.dt,
                          &o[10], &o[11]))
        return NULL;
    bufs b = {.n = 0};
    void *p[12];
    for (int i = 0; i < 12; i++)
        if ((p[i] = take(&b, o[i], kind[i], i == 11, name[i])) == NULL) return NULL;
    a.n_nodes = items(&b, 3) / 2;
    if (a.n_nodes == 0 || items(&b, 3) % 2 != 0) return fail(&b, "rest must be N x 2 float64");
    const Py_ssize_t pose = 2 * a.n_nodes; /* doubles per pose */
    if (items(&b, 1) % pose != 0) return fail(&b, "targets must be V x N x 2 float64");
    a.n_visemes = items(&b, 1) / pose;
    if (items(&b, 2) != a.n_visemes) return fail(&b, "closure must be V bools");
    for (int i = 4; i <= 6; i++)
        if (items(&b, i) != a.n_nodes) return fail(&b, "mass, k and c must be N float64");
    if (items(&b, 7) != a.n_nodes) return fail(&b, "lips must be N bools");
    if (items(&b, 8) % 2 != 0 || items(&b, 9) % 2 != 0)
        return fail(&b, "edges and lip_pairs must be E x 2 int64");
    a.n_steps = items(&b, 0);
    a.n_edges = items(&b, 8) / 2;
    a.n_pairs = items(&b, 9) / 2;
    a.n_frames = items(&b, 10);
    if (items(&b, 11) % pose != 0 || items(&b, 11) / pose != a.n_frames)
        return fail(&b, "out must be n_frames x N x 2 float64");
    /* private copies of the indices, checked, so the loop can trust them */
    const Py_ssize_t n_idx = a.n_steps + 2 * a.n_edges + 2 * a.n_pairs;
    int64_t *idx = PyMem_RawMalloc((size_t)(n_idx > 0 ? n_idx : 1) * sizeof(int64_t));
    if (idx == NULL) {
        release(&b);
        return PyErr_NoMemory();
    }
    memcpy(idx, p[0], (size_t)a.n_steps * sizeof(int64_t));
    memcpy(idx + a.n_steps, p[8], (size_t)(2 * a.n_edges) * sizeof(int64_t));
    memcpy(idx + a.n_steps + 2 * a.n_edges, p[9], (size_t)(2 * a.n_pairs) * sizeof(int64_t));
    a.vis_idx = idx;
    a.edges = idx + a.n_steps;
    a.lip_pairs = a.edges + 2 * a.n_edges;
    const char *bad = NULL;
    if (!indices_below(a.vis_idx, a.n_steps, a.n_visemes))
        bad = "vis_idx out of range";
    else if (!indices_below(a.edges, 2 * (a.n_edges + a.n_pairs), a.n_nodes))
        bad = "node index out of range in edges or lip_pairs";
    if (bad != NULL) {
        PyMem_RawFree(idx);
        return fail(&b, bad);
    }
    a.targets = p[1];
    a.closure = p[2];
    a.rest = p[3];
    a.mass = p[4];
    a.k = p[5];
    a.c = p[6];
    a.lips = p[7];
    a.frame_pos = p[10];
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = spring_integrate(&a, p[11]);
    Py_END_ALLOW_THREADS
    PyMem_RawFree(idx);
    release(&b);
    if (rc != 0) return PyErr_NoMemory();
    Py_RETURN_NONE;
}

PyDoc_STRVAR(bigram_stitch_doc,
"bigram_stitch(fs, bounds, ids, pose_id, ku, kw, nk, n_pose, w)\n--\n\n"
"Max-stitch each phone pair's warped curves into w (n_poses x len(fs), float64, in place).\n"
"fs, bounds (len(ids) + 2), ku, kw (K x n_pose x n_knot) float64; ids, pose_id, nk int64.");

static PyObject *py_bigram_stitch(PyObject *self, PyObject *args) {
    static const int kind[8] = {F64, F64, I64, I64, F64, F64, I64, F64};
    static const char *const name[8] = {"fs", "bounds", "ids", "pose_id", "ku", "kw", "nk",
                                        "w"};
    PyObject *o[8];
    Py_ssize_t n_pose;
    if (!PyArg_ParseTuple(args, "OOOOOOOnO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6],
                          &n_pose, &o[7]))
        return NULL;
    bufs b = {.n = 0};
    void *p[8];
    for (int i = 0; i < 8; i++)
        if ((p[i] = take(&b, o[i], kind[i], i == 7, name[i])) == NULL) return NULL;
    int64_t n_fs = items(&b, 0), n_ids = items(&b, 2);
    int64_t n_rows_k = items(&b, 3); /* keys x n_pose */
    if (n_pose < 1 || n_rows_k % n_pose != 0 || items(&b, 6) != n_rows_k ||
        items(&b, 4) != items(&b, 5))
        return fail(&b, "pose_id and nk must be K x n_pose; ku and kw alike");
    int64_t n_keys = n_rows_k / n_pose;
    if (n_ids == 0 || n_fs == 0) {
        release(&b);
        Py_RETURN_NONE;
    }
    if (items(&b, 1) < n_ids + 2) return fail(&b, "bounds needs len(ids) + 2");
    if (n_rows_k == 0 || items(&b, 4) % n_rows_k != 0)
        return fail(&b, "ku must be K x n_pose x n_knot");
    int64_t n_knot = items(&b, 4) / n_rows_k;
    if (items(&b, 7) % n_fs != 0) return fail(&b, "w must be n_poses x len(fs)");
    int64_t n_w = items(&b, 7) / n_fs;
    /* private copies of the indices, checked, so the loop can trust them */
    int64_t *ids = PyMem_RawMalloc((size_t)(n_ids + 2 * n_rows_k) * sizeof(int64_t));
    if (ids == NULL) {
        release(&b);
        return PyErr_NoMemory();
    }
    int64_t *pid = ids + n_ids, *nk = pid + n_rows_k;
    memcpy(ids, p[2], (size_t)n_ids * sizeof(int64_t));
    memcpy(pid, p[3], (size_t)n_rows_k * sizeof(int64_t));
    memcpy(nk, p[6], (size_t)n_rows_k * sizeof(int64_t));
    const char *bad = NULL;
    if (!indices_below(ids, n_ids, n_keys)) bad = "ids out of range";
    for (int64_t r = 0; bad == NULL && r < n_rows_k; r++)
        if (pid[r] >= 0 && (pid[r] >= n_w || nk[r] < 2 || nk[r] > n_knot))
            bad = "pose_id or knot count out of range";
    if (bad != NULL) {
        PyMem_RawFree(ids);
        return fail(&b, bad);
    }
    Py_BEGIN_ALLOW_THREADS
    bigram_stitch(p[0], n_fs, p[1], ids, n_ids, pid, p[4], p[5], nk, n_pose, n_knot, p[7]);
    Py_END_ALLOW_THREADS
    PyMem_RawFree(ids);
    release(&b);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(bigram_speed_limit_doc,
"bigram_speed_limit(w, step)\n--\n\n"
"In place on float64 w: every weight >= its neighbour's minus step (slope-limited dilation).");

static PyObject *py_bigram_speed_limit(PyObject *self, PyObject *args) {
    PyObject *o;
    double step;
    if (!PyArg_ParseTuple(args, "Od", &o, &step)) return NULL;
    bufs b = {.n = 0};
    double *w = take(&b, o, F64, 1, "w");
    if (w == NULL) return NULL;
    Py_BEGIN_ALLOW_THREADS
    bigram_speed_limit(w, items(&b, 0), step);
    Py_END_ALLOW_THREADS
    release(&b);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(limit_node_speed_doc,
"limit_node_speed(nodes, n_nodes, max_step)\n--\n\n"
"In place on float64 nodes (n_frames x n_nodes x 2): each node moves at most max_step\n"
"between frames, following late instead.");

static PyObject *py_limit_node_speed(PyObject *self, PyObject *args) {
    PyObject *o;
    Py_ssize_t n_nodes;
    double max_step;
    if (!PyArg_ParseTuple(args, "Ond", &o, &n_nodes, &max_step)) return NULL;
    bufs b = {.n = 0};
    double *nodes = take(&b, o, F64, 1, "nodes");
    if (nodes == NULL) return NULL;
    if (n_nodes < 1 || n_nodes > PY_SSIZE_T_MAX / 2 || items(&b, 0) % (2 * n_nodes) != 0)
        return fail(&b, "nodes must be n_frames x n_nodes x 2 float64");
    int64_t n_frames = items(&b, 0) / (2 * n_nodes);
    Py_BEGIN_ALLOW_THREADS
    limit_node_speed(nodes, n_frames, n_nodes, max_step);
    Py_END_ALLOW_THREADS
    release(&b);
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
