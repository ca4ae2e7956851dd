/* Compiled inner loops of lipclock (the lipclock._kernels extension module).
 *
 * Plain C over caller-owned double/int64/byte arrays: the Python wrappers in
 * speech/klatt.py and the face/ modules check dtypes and shapes, the module glue
 * (module.c) checks item types, buffer sizes and indices, so these loops trust their input.
 * Arithmetic follows the Python reference expressions term by term, in the same
 * order, so results are reproducible; build without -ffast-math and with
 * -ffp-contract=off (no fused multiply-add).
 */
#ifndef LIPCLOCK_KERNELS_H
#define LIPCLOCK_KERNELS_H

#include <stdint.h>

/* Klatt renderer state vector (speech/klatt.py keeps the same layout). */
enum {
    KS_PHASE, KS_T0, KS_TE, KS_AVLAT, KS_TILT, KS_NLP1, KS_QUIET, KS_RAD, KS_SEED,
    KS_RES /* resonator memories: 2 per section */
};
#define K_N_CASC 8 /* NZ, NP, F6, F5, F4, F3, F2, F1 */
#define K_P0 (3 * K_N_CASC) /* first parallel coefficient */
#define K_N_PAR 5  /* parallel F2..F6 */
#define K_N_MEM (2 * (K_N_CASC + K_N_PAR))
#define K_STATE_SIZE (KS_RES + K_N_MEM + 2)
#define K_N_PARAMS 28
#define K_N_VOICE 3 /* breathiness, flutter, formant scale */

/* Render samples [start, end) of the frames (n_frames x n_par, 5 ms apart) into out
 * (end - start doubles, before rounding to int16). state is read and updated. */
void klatt_render(const double *frames, int64_t n_frames, int64_t n_par, int64_t sr,
                  int64_t start, int64_t end, double *state, const double *voice,
                  double *out);

/* Semi-implicit Euler mouth springs (face/spring.py); see spring.py for the roles. */
typedef struct {
    const int64_t *vis_idx; int64_t n_steps;
    const double *targets; int64_t n_visemes; /* n_visemes x n_nodes x 2 */
    const uint8_t *closure;                   /* n_visemes */
    const double *rest; int64_t n_nodes;      /* n_nodes x 2 */
    const double *mass, *k, *c;               /* n_nodes */
    double k_cl, c_cl;
    const uint8_t *lips;                      /* n_nodes */
    const int64_t *edges; int64_t n_edges;    /* n_edges x 2 */
    double k_nb;
    const int64_t *lip_pairs; int64_t n_pairs; /* n_pairs x 2 (upper, lower) */
    double dt;
    const double *frame_pos; int64_t n_frames; /* in steps */
} spring_args;

/* Returns 0, or -1 when scratch memory could not be allocated. out: n_frames x n_nodes x 2. */
int spring_integrate(const spring_args *a, double *out);

/* Bigram blend curves (face/bigram.py): warp each pair's knots onto frames, max-stitch into w. */
void bigram_stitch(const double *fs, int64_t n_fs, const double *bounds, const int64_t *ids,
                   int64_t n_ids, const int64_t *pose_id, const double *ku, const double *kw,
                   const int64_t *nk, int64_t n_pose, int64_t n_knot, double *w);

/* In place: every weight >= its neighbour's minus step, forwards then backwards. */
void bigram_speed_limit(double *w, int64_t n, double step);

/* In place on n_frames x n_nodes x 2: no node moves more than max_step between frames. */
void limit_node_speed(double *nodes, int64_t n_frames, int64_t n_nodes, double max_step);

#endif
