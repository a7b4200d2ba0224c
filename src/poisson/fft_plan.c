/* fft_plan.c — the FFT solver's transforms: the real transform kind and the
 * eigenvalues of each uniform direction, the batched FFTW plans of the
 * pipeline, and the fast path's plane-by-plane 2-D r2c / c2r (fft.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fft_internal.h"
#include "util.h"

/* Transform kind, length and eigenvalues of one uniform direction. */
void fft_direction_setup(tf_dir_t *t, ebc_t lo, ebc_t hi, int ncell, double c)
{
    double n = ncell;
    t->m = ncell;
    double shift = 0.0, den = 2.0 * n; /* eigenvalue −4c sin²(π(k+shift)/den) */
    if (lo == EBC_PERIODIC && hi == EBC_PERIODIC) {
        t->periodic = 1;
        t->fwd = FFTW_R2HC;
        t->inv = FFTW_HC2R;
        t->norm = n;
        den = n;
    } else if (lo == EBC_NEUMANN && hi == EBC_NEUMANN) {
        t->neumann = 1;
        t->fwd = FFTW_REDFT10;
        t->inv = FFTW_REDFT01;
        t->norm = 2.0 * n;
    } else if (lo == EBC_DIRICHLET_GHOST && hi == EBC_DIRICHLET_GHOST) {
        t->fwd = FFTW_RODFT10;
        t->inv = FFTW_RODFT01;
        t->norm = 2.0 * n;
        shift = 1.0;
    } else if (lo == EBC_DIRICHLET_FACE && hi == EBC_DIRICHLET_FACE) {
        t->m = ncell - 1;
        t->fwd = t->inv = FFTW_RODFT00;
        t->norm = 2.0 * n; /* 2(m+1) */
        shift = 1.0;
    } else if (lo == EBC_NEUMANN && hi == EBC_DIRICHLET_GHOST) {
        t->fwd = t->inv = FFTW_REDFT11;
        t->norm = 2.0 * n;
        shift = 0.5;
    } else if (lo == EBC_DIRICHLET_GHOST && hi == EBC_NEUMANN) {
        t->fwd = t->inv = FFTW_RODFT11;
        t->norm = 2.0 * n;
        shift = 0.5;
    } else
        die("poisson fft: unsupported boundary pair (%d, %d) in a uniform direction", (int)lo, (int)hi);
    t->eig = xcalloc((size_t)(t->m > 0 ? t->m : 1), sizeof(double));
    for (int k = 0; k < t->m; k++) {
        double s = sin(M_PI * (k + shift) / den);
        t->eig[k] = -4.0 * c * s * s;
    }
}

static fftw_iodim iod(int n, long is, long os)
{
    if (labs(is) > 2147483647L || labs(os) > 2147483647L) die("poisson fft: stride exceeds the FFTW int range");
    return (fftw_iodim){n, (int)is, (int)os};
}

static step_t step_make(tkind_t kind, fftw_r2r_kind rk, int sign, side_t in, side_t out, int rank, fftw_iodim d0,
                        fftw_iodim d1, int nhow, fftw_iodim h0, fftw_iodim h1)
{
    step_t s;
    memset(&s, 0, sizeof s);
    s.kind = kind;
    s.rk = rk;
    s.sign = sign;
    s.in = in;
    s.out = out;
    s.rank = rank;
    s.dims[0] = d0;
    s.dims[1] = d1;
    s.nhow = nhow;
    s.how[0] = h0;
    s.how[1] = h1;
    return s;
}

/* Plan step s for field pointers of alignment class a with the planner
 * flags `planner`, on scratch arrays for the field side (a measuring planner
 * overwrites its arrays). */
static void step_plan(fft_t *t, step_t *s, int a, unsigned planner)
{
    const grid_t *g = t->p->g;
    /* a real-to-real kind: from complex DFTs where r2r.c covers it (FFTW runs
     * its r2r kinds with scalar codelets: 2.4-3.1x slower on 80 lines of 880,
     * bench_r2r) */
    if (s->kind == TK_R2R && s->rank == 1 && !s->cr) s->cr = r2r_plan_make(s->rk, s->dims[0].n, planner);
    if (s->cr) return;
    double *tmp = NULL, *f = NULL;
    if (s->in == SIDE_FIELD || s->out == SIDE_FIELD) {
        tmp = xcalloc((size_t)g->nalloc + 2, sizeof(double));
        f = tmp + G_IDX(g, 0, 0, 0);
        if ((fftw_alignment_of(f) != 0) != a) f++;
    }
    double *side[2] = {f, t->work};
    double *in = side[s->in], *out = side[s->out];
    unsigned flags = planner | (s->in == SIDE_FIELD ? FFTW_PRESERVE_INPUT : FFTW_DESTROY_INPUT);
    fftw_plan pl = NULL;
    switch (s->kind) {
    case TK_R2R: pl = fftw_plan_guru_r2r(s->rank, s->dims, s->nhow, s->how, in, out, &s->rk, flags); break;
    case TK_R2C:
        pl = fftw_plan_guru_dft_r2c(s->rank, s->dims, s->nhow, s->how, in, (fftw_complex *)out, flags);
        break;
    case TK_C2R:
        pl = fftw_plan_guru_dft_c2r(s->rank, s->dims, s->nhow, s->how, (fftw_complex *)in, out, flags);
        break;
    case TK_C2C:
        pl = fftw_plan_guru_dft(s->rank, s->dims, s->nhow, s->how, (fftw_complex *)in, (fftw_complex *)out,
                                s->sign, flags);
        break;
    }
    if (!pl)
        die("poisson fft: FFTW could not plan a transform%s",
            planner & FFTW_WISDOM_ONLY ? " from the merged wisdom (an entry is missing)" : "");
    s->plan[a] = pl;
    free(tmp);
}

/* Run step s; f is the field (pointer to its first interior unknown) when a
 * side of the step is the field. */
void fft_step_run(fft_t *t, step_t *s, double *f)
{
    if (s->cr) {
        double *side[2] = {f, t->work};
        int h1 = s->nhow > 1 ? s->how[1].n : 1;
        long id1 = s->nhow > 1 ? s->how[1].is : 0, od1 = s->nhow > 1 ? s->how[1].os : 0;
        int h0 = s->nhow > 0 ? s->how[0].n : 1;
        long id0 = s->nhow > 0 ? s->how[0].is : 0, od0 = s->nhow > 0 ? s->how[0].os : 0;
        r2r_plan_exec(s->cr, side[s->in], s->dims[0].is, side[s->out], s->dims[0].os, h0, id0, od0, h1, id1, od1);
        return;
    }
    int a = (s->in == SIDE_FIELD || s->out == SIDE_FIELD) ? fftw_alignment_of(f) != 0 : 0;
    if (!s->plan[a]) step_plan(t, s, a, t->lazy_flags);
    double *side[2] = {f, t->work};
    double *in = side[s->in], *out = side[s->out];
    fftw_plan pl = s->plan[a];
    switch (s->kind) {
    case TK_R2R: fftw_execute_r2r(pl, in, out); break;
    case TK_R2C: fftw_execute_dft_r2c(pl, in, (fftw_complex *)out); break;
    case TK_C2R: fftw_execute_dft_c2r(pl, (fftw_complex *)in, out); break;
    case TK_C2C: fftw_execute_dft(pl, (fftw_complex *)in, (fftw_complex *)out); break;
    }
}

/* The transform pipeline.
 * Fast path (y and z each periodic or Neumann with an even count): plane by
 * plane (fft_plane_transforms).
 * General 3-D: z first (field → work; r2c when z is periodic, so its output
 * is complex and the y step is a complex DFT if y is periodic too, else the
 * r2r kind of z), then y in place (r2r kind of y, on every double).  2-D: y
 * only (field → work).  The inverse runs the inverse steps in reverse order. */
void fft_setup_steps(fft_t *t)
{
    const grid_t *g = t->p->g;
    long sx = g->sx, sy = g->sy, RS = t->RS, PS = t->PS;
    int nxu = t->nxu, ny = t->ny, nz = t->nz, TC = t->TC;
    fftw_iodim none = {0, 0, 0};
    if (t->fast) {
        t->nsteps = 0; /* fft_plane_transforms */
    } else if (t->dim3) {
        t->nsteps = 2;
        if (t->dz.periodic) {
            t->fwd[0] = step_make(TK_R2C, 0, 0, SIDE_FIELD, SIDE_WORK, 1, iod(nz, 1, 1), none, 2,
                                  iod(nxu, sx, PS / 2), iod(ny, sy, RS / 2));
            t->inv[1] = step_make(TK_C2R, 0, 0, SIDE_WORK, SIDE_FIELD, 1, iod(nz, 1, 1), none, 2,
                                  iod(nxu, PS / 2, sx), iod(ny, RS / 2, sy));
        } else {
            t->fwd[0] = step_make(TK_R2R, t->dz.fwd, 0, SIDE_FIELD, SIDE_WORK, 1, iod(nz, 1, 1), none, 2,
                                  iod(nxu, sx, PS), iod(ny, sy, RS));
            t->inv[1] = step_make(TK_R2R, t->dz.inv, 0, SIDE_WORK, SIDE_FIELD, 1, iod(nz, 1, 1), none, 2,
                                  iod(nxu, PS, sx), iod(ny, RS, sy));
        }
        if (t->dy.periodic && t->dz.periodic) {
            fftw_iodim d = iod(ny, RS / 2, RS / 2), h0 = iod(nxu, PS / 2, PS / 2), h1 = iod(TC / 2, 1, 1);
            t->fwd[1] = step_make(TK_C2C, 0, FFTW_FORWARD, SIDE_WORK, SIDE_WORK, 1, d, none, 2, h0, h1);
            t->inv[0] = step_make(TK_C2C, 0, FFTW_BACKWARD, SIDE_WORK, SIDE_WORK, 1, d, none, 2, h0, h1);
        } else {
            fftw_iodim d = iod(ny, RS, RS), h0 = iod(nxu, PS, PS), h1 = iod(TC, 1, 1);
            t->fwd[1] = step_make(TK_R2R, t->dy.fwd, 0, SIDE_WORK, SIDE_WORK, 1, d, none, 2, h0, h1);
            t->inv[0] = step_make(TK_R2R, t->dy.inv, 0, SIDE_WORK, SIDE_WORK, 1, d, none, 2, h0, h1);
        }
    } else {
        t->nsteps = 1;
        if (t->dy.periodic) {
            t->fwd[0] = step_make(TK_R2C, 0, 0, SIDE_FIELD, SIDE_WORK, 1, iod(ny, sy, RS / 2), none, 1,
                                  iod(nxu, sx, PS / 2), none);
            t->inv[0] = step_make(TK_C2R, 0, 0, SIDE_WORK, SIDE_FIELD, 1, iod(ny, RS / 2, sy), none, 1,
                                  iod(nxu, PS / 2, sx), none);
        } else {
            t->fwd[0] = step_make(TK_R2R, t->dy.fwd, 0, SIDE_FIELD, SIDE_WORK, 1, iod(ny, sy, RS), none, 1,
                                  iod(nxu, sx, PS), none);
            t->inv[0] = step_make(TK_R2R, t->dy.inv, 0, SIDE_WORK, SIDE_FIELD, 1, iod(ny, RS, sy), none, 1,
                                  iod(nxu, PS, sx), none);
        }
    }
}

/* ---- the 2-D r2c / c2r of one plane --------------------------------------
 *
 * For an even row length N = 2M, the r2c of a real row x is computed as the
 * complex DFT of length M of z_m = x_2m + i x_2m+1, Z = E + iO with E, O the
 * DFTs of the even and odd values, followed by the split
 *     E_k = ½(Z_k + conj Z_{M−k}),  O_k = −½i(Z_k − conj Z_{M−k}),
 *     X_k = E_k + W^k O_k  (k = 0 … M, Z_M = Z_0, W = e^{−2πi/N}),
 * X exactly FFTW's unnormalised r2c output; the c2r runs it backwards,
 *     Z_k = E_k + iO_k,  E_k = X_k + conj X_{M−k},  O_k = W^{−k}(X_k − conj X_{M−k}),
 * then the inverse complex DFT of length M (N x as from FFTW's c2r, which
 * also ignores the imaginary parts of X_0 and X_M).  Why not FFTW's r2c: the
 * default planner (FFTW_ESTIMATE, no timing) takes the scalar straight-line
 * r2c codelet of the whole row, while complex DFTs get its SIMD codelets;
 * with FFTW_MEASURE it picks a split of the same kind itself.  Measured on
 * 128 planes of 128 x 128 (2026-11-26): FFTW's 2-D r2c 4.2 ms (ESTIMATE),
 * 2.8 ms (MEASURE); c2r 5.7 and 4.4 ms. */
static void split_rows(const fft_t *t, double *w)
{
    const int M = t->nz / 2, ny = t->ny;
    const double *tw = t->tw;
    for (int r = 0; r < ny; r++) {
        double *x = w + r * t->RS;
        double a = x[0], b = x[1];
        x[0] = a + b;
        x[1] = 0.0;
        x[2 * M] = a - b;
        x[2 * M + 1] = 0.0;
        for (int k = 1; 2 * k <= M; k++) {
            int j = M - k;
            double zkr = x[2 * k], zki = x[2 * k + 1], zjr = x[2 * j], zji = x[2 * j + 1];
            double er = 0.5 * (zkr + zjr), ei = 0.5 * (zki - zji);
            double orr = 0.5 * (zki + zji), oi = -0.5 * (zkr - zjr);
            /* X_k = E_k + W^k O_k, X_{M−k} = conj(E_k) − conj(W^k O_k) (W^M = −1) */
            double c = tw[2 * k], sn = tw[2 * k + 1], wr = c * orr - sn * oi, wi = c * oi + sn * orr;
            x[2 * k] = er + wr;
            x[2 * k + 1] = ei + wi;
            if (j != k) {
                x[2 * j] = er - wr;
                x[2 * j + 1] = wi - ei;
            }
        }
    }
}

static void merge_rows(const fft_t *t, double *w)
{
    const int M = t->nz / 2, ny = t->ny;
    const double *tw = t->tw;
    for (int r = 0; r < ny; r++) {
        double *x = w + r * t->RS;
        double p = x[0], q = x[2 * M];
        x[0] = p + q;
        x[1] = p - q;
        for (int k = 1; 2 * k <= M; k++) {
            int j = M - k;
            double xkr = x[2 * k], xki = x[2 * k + 1], xjr = x[2 * j], xji = x[2 * j + 1];
            double er = xkr + xjr, ei = xki - xji, dr = xkr - xjr, di = xki + xji;
            double c = tw[2 * k], sn = tw[2 * k + 1];
            /* O_k = conj(W^k) D_k and O_{M−k} = conj(O_k); Z = E + iO */
            double okr = c * dr + sn * di, oki = c * di - sn * dr;
            x[2 * k] = er - oki;
            x[2 * k + 1] = ei + okr;
            if (j != k) {
                x[2 * j] = er + oki;
                x[2 * j + 1] = okr - ei;
            }
        }
    }
}

/* FFTW's r2c of pbuf into the work plane w, or the split path (destroys pbuf) */
static void plane_r2c(fft_t *t, fftw_complex *w)
{
    if (!t->half) {
        fftw_execute_dft_r2c(t->pfwd, t->pbuf, w);
        return;
    }
    fftw_execute_dft(t->prow_f, (fftw_complex *)t->pbuf, w);
    split_rows(t, (double *)w);
    fftw_execute_dft(t->pcol_f, w, w);
}

/* the inverse: work plane w (destroyed) into pbuf */
static void plane_c2r(fft_t *t, fftw_complex *w)
{
    if (!t->half) {
        fftw_execute_dft_c2r(t->pinv, w, t->pbuf);
        return;
    }
    fftw_execute_dft(t->pcol_b, w, w);
    merge_rows(t, (double *)w);
    fftw_execute_dft(t->prow_b, w, (fftw_complex *)t->pbuf);
}

/* Transforms of the fast path, one x plane at a time.  Forward: gather the
 * plane into pbuf, which stays in cache, reordered in each Neumann direction
 * (Makhoul: v(n) = x(2n), v(N−1−n) = x(2n+1); row n1 comes from field row
 * p_y(n1)) and copied as it is in a periodic one, then the plane's 2-D r2c
 * into the work plane (plane_r2c).  Inverse: c2r of the work plane into
 * pbuf, scattered back.  This costs no extra pass over memory compared with
 * a transform from the field. */
void fft_plane_transform(fft_t *t, double *f, int inverse, int i)
{
    const grid_t *g = t->p->g;
    int ny = t->ny, nz = t->nz, hz = nz / 2;
    long o = G_IDX(g, 0, 0, 0);
    fftw_complex *w = (fftw_complex *)(t->work + i * t->PS);
    if (inverse) plane_c2r(t, w);
    for (int n1 = 0; n1 < ny; n1++) {
        int j = !t->ynn ? n1 : n1 < ny / 2 ? 2 * n1 : 2 * (ny - 1 - n1) + 1;
        double *restrict fr = f + G_IDX(g, i, j, 0) - o;
        double *restrict zr = t->pbuf + (long)n1 * nz;
        if (!t->znn) {
            if (inverse)
                memcpy(fr, zr, (size_t)nz * sizeof(double));
            else
                memcpy(zr, fr, (size_t)nz * sizeof(double));
        } else if (inverse) {
            /* one loop: each cache line of the field row written once */
            for (int m = 0; m < hz; m++) {
                fr[2 * m] = zr[m];
                fr[2 * m + 1] = zr[nz - 1 - m];
            }
        } else {
            for (int m = 0; m < hz; m++) {
                zr[m] = fr[2 * m];
                zr[nz - 1 - m] = fr[2 * m + 1];
            }
        }
    }
    if (!inverse) plane_r2c(t, w);
}

void fft_plane_transforms(fft_t *t, double *f, int inverse)
{
    for (int i = 0; i < t->nxu; i++) fft_plane_transform(t, f, inverse, i);
}

static void plane_plans(fft_t *t)
{
    int ny = t->ny, nz = t->nz;
    if (t->half) {
        int M = nz / 2, rs = (int)(t->RS / 2);
        fftw_complex *pb = (fftw_complex *)t->pbuf, *wk = (fftw_complex *)t->work;
        fftw_iodim dr = iod(M, 1, 1), hrf = iod(ny, M, rs), hrb = iod(ny, rs, M);
        fftw_iodim dc = iod(ny, rs, rs), hc = iod(M + 1, 1, 1);
        unsigned fl = t->plan_flags | FFTW_DESTROY_INPUT;
        t->prow_f = fftw_plan_guru_dft(1, &dr, 1, &hrf, pb, wk, FFTW_FORWARD, fl);
        t->prow_b = fftw_plan_guru_dft(1, &dr, 1, &hrb, wk, pb, FFTW_BACKWARD, fl);
        t->pcol_f = fftw_plan_guru_dft(1, &dc, 1, &hc, wk, wk, FFTW_FORWARD, fl);
        t->pcol_b = fftw_plan_guru_dft(1, &dc, 1, &hc, wk, wk, FFTW_BACKWARD, fl);
        if (!t->prow_f || !t->prow_b || !t->pcol_f || !t->pcol_b)
            die("poisson fft: FFTW could not plan a transform%s",
                t->plan_flags & FFTW_WISDOM_ONLY ? " from the merged wisdom (an entry is missing)" : "");
        return;
    }
    fftw_iodim df[2] = {iod(ny, nz, t->RS / 2), iod(nz, 1, 1)}, di[2] = {iod(ny, t->RS / 2, nz), iod(nz, 1, 1)};
    t->pfwd = fftw_plan_guru_dft_r2c(2, df, 0, NULL, t->pbuf, (fftw_complex *)t->work,
                                     t->plan_flags | FFTW_DESTROY_INPUT);
    t->pinv = fftw_plan_guru_dft_c2r(2, di, 0, NULL, (fftw_complex *)t->work, t->pbuf,
                                     t->plan_flags | FFTW_DESTROY_INPUT);
    if (!t->pfwd || !t->pinv)
        die("poisson fft: FFTW could not plan a transform%s",
            t->plan_flags & FFTW_WISDOM_ONLY ? " from the merged wisdom (an entry is missing)" : "");
}

/* The set-up plans (plane_plans and the steps for the alignment class a of
 * the fields from field_alloc) with the flags t->plan_flags, and their
 * destruction. */
void fft_plans_make(fft_t *t, int a)
{
    if (t->nxu == 0) return;
    if (t->fast) plane_plans(t);
    for (int k = 0; k < t->nsteps; k++) {
        step_plan(t, &t->fwd[k], a, t->plan_flags);
        step_plan(t, &t->inv[k], a, t->plan_flags);
    }
}

void fft_plans_destroy(fft_t *t)
{
    for (int k = 0; k < 2; k++)
        for (int a = 0; a < 2; a++) {
            if (t->fwd[k].plan[a]) fftw_destroy_plan(t->fwd[k].plan[a]);
            if (t->inv[k].plan[a]) fftw_destroy_plan(t->inv[k].plan[a]);
            t->fwd[k].plan[a] = t->inv[k].plan[a] = NULL;
        }
    for (int k = 0; k < 2; k++) {
        r2r_plan_destroy(t->fwd[k].cr);
        r2r_plan_destroy(t->inv[k].cr);
        t->fwd[k].cr = t->inv[k].cr = NULL;
    }
    if (t->pfwd) fftw_destroy_plan(t->pfwd);
    if (t->pinv) fftw_destroy_plan(t->pinv);
    t->pfwd = t->pinv = NULL;
    fftw_plan *hp[4] = {&t->prow_f, &t->prow_b, &t->pcol_f, &t->pcol_b};
    for (int k = 0; k < 4; k++) {
        if (*hp[k]) fftw_destroy_plan(*hp[k]);
        *hp[k] = NULL;
    }
}

