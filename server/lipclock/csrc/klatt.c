/* Klatt cascade/parallel synthesis loop; speech/klatt.py documents the signal path.
 *
 * Coefficients are recomputed at the first sample of a call and at every absolute
 * block boundary (block = max(8, sr / 500) samples), and depend only on that block,
 * so rendering [a, b) then [b, c) gives the same samples as [a, c).
 */
#include <math.h>

#include "kernels.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define FRAME_RATE_HZ 200.0
#define OUTPUT_GAIN 36000.0 /* loud vowels peak near -6 dBFS (tests check no clipping) */
#define LIMIT 30000.0       /* soft limiter knee, int16 units */
#define QUIET_BLOCKS 10 /* parallel branch skipped after ~20 ms without input */

static double db_to_amp(double x) {
    return x <= 0.0 ? 0.0 : pow(10.0, (x - 60.0) / 20.0);
}

/* Two-pole resonator coefficients (A, B, C) into out[0..2]; peak: unity gain at the
 * peak (parallel), otherwise unity gain at DC (cascade). Bypassed at >= 0.45 sr. */
static void resonator(double f, double bw, double sr, int peak, double *out) {
    if (f <= 0.0 || f >= 0.45 * sr) {
        out[0] = peak ? 0.0 : 1.0;
        out[1] = 0.0;
        out[2] = 0.0;
        return;
    }
    double r = exp(-M_PI * bw / sr);
    double c = -r * r;
    double b = 2.0 * r * cos(2.0 * M_PI * f / sr);
    double a;
    if (peak) {
        double th = 2.0 * M_PI * f / sr;
        a = (1.0 - r) * sqrt(1.0 - 2.0 * r * cos(2.0 * th) + r * r);
    } else {
        a = 1.0 - b - c;
    }
    out[0] = a;
    out[1] = b;
    out[2] = c;
}

/* resonator() with a one-entry memory per slot: consecutive blocks often carry the same
 * frequency and bandwidth (steady segments, bypassed nasals), and the same inputs give the
 * same coefficients, so skipping the exp/cos/sqrt is exact. */
typedef struct { double f, bw; } res_key;

static void resonator_memo(double f, double bw, double sr, int peak, double *out, res_key *key) {
    if (f == key->f && bw == key->bw) return;
    key->f = f;
    key->bw = bw;
    resonator(f, bw, sr, peak, out);
}

static double db_to_amp_memo(double x, double *last_x, double *last_amp) {
    if (x != *last_x) {
        *last_x = x;
        *last_amp = db_to_amp(x);
    }
    return *last_amp;
}

void klatt_render(const double *frames, int64_t n_frames, int64_t n_par, int64_t sr,
                  int64_t start, int64_t end, double *state, const double *voice,
                  double *out) {
    const int64_t block = sr / 500 > 8 ? sr / 500 : 8;
    const double srf = (double)sr;
    const double breath = voice[0], flutter = voice[1], fscale = voice[2];
    double p[K_N_PARAMS] = {0.0};
    double coef[3 * (K_N_CASC + K_N_PAR)] = {0.0};
    double mem[K_N_MEM];
    double par_amp[6] = {0.0};
    for (int j = 0; j < K_N_MEM; j++) mem[j] = state[KS_RES + j];
    double phase = state[KS_PHASE], t0 = state[KS_T0], te = state[KS_TE];
    double av_latch = state[KS_AVLAT], tilt_y = state[KS_TILT], nlp1 = state[KS_NLP1];
    double rad_prev = state[KS_RAD];
    int64_t seed = (int64_t)state[KS_SEED];
    int64_t quiet_blocks = (int64_t)state[KS_QUIET];
    double av = 0.0, ah = 0.0, af = 0.0, tilt_a = 0.0, inv_a0 = 1.0;
    res_key keys[K_N_CASC + K_N_PAR];
    for (int j = 0; j < K_N_CASC + K_N_PAR; j++) keys[j].f = keys[j].bw = NAN; /* never equal */
    double amp_x[9], amp_v[9] = {0.0}, last_tilt_db = NAN, g = 1.0;
    for (int j = 0; j < 9; j++) amp_x[j] = NAN;

    int64_t next_block = start - start % block; /* the next absolute block boundary */
    for (int64_t n = start; n < end; n++) {
        const int at_boundary = n == next_block;
        if (n == start || at_boundary) {
            int64_t b0 = n - n % block;
            next_block = b0 + block;
            double pos = (double)b0 * FRAME_RATE_HZ / srf;
            int64_t k = n_frames - 2;
            double frac = 1.0; /* past the last frame: hold it */
            if (pos < (double)(n_frames - 1)) { /* compare before casting: no overflow */
                k = (int64_t)pos;
                frac = pos - (double)k;
            }
            const double *f0row = frames + k * n_par, *f1row = f0row + n_par;
            for (int j = 0; j < K_N_PARAMS; j++) p[j] = f0row[j] * (1.0 - frac) + f1row[j] * frac;
            resonator_memo(p[18], p[19], srf, 0, coef + 0, keys + 0); /* FNZ (used inverted) */
            inv_a0 = coef[0] != 0.0 ? 1.0 / coef[0] : 0.0;
            resonator_memo(p[16], p[17], srf, 0, coef + 3, keys + 1); /* FNP */
            for (int j = 0; j < 6; j++) {
                int fi = 5 - j; /* F6 first */
                resonator_memo(p[4 + fi] * fscale, p[10 + fi] * fscale, srf, 0, coef + 6 + 3 * j,
                               keys + 2 + j);
            }
            av = db_to_amp_memo(p[1], amp_x + 0, amp_v + 0);
            ah = db_to_amp_memo(p[2], amp_x + 1, amp_v + 1);
            af = db_to_amp_memo(p[3], amp_x + 2, amp_v + 2);
            if (af > 0.0)
                quiet_blocks = 0;
            else if (at_boundary)
                quiet_blocks += 1;
            for (int j = 0; j < 6; j++) par_amp[j] = db_to_amp_memo(p[20 + j], amp_x + 3 + j, amp_v + 3 + j);
            if (quiet_blocks < QUIET_BLOCKS || n == start)
                for (int j = 0; j < K_N_PAR; j++) /* parallel F2..F6 */
                    resonator_memo(p[5 + j] * fscale, p[11 + j] * fscale, srf, 1,
                                   coef + K_P0 + 3 * j, keys + K_N_CASC + j);
            if (p[27] != last_tilt_db) {
                last_tilt_db = p[27];
                g = pow(10.0, -p[27] / 20.0);
            }
            if (g >= 0.999) {
                tilt_a = 0.0;
            } else {
                double cw = cos(2.0 * M_PI * 3000.0 / srf);
                double g2 = g * g;
                double qa = 1.0 - g2;
                double qb = 1.0 - g2 * cw;
                double disc = qb * qb - qa * qa;
                tilt_a = (qb - sqrt(0.0 > disc ? 0.0 : disc)) / qa; /* Python max(disc, 0.0) */
            }
        }
        /* voicing source: KLGLOTT88 flow, parameters latched once per period */
        if (phase >= t0) {
            phase -= t0;
            double f0 = p[0];
            double tsec = (double)n / srf;
            double fl = flutter / 50.0 * (sin(2.0 * M_PI * 12.7 * tsec)
                                          + sin(2.0 * M_PI * 7.1 * tsec)
                                          + sin(2.0 * M_PI * 4.7 * tsec)) / 100.0;
            if (f0 > 20.0) {
                t0 = srf / (f0 * (1.0 + fl));
                av_latch = av;
            } else {
                t0 = srf / 100.0;
                av_latch = 0.0;
            }
            double oq = p[26] > 0.05 ? p[26] : 0.5;
            te = oq * t0;
        }
        double flow = 0.0;
        if (phase < te) {
            double x = phase / te;
            flow = 6.75 * (x * x - x * x * x); /* peak 1.0 at x = 2/3 */
        }
        phase += 1.0;
        tilt_y = (1.0 - tilt_a) * flow * av_latch + tilt_a * tilt_y;
        /* noise: sum of two uniform draws from a 31-bit LCG, low-passed */
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF;
        double r1 = (double)seed / 1073741823.5 - 1.0;
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF;
        nlp1 = r1 + (double)seed / 1073741823.5 - 1.0 + 0.75 * nlp1;
        double mod = (av_latch == 0.0 || phase <= te) ? 1.0 : 0.5;
        double asp = (ah + breath * av_latch * 0.12) * nlp1 * mod * 0.012;
        /* cascade: nasal zero (inverse resonator), nasal pole, F6..F1 */
        double x = tilt_y + asp;
        double y = inv_a0 != 0.0 ? (x - (coef[1] * mem[0] + coef[2] * mem[1])) * inv_a0 : x;
        mem[1] = mem[0];
        mem[0] = x;
        x = y;
#pragma GCC unroll 8
        for (int j = 1; j < K_N_CASC; j++) {
            const double *cf = coef + 3 * j;
            double *m = mem + 2 * j;
            y = cf[0] * x + (cf[1] * m[0] + cf[2] * m[1]); /* x waits on one mul+add */
            m[1] = m[0];
            m[0] = y;
            x = y;
        }
        double total = x;
        /* parallel (frication) with alternating signs, while it has had recent input */
        if (quiet_blocks < QUIET_BLOCKS) {
            double fric = af * nlp1 * mod * 0.1;
            double par = par_amp[5] * fric;
            double sign = 1.0;
#pragma GCC unroll 8
            for (int j = 0; j < K_N_PAR; j++) {
                const double *cf = coef + K_P0 + 3 * j;
                double *m = mem + 2 * (K_N_CASC + j);
                y = (cf[0] * fric + cf[2] * m[1]) + cf[1] * m[0]; /* m[0]: one mul+add */
                m[1] = m[0];
                m[0] = y;
                par += sign * par_amp[j] * y;
                sign = -sign;
            }
            total += par;
        }
        double rad = total - rad_prev; /* radiation: first difference */
        rad_prev = total;
        double s = rad * OUTPUT_GAIN;
        double a = fabs(s);
        if (a > LIMIT)
            s = copysign(LIMIT + (32767.0 - LIMIT) * tanh((a - LIMIT) / (32767.0 - LIMIT)), s);
        out[n - start] = s;
    }
    state[KS_PHASE] = phase;
    state[KS_T0] = t0;
    state[KS_TE] = te;
    state[KS_AVLAT] = av_latch;
    state[KS_TILT] = tilt_y;
    state[KS_NLP1] = nlp1;
    state[KS_RAD] = rad_prev;
    state[KS_SEED] = (double)seed;
    state[KS_QUIET] = (double)quiet_blocks;
    for (int j = 0; j < K_N_MEM; j++) state[KS_RES + j] = mem[j];
}
