/* fft_tridiag.c — the FFT solver's tridiagonal solves along x, one per
 * (y, z) mode, by blocks of modes (Thomas; cyclic by Sherman–Morrison), and
 * the singular modes (fft.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fft_internal.h"
#include "util.h"

/* A block of modes for the tridiagonal sweeps: rows row[0..nr−1] of the
 * view, columns ca..cb−1.  With the fused butterfly (one rank, reordering
 * fast path) a block is the row pair k1, N1−k1 (or the self-paired row k1),
 * and the butterfly is applied to each x plane of the block as the forward
 * sweep reaches it, its inverse as the backward sweep leaves it. */
typedef struct {
    const int *row;
    int nr, ca, cb;
    int bf, k1; /* bf: 1 = apply the butterfly of rows k1 (and row[1]) */
} block_t;

static inline double *blk_row(const fft_t *t, int i, int r, int ca) { return t->tbuf + t->toff[i] + r * t->trs[i] + ca; }

static void blk_butterfly(const fft_t *t, const block_t *B, int i, int inverse)
{
    if (!B->bf) return;
    double *p = blk_row(t, i, B->row[0], B->ca), *q = B->nr > 1 ? blk_row(t, i, B->row[1], B->ca) : NULL;
    fft_bf_apply(t, p, q, (B->cb - B->ca) / 2, B->ca / 2, B->k1, inverse);
}

/* Thomas algorithm for the modes of a block, non-periodic x.  The
 * right-hand side is scaled by s (transform norm). */
static void tri_block(fft_t *t, double lambda, const block_t *B)
{
    const poisson_t *p = t->p;
    const int n = t->nx, ca = B->ca, nc = B->cb - B->ca;
    const double s = t->scale;
    double *restrict cp = t->cp;
    for (int i = 0; i < n; i++) {
        const double a = p->cw[i], c = p->ce[i], dd = -p->cd[i] - lambda;
        blk_butterfly(t, B, i, 0);
        for (int q = 0; q < B->nr; q++) {
            int r = B->row[q];
            double *restrict xi = blk_row(t, i, r, ca);
            double *restrict ci = cp + (long)i * MODE_BLOCK + (long)q * nc;
            const double er = t->erow[r] + dd, *restrict ec = t->ecol + ca;
            if (i == 0) {
                for (int k = 0; k < nc; k++) {
                    double inv = 1.0 / (er + ec[k]);
                    ci[k] = c * inv;
                    xi[k] *= s * inv;
                }
            } else {
                const double *restrict xm = blk_row(t, i - 1, r, ca);
                const double *restrict cm = ci - MODE_BLOCK;
                for (int k = 0; k < nc; k++) {
                    double inv = 1.0 / (er + ec[k] - a * cm[k]);
                    ci[k] = c * inv;
                    xi[k] = (s * xi[k] - a * xm[k]) * inv;
                }
            }
        }
    }
    for (int i = n - 2; i >= 0; i--) {
        for (int q = 0; q < B->nr; q++) {
            int r = B->row[q];
            double *restrict xi = blk_row(t, i, r, ca);
            const double *restrict xp = blk_row(t, i + 1, r, ca);
            const double *restrict ci = cp + (long)i * MODE_BLOCK + (long)q * nc;
            for (int k = 0; k < nc; k++) xi[k] -= ci[k] * xp[k];
        }
        blk_butterfly(t, B, i + 1, 1);
    }
    blk_butterfly(t, B, 0, 1);
}

/* Cyclic tridiagonal (periodic x, a_0 = cw[0] couples X_0 to X_{n−1} and
 * c_{n−1} = ce[n−1] couples X_{n−1} to X_0) by Sherman–Morrison: with
 * γ = −b_0, A = A' + u vᵀ where u = (γ, 0, …, 0, c_{n−1}), v = (1, 0, …, 0,
 * a_0/γ) and A' is tridiagonal with b'_0 = b_0 − γ, b'_{n−1} = b_{n−1} −
 * a_0 c_{n−1}/γ.  Solve A'y = d, A'z = u; X = y − (v·y)/(1 + v·z) z. */
static void tri_block_cyclic(fft_t *t, double lambda, const block_t *B)
{
    const poisson_t *p = t->p;
    const int n = t->nx, ca = B->ca, nc = B->cb - B->ca;
    const double s = t->scale, a0 = p->cw[0], cn = p->ce[n - 1];
    double *restrict cp = t->cp, *restrict zs = t->zs, *restrict gam = t->gam;
    for (int i = 0; i < n; i++) {
        const double a = p->cw[i], c = p->ce[i], dd = -p->cd[i] - lambda;
        blk_butterfly(t, B, i, 0);
        for (int q = 0; q < B->nr; q++) {
            int r = B->row[q];
            long m0 = (long)q * nc;
            double *restrict xi = blk_row(t, i, r, ca);
            double *restrict ci = cp + (long)i * MODE_BLOCK + m0, *restrict zi = zs + (long)i * MODE_BLOCK + m0;
            double *restrict gm = gam + m0;
            const double er = t->erow[r] + dd, *restrict ec = t->ecol + ca;
            if (i == 0) {
                for (int k = 0; k < nc; k++) {
                    double b0 = er + ec[k];
                    gm[k] = -b0;
                    double inv = 1.0 / (b0 - gm[k]);
                    ci[k] = c * inv;
                    xi[k] *= s * inv;
                    zi[k] = gm[k] * inv;
                }
            } else {
                const double *restrict xm = blk_row(t, i - 1, r, ca);
                const double *restrict cm = ci - MODE_BLOCK, *restrict zm = zi - MODE_BLOCK;
                if (i < n - 1) {
                    for (int k = 0; k < nc; k++) {
                        double inv = 1.0 / (er + ec[k] - a * cm[k]);
                        ci[k] = c * inv;
                        xi[k] = (s * xi[k] - a * xm[k]) * inv;
                        zi[k] = -a * zm[k] * inv;
                    }
                } else {
                    for (int k = 0; k < nc; k++) {
                        double inv = 1.0 / (er + ec[k] - a0 * cn / gm[k] - a * cm[k]);
                        ci[k] = 0.0;
                        xi[k] = (s * xi[k] - a * xm[k]) * inv;
                        zi[k] = (cn - a * zm[k]) * inv;
                    }
                }
            }
        }
    }
    for (int i = n - 2; i >= 0; i--)
        for (int q = 0; q < B->nr; q++) {
            int r = B->row[q];
            long m0 = (long)q * nc;
            double *restrict xi = blk_row(t, i, r, ca);
            const double *restrict xp = blk_row(t, i + 1, r, ca);
            const double *restrict ci = cp + (long)i * MODE_BLOCK + m0;
            double *restrict zi = zs + (long)i * MODE_BLOCK + m0;
            const double *restrict zp = zi + MODE_BLOCK;
            for (int k = 0; k < nc; k++) {
                xi[k] -= ci[k] * xp[k];
                zi[k] -= ci[k] * zp[k];
            }
        }
    /* f = (v·y)/(1 + v·z), kept in gam (overwrites γ after use) */
    for (int q = 0; q < B->nr; q++) {
        int r = B->row[q];
        long m0 = (long)q * nc;
        const double *x0 = blk_row(t, 0, r, ca), *xn = blk_row(t, n - 1, r, ca);
        const double *z0 = zs + m0, *zn = zs + (long)(n - 1) * MODE_BLOCK + m0;
        double *gm = gam + m0;
        for (int k = 0; k < nc; k++) {
            double qq = a0 / gm[k];
            gm[k] = (x0[k] + qq * xn[k]) / (1.0 + z0[k] + qq * zn[k]);
        }
    }
    for (int i = 0; i < n; i++) {
        for (int q = 0; q < B->nr; q++) {
            long m0 = (long)q * nc;
            double *restrict xi = blk_row(t, i, B->row[q], ca);
            const double *restrict zi = zs + (long)i * MODE_BLOCK + m0, *restrict gm = gam + m0;
            for (int k = 0; k < nc; k++) xi[k] -= gm[k] * zi[k];
        }
        blk_butterfly(t, B, i, 1);
    }
}

static void run_block(fft_t *t, double lambda, const block_t *B)
{
    if (t->periodic_x)
        tri_block_cyclic(t, lambda, B);
    else
        tri_block(t, lambda, B);
}

/* A singular mode (eigenvalue 0, λ = 0) with values d (over x).  Its x
 * system has the constant null vector and the left null vector w (wx):
 * first project the right-hand side onto the compatible space (Σ w_i B_i =
 * 0; in physical space this removes the weighted mean of b, as poisson_solve
 * does for other back-ends), then solve rows 0..n−2 with X_{n−1} = 0 (its
 * coupling terms drop: a plain Thomas solve; the last equation holds by
 * compatibility), and shift the result to Σ w_i X_i = 0 (x of zero weighted
 * mean). */
static void solve_zero_mode(fft_t *t, double *d)
{
    const poisson_t *p = t->p;
    int n = t->nx;
    double *cq = t->cp, *w = t->wx;
    double sw = 0.0, swd = 0.0;
    for (int i = 0; i < n; i++) {
        d[i] *= t->scale;
        sw += w[i];
        swd += w[i] * d[i];
    }
    for (int i = 0; i < n; i++) d[i] -= swd / sw;
    for (int i = 0; i < n - 1; i++) {
        double a = i > 0 ? p->cw[i] : 0.0, b = -p->cd[i];
        double den = i > 0 ? b - a * cq[i - 1] : b;
        cq[i] = p->ce[i] / den;
        d[i] = (d[i] - (i > 0 ? a * d[i - 1] : 0.0)) / den;
    }
    d[n - 1] = 0.0;
    for (int i = n - 3; i >= 0; i--) d[i] -= cq[i] * d[i + 1];
    swd = 0.0;
    for (int i = 0; i < n; i++) swd += w[i] * d[i];
    for (int i = 0; i < n; i++) d[i] -= swd / sw;
}

/* The butterfly of row 0 restricted to its columns 0 and 1 (which it maps
 * to themselves), applied to the singular modes kept in zero_sol. */
static void zero_pair_butterfly(fft_t *t, int inverse)
{
    int nx = t->nx;
    double *zsol = t->zero_sol, pair[2];
    for (int i = 0; i < nx; i++) {
        pair[0] = zsol[i];
        pair[1] = zsol[nx + i];
        fft_bf_apply(t, pair, NULL, 1, 0, 0, inverse);
        zsol[i] = pair[0];
        zsol[nx + i] = pair[1];
    }
}

void fft_tridiagonal_solves(fft_t *t, double lambda)
{
    int nx = t->nx, nzero = lambda == 0.0 ? t->nzero : 0;
    double *zsol = t->zero_sol;
    /* singular modes first, into zero_sol (the block solves leave
     * meaningless values in their columns, replaced afterwards).  With the
     * fused butterfly the stored values are before the butterfly: it maps
     * the pair of columns 0, 1 of row 0 to itself. */
    if (nzero) {
        for (int z = 0; z < nzero; z++)
            for (int i = 0; i < nx; i++) zsol[(long)z * nx + i] = t->tbuf[t->toff[i] + t->zcol[z]];
        if (t->fused) zero_pair_butterfly(t, 0);
        for (int z = 0; z < nzero; z++) solve_zero_mode(t, zsol + (long)z * nx);
        if (t->fused) zero_pair_butterfly(t, 1);
    }
    block_t B = {t->rowlist, 0, 0, 0, 0, 0};
    if (t->fused) {
        /* row pairs (k1, N1−k1) × column chunks of equal even width */
        int N1 = t->TR, nchunk = (t->tcols + MODE_BLOCK / 2 - 1) / (MODE_BLOCK / 2);
        int w = (t->tcols + nchunk - 1) / nchunk;
        w += w % 2;
        B.bf = 1;
        for (int k1 = 0; k1 <= N1 / 2; k1++) {
            int k1p = k1 ? N1 - k1 : 0;
            t->rowlist[0] = k1;
            t->rowlist[1] = k1p;
            B.nr = k1p == k1 ? 1 : 2;
            B.k1 = k1;
            for (B.ca = 0; B.ca < t->tcols; B.ca += w) {
                B.cb = B.ca + w < t->tcols ? B.ca + w : t->tcols;
                run_block(t, lambda, &B);
            }
        }
    } else {
        /* several rows per block only when a row is shorter than a block
         * (then the block holds whole rows) */
        int nchunk = (t->tcols + MODE_BLOCK - 1) / MODE_BLOCK;
        int nc = (t->tcols + nchunk - 1) / nchunk, nr = MODE_BLOCK / nc;
        for (int ra = 0; ra < t->trows; ra += nr) {
            B.nr = ra + nr < t->trows ? nr : t->trows - ra;
            for (int q = 0; q < B.nr; q++) t->rowlist[q] = ra + q;
            for (B.ca = 0; B.ca < t->tcols; B.ca += nc) {
                B.cb = B.ca + nc < t->tcols ? B.ca + nc : t->tcols;
                run_block(t, lambda, &B);
            }
        }
    }
    for (int z = 0; z < nzero; z++)
        for (int i = 0; i < nx; i++) t->tbuf[t->toff[i] + t->zcol[z]] = zsol[(long)z * nx + i];
}
