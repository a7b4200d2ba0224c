/* r2r.c — FFTW's r2r kinds from complex DFTs (see r2r.h).
 *
 * With FFTW's unnormalised conventions (x the input, Y the output, n points):
 *
 *  REDFT10 (DCT-II)  Y_k = 2 Σ x_j cos(πk(2j+1)/2n).  Makhoul (1980): with
 *      v_m = x_2m, v_{n−1−m} = x_2m+1 and V = DFT_n(v), Y_k = 2 Re(w_k V_k),
 *      w_k = e^{−iπk/2n}.  Two real lines a, b go through one complex DFT of
 *      z = v_a + i v_b: with P = Z_k, Q = conj Z_{n−k},
 *      Y_a,k = Re(w_k (P + Q)), Y_b,k = Im(w_k (P − Q)).
 *  REDFT01 (DCT-III) Y_j = x_0 + 2 Σ_{k≥1} x_k cos(πk(2j+1)/2n), the inverse
 *      of REDFT10 up to 2n: V_k = conj(w_k)(x_k − i x_{n−k}) (x_n = 0) is
 *      Hermitian, v = DFT⁻¹_n(V) (unnormalised) is real, Y_2m = v_m,
 *      Y_2m+1 = v_{n−1−m}; two lines as V_a + i V_b.
 *  RODFT10 (DST-II)  Y_k = REDFT10((−1)^j x_j)_{n−1−k};
 *  RODFT01 (DST-III) Y_j = (−1)^j REDFT01(x reversed)_j.
 *  REDFT11 (DCT-IV)  Y_k = 2 Σ x_j cos(π(2j+1)(2k+1)/4n), n even, M = n/2:
 *      t_m = (x_2m + i x_{n−1−2m}) e^{−iπ(4m+1)/4n}, T = DFT_M(t),
 *      u_k = T_k e^{−iπk/n}: Y_2k = 2 Re u_k, Y_{n−1−2k} = −2 Im u_k.  One
 *      line per DFT (t is complex already).
 *  RODFT11 (DST-IV)  Y_k = (−1)^k REDFT11(x reversed)_k.
 *  RODFT00 (DST-I)   Y_k = 2 Σ x_j sin(π(j+1)(k+1)/(n+1)): the DFT of length
 *      L = 2(n+1) of the odd extension (0, x, 0, −x reversed) is −i Y; two
 *      lines a + ib give Z_{k+1} = Y_b,k − i Y_a,k.
 *
 * Lines are gathered a chunk at a time (B transforms of a buffer that stays
 * in cache) for one FFTW complex plan with B transforms, then scattered.
 * tests/test_poisson_r2r.c checks every kind against FFTW's r2r. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "r2r.h"
#include "util.h"

typedef enum { FAM_DCT2, FAM_DCT3, FAM_DCT4, FAM_DST1 } family_t;

struct r2r_plan {
    fftw_r2r_kind kind;
    family_t fam;
    int n;          /* points per line */
    int L;          /* complex DFT length */
    int per;        /* lines per complex DFT (1 or 2) */
    int B;          /* complex DFTs per chunk */
    int flip;       /* the sine variant of the family (RODFT10, RODFT01, RODFT11) */
    fftw_complex *a, *b; /* chunk buffers, B × L */
    double *w;      /* twiddles (re, im): DCT2/3: w_k, k < n; DCT4: pre (M) then post (M) */
    fftw_plan plan;
};

r2r_plan_t *r2r_plan_make(fftw_r2r_kind kind, int n, unsigned flags)
{
    family_t fam;
    int flip = 0;
    switch (kind) {
    case FFTW_REDFT10: fam = FAM_DCT2; break;
    case FFTW_RODFT10: fam = FAM_DCT2; flip = 1; break;
    case FFTW_REDFT01: fam = FAM_DCT3; break;
    case FFTW_RODFT01: fam = FAM_DCT3; flip = 1; break;
    case FFTW_REDFT11: fam = FAM_DCT4; break;
    case FFTW_RODFT11: fam = FAM_DCT4; flip = 1; break;
    case FFTW_RODFT00: fam = FAM_DST1; break;
    default: return NULL;
    }
    if (n < 2 || (fam == FAM_DCT4 && n % 2)) return NULL;
    r2r_plan_t *p = xcalloc(1, sizeof *p);
    p->kind = kind;
    p->fam = fam;
    p->n = n;
    p->flip = flip;
    p->L = fam == FAM_DCT4 ? n / 2 : fam == FAM_DST1 ? 2 * (n + 1) : n;
    p->per = fam == FAM_DCT4 ? 1 : 2;
    /* a chunk of about 128 kB (two buffers), at most 16 transforms */
    p->B = 8192 / p->L;
    if (p->B < 1) p->B = 1;
    if (p->B > 16) p->B = 16;
    p->a = fftw_alloc_complex((size_t)p->B * p->L);
    p->b = fftw_alloc_complex((size_t)p->B * p->L);
    if (fam == FAM_DCT2 || fam == FAM_DCT3) {
        p->w = xcalloc((size_t)2 * n, sizeof(double));
        for (int k = 0; k < n; k++) {
            p->w[2 * k] = cos(M_PI * k / (2.0 * n));
            p->w[2 * k + 1] = -sin(M_PI * k / (2.0 * n));
        }
    } else if (fam == FAM_DCT4) {
        int M = n / 2;
        p->w = xcalloc((size_t)4 * M, sizeof(double));
        for (int m = 0; m < M; m++) {
            p->w[2 * m] = cos(M_PI * (4 * m + 1) / (4.0 * n));
            p->w[2 * m + 1] = -sin(M_PI * (4 * m + 1) / (4.0 * n));
            p->w[2 * M + 2 * m] = cos(M_PI * m / (double)n);
            p->w[2 * M + 2 * m + 1] = -sin(M_PI * m / (double)n);
        }
    }
    int sign = fam == FAM_DCT3 ? FFTW_BACKWARD : FFTW_FORWARD;
    fftw_iodim d = {p->L, 1, 1}, h = {p->B, p->L, p->L};
    p->plan = fftw_plan_guru_dft(1, &d, 1, &h, p->a, p->b, sign, flags | FFTW_DESTROY_INPUT);
    if (!p->plan) {
        r2r_plan_destroy(p);
        return NULL;
    }
    return p;
}

void r2r_plan_destroy(r2r_plan_t *p)
{
    if (!p) return;
    if (p->plan) fftw_destroy_plan(p->plan);
    fftw_free(p->a);
    fftw_free(p->b);
    free(p->w);
    free(p);
}

/* ---- one chunk: gather the lines into p->a, transform, scatter from p->b ---- */

/* input element j of a line, with the sign and order of the sine variant */
static inline double in_at(const r2r_plan_t *p, const double *x, long is, int j)
{
    if (!p->flip) return x[j * is];
    if (p->fam == FAM_DCT2) return (j & 1) ? -x[j * is] : x[j * is]; /* (−1)^j x_j */
    return x[(p->n - 1 - j) * is];                                    /* reversed (DCT3, DCT4) */
}

/* write output element k of a line, with the sign and order of the sine variant */
static inline void out_set(const r2r_plan_t *p, double *y, long os, int k, double v)
{
    if (!p->flip) {
        y[k * os] = v;
        return;
    }
    if (p->fam == FAM_DCT2) y[(p->n - 1 - k) * os] = v; /* reversed */
    else y[k * os] = (k & 1) ? -v : v;                  /* (−1)^k (DCT3, DCT4) */
}

static void gather(const r2r_plan_t *p, fftw_complex *z, const double *xa, const double *xb, long is)
{
    const int n = p->n;
    switch (p->fam) {
    case FAM_DCT2:
        for (int j = 0; j < n; j++) {
            int m = (j & 1) ? n - 1 - (j >> 1) : j >> 1;
            z[m][0] = in_at(p, xa, is, j);
            z[m][1] = xb ? in_at(p, xb, is, j) : 0.0;
        }
        break;
    case FAM_DCT3:
        for (int k = 0; k < n; k++) {
            double ar = in_at(p, xa, is, k), ai = k ? -in_at(p, xa, is, n - k) : 0.0;
            double br = xb ? in_at(p, xb, is, k) : 0.0, bi = xb && k ? -in_at(p, xb, is, n - k) : 0.0;
            /* conj(w_k) (x_k − i x_{n−k}) for each line, then V_a + i V_b */
            double c = p->w[2 * k], s = -p->w[2 * k + 1];
            double var = c * ar - s * ai, vai = c * ai + s * ar;
            double vbr = c * br - s * bi, vbi = c * bi + s * br;
            z[k][0] = var - vbi;
            z[k][1] = vai + vbr;
        }
        break;
    case FAM_DCT4: {
        int M = n / 2;
        for (int m = 0; m < M; m++) {
            double re = in_at(p, xa, is, 2 * m), im = in_at(p, xa, is, n - 1 - 2 * m);
            double c = p->w[2 * m], s = p->w[2 * m + 1];
            z[m][0] = re * c - im * s;
            z[m][1] = re * s + im * c;
        }
        break;
    }
    case FAM_DST1: {
        int N = n + 1;
        z[0][0] = z[0][1] = z[N][0] = z[N][1] = 0.0;
        for (int j = 1; j <= n; j++) {
            double re = xa[(j - 1) * is], im = xb ? xb[(j - 1) * is] : 0.0;
            z[j][0] = re;
            z[j][1] = im;
            z[2 * N - j][0] = -re;
            z[2 * N - j][1] = -im;
        }
        break;
    }
    }
}

static void scatter(const r2r_plan_t *p, const fftw_complex *Z, double *ya, double *yb, long os)
{
    const int n = p->n;
    switch (p->fam) {
    case FAM_DCT2:
        for (int k = 0; k < n; k++) {
            int kk = k ? n - k : 0;
            double pr = Z[k][0], pi = Z[k][1], qr = Z[kk][0], qi = -Z[kk][1];
            double c = p->w[2 * k], s = p->w[2 * k + 1];
            /* Re(w (P + Q)), Im(w (P − Q)) */
            double sr = pr + qr, si = pi + qi, dr = pr - qr, di = pi - qi;
            out_set(p, ya, os, k, c * sr - s * si);
            if (yb) out_set(p, yb, os, k, c * di + s * dr);
        }
        break;
    case FAM_DCT3:
        for (int j = 0; j < n; j++) {
            int m = (j & 1) ? n - 1 - (j >> 1) : j >> 1;
            out_set(p, ya, os, j, Z[m][0]);
            if (yb) out_set(p, yb, os, j, Z[m][1]);
        }
        break;
    case FAM_DCT4: {
        int M = n / 2;
        const double *pw = p->w + 2 * M;
        for (int k = 0; k < M; k++) {
            double c = pw[2 * k], s = pw[2 * k + 1];
            double ur = Z[k][0] * c - Z[k][1] * s, ui = Z[k][0] * s + Z[k][1] * c;
            out_set(p, ya, os, 2 * k, 2.0 * ur);
            out_set(p, ya, os, n - 1 - 2 * k, -2.0 * ui);
        }
        break;
    }
    case FAM_DST1:
        for (int k = 0; k < n; k++) {
            ya[k * os] = -Z[k + 1][1];
            if (yb) yb[k * os] = Z[k + 1][0];
        }
        break;
    }
}

void r2r_plan_exec(r2r_plan_t *p, const double *in, long is, double *out, long os, int h0, long id0, long od0,
                   int h1, long id1, long od1)
{
    long nl = (long)h0 * h1, per_chunk = (long)p->B * p->per;
    for (long q0 = 0; q0 < nl; q0 += per_chunk) {
        long q1 = q0 + per_chunk < nl ? q0 + per_chunk : nl;
        for (int t = 0; t < p->B; t++) {
            long qa = q0 + (long)t * p->per, qb = qa + 1;
            fftw_complex *z = p->a + (long)t * p->L;
            if (qa >= q1) {
                memset(z, 0, (size_t)p->L * sizeof(fftw_complex));
                continue;
            }
            const double *xa = in + (qa / h1) * id0 + (qa % h1) * id1;
            const double *xb = p->per == 2 && qb < q1 ? in + (qb / h1) * id0 + (qb % h1) * id1 : NULL;
            gather(p, z, xa, xb, is);
        }
        fftw_execute_dft(p->plan, p->a, p->b);
        for (int t = 0; t < p->B; t++) {
            long qa = q0 + (long)t * p->per, qb = qa + 1;
            if (qa >= q1) break;
            double *ya = out + (qa / h1) * od0 + (qa % h1) * od1;
            double *yb = p->per == 2 && qb < q1 ? out + (qb / h1) * od0 + (qb % h1) * od1 : NULL;
            scatter(p, p->b + (long)t * p->L, ya, yb, os);
        }
    }
}
