/* fft_butterfly.c — the fast path of the FFT solver: the cosine (and
 * Fourier) coefficients of the Neumann directions from the 2-D DFT of the
 * reordered data, and their exact inverse (fft.c, "Fast path"). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fft_internal.h"
#include "util.h"

/* The pass that turns the 2-D DFT V of the reordered data into the cosine
 * (Neumann direction) / Fourier (periodic direction) coefficients, and its
 * exact inverse.  For rows k1 and k1' = N1−k1 (mod N1) and z index k2:
 * P = V(k1, k2), Q = V(k1', k2), β = W1^{k1}, α = W2^{k2} (W = e^{−iπ/2N}).
 *  both Neumann: a = αP, b = conj(αQ), s = β(a+b), d = β(a−b):
 *      Y(k1,k2) = 2Re s, Y(k1,N2−k2) = −2Im d, Y(k1',k2) = −2Im s, Y(k1',N2−k2) = −2Re d
 *  z Neumann, y periodic: T1 = a+b, T2 = i(a−b) are the y-DFT at k1 of the
 *      z-cosine coefficients k2 and N2−k2: row k1 keeps their real parts, row
 *      k1' their imaginary parts (same eigenvalue e_y(k1)).
 *  y Neumann, z periodic: a = βP, b = conj(β)Q, row k1 ← a+b, row k1' ← i(a−b)
 *      (complex, the y-cosine coefficients k1 and k1').
 * A row with k1' = k1 (k1 = 0 or N1/2) has Q = P and keeps its own outputs
 * only.  The formulas follow from DCT_k = W^k V_k + W^{−k} V_{N−k} applied
 * in each direction and V(−k1, −k2) = conj V(k1, k2) for real data.  Each
 * case is a branch-free loop over k2 (vectorised). */
/* a = αP and b = conj(αQ) for α = (ar, ai), entry k of rows p and q */
static inline void bf_twiddle(const double *p, const double *q, int k, double ar, double ai, double *a, double *b)
{
    double Pr = p[2 * k], Pi = p[2 * k + 1], Qr = q[2 * k], Qi = q[2 * k + 1];
    a[0] = ar * Pr - ai * Pi;
    a[1] = ar * Pi + ai * Pr;
    b[0] = ar * Qr - ai * Qi;
    b[1] = -(ar * Qi + ai * Qr);
}

/* The inverse: P = conj(α) a into p, Q = conj(α b) into q */
static inline void bf_untwiddle(double *p, double *q, int k, double ar, double ai, const double *a, const double *b)
{
    p[2 * k] = ar * a[0] + ai * a[1];
    p[2 * k + 1] = ar * a[1] - ai * a[0];
    q[2 * k] = ar * b[0] - ai * b[1];
    q[2 * k + 1] = -(ar * b[1] + ai * b[0]);
}

static void bf_nn(double *restrict p, double *restrict q, const double *restrict w, int n, double br, double bi,
                  int inverse)
{
    if (!inverse)
        for (int k = 0; k < n; k++) {
            double a[2], b[2];
            bf_twiddle(p, q, k, w[2 * k], w[2 * k + 1], a, b);
            double Sr = a[0] + b[0], Si = a[1] + b[1], Dr = a[0] - b[0], Di = a[1] - b[1];
            p[2 * k] = 2.0 * (br * Sr - bi * Si);
            p[2 * k + 1] = -2.0 * (br * Di + bi * Dr);
            q[2 * k] = -2.0 * (br * Si + bi * Sr);
            q[2 * k + 1] = -2.0 * (br * Dr - bi * Di);
        }
    else
        for (int k = 0; k < n; k++) {
            double ar = w[2 * k], ai = w[2 * k + 1];
            double sr = 0.5 * p[2 * k], di = -0.5 * p[2 * k + 1], si = -0.5 * q[2 * k], dr = -0.5 * q[2 * k + 1];
            double Sr = br * sr + bi * si, Si = br * si - bi * sr, Dr = br * dr + bi * di, Di = br * di - bi * dr;
            double a[2] = {0.5 * (Sr + Dr), 0.5 * (Si + Di)}, b[2] = {0.5 * (Sr - Dr), 0.5 * (Si - Di)};
            bf_untwiddle(p, q, k, ar, ai, a, b);
        }
}

static void bf_nn_self(double *restrict p, const double *restrict w, int n, double br, double bi, int inverse)
{
    if (!inverse)
        for (int k = 0; k < n; k++) {
            double ar = w[2 * k], ai = w[2 * k + 1], Pr = p[2 * k], Pi = p[2 * k + 1];
            double a_r = ar * Pr - ai * Pi, a_i = ar * Pi + ai * Pr;
            /* b = conj(a): S = 2 Re a (real), D = 2i Im a */
            double Sr = 2.0 * a_r, Di = 2.0 * a_i;
            p[2 * k] = 2.0 * br * Sr;
            p[2 * k + 1] = -2.0 * br * Di;
        }
    else {
        double r = 0.5 / br;
        for (int k = 0; k < n; k++) {
            double ar = w[2 * k], ai = w[2 * k + 1];
            double a_r = 0.5 * r * p[2 * k], a_i = -0.5 * r * p[2 * k + 1];
            p[2 * k] = ar * a_r + ai * a_i;
            p[2 * k + 1] = ar * a_i - ai * a_r;
        }
    }
    (void)bi;
}

static void bf_zn(double *restrict p, double *restrict q, const double *restrict w, int n, int inverse)
{
    if (!inverse)
        for (int k = 0; k < n; k++) {
            double a[2], b[2];
            bf_twiddle(p, q, k, w[2 * k], w[2 * k + 1], a, b);
            p[2 * k] = a[0] + b[0];     /* Re T1 */
            p[2 * k + 1] = b[1] - a[1]; /* Re T2 */
            q[2 * k] = a[1] + b[1];     /* Im T1 */
            q[2 * k + 1] = a[0] - b[0]; /* Im T2 */
        }
    else
        for (int k = 0; k < n; k++) {
            double ar = w[2 * k], ai = w[2 * k + 1];
            double T1r = p[2 * k], T2r = p[2 * k + 1], T1i = q[2 * k], T2i = q[2 * k + 1];
            double a[2] = {0.5 * (T1r + T2i), 0.5 * (T1i - T2r)}, b[2] = {0.5 * (T1r - T2i), 0.5 * (T1i + T2r)};
            bf_untwiddle(p, q, k, ar, ai, a, b);
        }
}

static void bf_zn_self(double *restrict p, const double *restrict w, int n, int inverse)
{
    if (!inverse)
        for (int k = 0; k < n; k++) {
            double ar = w[2 * k], ai = w[2 * k + 1], Pr = p[2 * k], Pi = p[2 * k + 1];
            double a_r = ar * Pr - ai * Pi, a_i = ar * Pi + ai * Pr;
            p[2 * k] = 2.0 * a_r;
            p[2 * k + 1] = -2.0 * a_i;
        }
    else
        for (int k = 0; k < n; k++) {
            double ar = w[2 * k], ai = w[2 * k + 1];
            double a_r = 0.5 * p[2 * k], a_i = -0.5 * p[2 * k + 1];
            p[2 * k] = ar * a_r + ai * a_i;
            p[2 * k + 1] = ar * a_i - ai * a_r;
        }
}

static void bf_yn(double *restrict p, double *restrict q, int n, double br, double bi, int inverse)
{
    if (!inverse)
        for (int k = 0; k < n; k++) {
            double Pr = p[2 * k], Pi = p[2 * k + 1], Qr = q[2 * k], Qi = q[2 * k + 1];
            double a_r = br * Pr - bi * Pi, a_i = br * Pi + bi * Pr;
            double b_r = br * Qr + bi * Qi, b_i = br * Qi - bi * Qr;
            p[2 * k] = a_r + b_r;
            p[2 * k + 1] = a_i + b_i;
            q[2 * k] = b_i - a_i;
            q[2 * k + 1] = a_r - b_r;
        }
    else
        for (int k = 0; k < n; k++) {
            double U1r = p[2 * k], U1i = p[2 * k + 1], U2r = q[2 * k], U2i = q[2 * k + 1];
            double a_r = 0.5 * (U1r + U2i), a_i = 0.5 * (U1i - U2r);
            double b_r = 0.5 * (U1r - U2i), b_i = 0.5 * (U1i + U2r);
            p[2 * k] = br * a_r + bi * a_i;
            p[2 * k + 1] = br * a_i - bi * a_r;
            q[2 * k] = br * b_r - bi * b_i;
            q[2 * k + 1] = br * b_i + bi * b_r;
        }
}

/* Butterfly of rows k1 (p) and N1−k1 (q; NULL when the row pairs with
 * itself) over n complex entries starting at z index k2 = c0. */
void fft_bf_apply(const fft_t *t, double *p, double *q, int n, int c0, int k1, int inverse)
{
    const double *wz = t->wz + 2 * c0;
    double br = t->wy[2 * k1], bi = t->wy[2 * k1 + 1];
    if (!q) {
        if (t->ynn && t->znn)
            bf_nn_self(p, wz, n, br, bi, inverse);
        else if (t->znn)
            bf_zn_self(p, wz, n, inverse);
        else {
            /* y cosine coefficient k1 of a self-paired row: (β + conj β) P */
            double f = inverse ? 0.5 / br : 2.0 * br;
            for (int k = 0; k < 2 * n; k++) p[k] *= f;
        }
    } else if (t->ynn && t->znn)
        bf_nn(p, q, wz, n, br, bi, inverse);
    else if (t->znn)
        bf_zn(p, q, wz, n, inverse);
    else
        bf_yn(p, q, n, br, bi, inverse);
}

/* The butterfly as a pass over the local planes (when the tridiagonal
 * sweeps cannot do it on the fly: rows k1 and N1−k1 on different ranks). */
void fft_fast_butterfly(fft_t *t, int inverse)
{
    int N1 = t->ny, n = t->nz / 2 + 1;
    for (int i = 0; i < t->nxu; i++)
        for (int k1 = 0; k1 <= N1 / 2; k1++) {
            int k1p = k1 ? N1 - k1 : 0;
            double *p = t->work + i * t->PS + k1 * t->RS, *q = t->work + i * t->PS + k1p * t->RS;
            fft_bf_apply(t, p, k1p == k1 ? NULL : q, n, 0, k1, inverse);
        }
}
