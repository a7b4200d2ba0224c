/* fft.c — direct solver of (L − λI) x = b by eigenfunction expansion:
 * real Fourier-type transforms in the two uniform directions y and z, a
 * tridiagonal solve in x for every (y, z) mode (Schumann & Sweet 1988; the
 * slab layout follows CaNS, Costa 2018).
 *
 * The operator is the one of poisson.c: L = L_x + cy δ²_y + cz δ²_z with the
 * homogeneous BCs of the location folded in.  Along y (and z) the BC pair
 * selects the real transform whose basis vectors are the exact eigenvectors
 * of the 3-point stencil with those ghosts (h = spacing, n = cells, the
 * transform has m unknowns):
 *
 *   pair (low, high)               FFTW kind fwd/inv     eigenvalue × h²        norm
 *   periodic                       R2HC / HC2R (or DFT)  −4 sin²(π k / n)       n
 *   Neumann, Neumann               REDFT10 / REDFT01     −4 sin²(π k / 2n)      2n
 *   Dir.-ghost, Dir.-ghost         RODFT10 / RODFT01     −4 sin²(π(k+1) / 2n)   2n
 *   Dir.-face, Dir.-face (m = n−1) RODFT00 / RODFT00     −4 sin²(π(k+1) / 2n)   2n
 *   Neumann, Dir.-ghost            REDFT11 / REDFT11     −4 sin²(π(k+½) / 2n)   2n
 *   Dir.-ghost, Neumann            RODFT11 / RODFT11     −4 sin²(π(k+½) / 2n)   2n
 *
 * (k = 0..m−1 is the transform index; for a periodic direction the real and
 * imaginary parts of wavenumber k share the eigenvalue, and sin²(πk/n) =
 * sin²(π(n−k)/n).)  "norm" is the factor FFTW's unnormalised forward+inverse
 * pair multiplies the data by.
 *
 * Each mode then satisfies the tridiagonal system along x
 *   cw_i X_{i−1} + (−cd_i − λ + e_y + e_z) X_i + ce_i X_{i+1} = B_i,
 * solved by the Thomas algorithm (cyclic, via Sherman–Morrison, when x is
 * periodic).  The loops run over i outside and over a block of modes inside
 * so that the inner loop is contiguous and vectorises; the block's data and
 * scratch stay in cache.  The singular mode (λ = 0, every face periodic or
 * Neumann, e_y = e_z = 0) is solved with its last unknown pinned (see
 * solve_zero_mode).
 *
 * Fast path (3-D, each of y and z periodic or Neumann–Neumann with an even
 * cell count — the pressure of every box, channel or duct): FFTW's real
 * cosine transforms are several times slower than its complex codelets, so
 * the cosine transforms are computed from one 2-D real DFT (r2c) of the data
 * reordered as v(n) = x(2n), v(N−1−n) = x(2n+1) (Makhoul 1980): with
 * V = DFT(v) and W = e^{−iπ/2N}, DCT-II_k(x) = 2 Re(W^k V_k).  In 2-D
 * (y, z), pairing row k1 with N1−k1 (and using V(k1, −k2) = conj V(−k1, k2))
 * gives every output of a pair of rows from two complex numbers (a
 * "butterfly", bf_*); its exact inverse runs before the inverse DFT (c2r).
 * The z modes are then stored as slot 2k ↔ mode k, slot 2k+1 ↔ mode N−k
 * (slot 1 holds 0, slot N+1 repeats mode N/2).  The reordering is done plane
 * by plane into a buffer that stays in cache (plane_transforms), and on one
 * rank the butterflies run inside the tridiagonal sweeps (blocks pair rows
 * k1 and N1−k1), so this path makes no more passes over memory than a
 * transform from the field; with several ranks the pair of rows may be split
 * among them and the butterfly is a pass of its own (fast_butterfly).
 * Other boundary pairs, odd sizes and 2-D grids use FFTW's r2r kinds
 * directly (batched 1-D plans: faster than rank-2 r2r plans, measured).
 *
 * Memory: the transformed data live in scratch arrays shared by the solvers
 * of all locations (scratch_*): one field's worth on one rank, two with MPI.
 *
 * MPI: the field is split in x slabs.  The transforms are local to each x
 * plane; their output is written in the order [y row][i][z slot], so each
 * rank's block of y rows is contiguous and one MPI_Alltoallv gives every
 * rank all x planes of its rows (no packing); the tridiagonal solves run
 * there, a second Alltoallv brings the modes back, and the inverse
 * transforms write x.  Uneven splits of the rows are allowed.  With one rank
 * the transforms write [i][y row][z slot] and nothing is exchanged.
 *
 * Plans are made once, with FFTW_ESTIMATE by default so that the same input
 * gives bit-identical results run after run.  [poisson] fftw_planner =
 * measure uses FFTW_MEASURE (faster transforms), whose choice of algorithm,
 * hence the round-off, depends on timings; it is made reproducible with FFTW
 * wisdom (the record of the choices): see "FFTW wisdom" below.
 */
#include <errno.h>
#include <fftw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "poisson.h"
#include "r2r.h"
#include "util.h"

/* Modes per block of the tridiagonal sweep: the block's data, c' and the
 * Sherman–Morrison vector are n_x × MODE_BLOCK doubles each (in cache). */
#define MODE_BLOCK 512

typedef struct {
    int m;                     /* transform length (unknowns) */
    int periodic, neumann;     /* the BC pair is periodic / Neumann–Neumann */
    fftw_r2r_kind fwd, inv;    /* real kinds (periodic: R2HC/HC2R) */
    double norm;               /* forward+inverse scale factor of the r2r kinds */
    double *eig;               /* eigenvalues of c δ² (≤ 0) by transform index, m of them */
} tf_dir_t;

/* One batched transform of the pipeline (an FFTW guru plan). */
typedef enum { TK_R2R, TK_R2C, TK_C2R, TK_C2C } tkind_t;
typedef enum { SIDE_FIELD, SIDE_WORK } side_t;
typedef struct {
    tkind_t kind;
    int sign;                  /* TK_C2C: FFTW_FORWARD or FFTW_BACKWARD */
    fftw_r2r_kind rk;          /* TK_R2R (rank 1) */
    int rank;
    fftw_iodim dims[2];        /* transformed dimensions (strides in units of each side's type) */
    int nhow;
    fftw_iodim how[2];         /* loops: x planes, then rows or columns */
    side_t in, out;
    fftw_plan plan[2];         /* per alignment class of the field pointer */
    r2r_plan_t *cr;            /* TK_R2R: the kind from complex DFTs (r2r.h), used instead of plan */
} step_t;

typedef struct {
    poisson_t *p;
    int dim3;                  /* a z transform exists */
    int nx, ny, nz;            /* unknowns in x (global), y, z */
    int nxu;                   /* local unknown x planes */
    int periodic_x;
    tf_dir_t dy, dz;
    double scale;              /* 1 / (forward+inverse factor) */
    unsigned plan_flags;       /* planner of the set-up plans */
    unsigned lazy_flags;       /* planner of a plan made at the first solve (step_run) */

    /* transformed data of one x plane: TR rows (y modes) of TC doubles (z
     * modes; re/im interleaved when z, or y in 2-D, is periodic); in the
     * work array a row starts every RS doubles and a plane every PS */
    int TR, TC;
    long RS, PS;
    step_t fwd[2], inv[2];     /* forward: [0] then [1]; inverse: [0] then [1] */
    int nsteps;
    /* fast path: a 2-D DFT per x plane, with Makhoul reordering of the
     * Neumann directions */
    int fast, ynn, znn, reord; /* reord = ynn || znn */
    int fused;                 /* butterflies applied inside the tridiagonal sweeps (one rank) */
    double *wy, *wz;           /* twiddles e^{−iπk/2N} (re, im) */
    /* fast path: the 2-D transforms run plane by plane on a (reordered)
     * copy of the plane (pbuf, in cache) */
    double *pbuf;
    fftw_plan pfwd, pinv;
    /* nz even: the plane's r2c as a complex DFT of length nz/2 of each row
     * (even and odd values as real and imaginary parts), a split pass, and
     * the complex DFT of the columns (plane_r2c); c2r in reverse */
    int half;
    fftw_plan prow_f, prow_b, pcol_f, pcol_b;
    double *tw;                /* W^k = e^{−2πik/nz}, k = 0 … nz/2 (re, im) */
    unsigned char *fwd_ready;  /* plane i already forward-transformed (poisson_forward_plane) */

    /* decomposition of the rows among ranks (P > 1) */
    int P, me;
    int *j0, *nyl, *nxu_r, *scount, *sdispl, *rcount, *rdispl;
    double *work;              /* transformed data in the slab layout */
    double *recv;              /* transposed data (P > 1) */

    /* view of the data for the tridiagonal solves: element (i, row, col) at
     * tbuf[toff[i] + row * trs[i] + col], eigenvalue erow[row] + ecol[col] */
    double *tbuf;
    long *toff, *trs;
    int trows, tcols;
    double *erow, *ecol;
    int nzero, zcol[4];        /* columns of row 0 with eigenvalue 0 (singular modes) */
    double *wx;                /* compatibility weights in x (singular problems) */

    double *cp, *zs, *gam;     /* scratch of one block */
    int *rowlist;              /* rows of one block */
    double *zero_sol;          /* solutions of the singular modes (nzero × nx) */
} fft_t;

/* Transform kind, length and eigenvalues of one uniform direction. */
static void tf_setup(tf_dir_t *t, ebc_t lo, ebc_t hi, int ncell, double c)
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
static void step_run(fft_t *t, step_t *s, double *f)
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
 * plane (plane_transforms).
 * General 3-D: z first (field → work; r2c when z is periodic, so its output
 * is complex and the y step is a complex DFT if y is periodic too, else the
 * r2r kind of z), then y in place (r2r kind of y, on every double).  2-D: y
 * only (field → work).  The inverse runs the inverse steps in reverse order. */
static void setup_steps(fft_t *t)
{
    const grid_t *g = t->p->g;
    long sx = g->sx, sy = g->sy, RS = t->RS, PS = t->PS;
    int nxu = t->nxu, ny = t->ny, nz = t->nz, TC = t->TC;
    fftw_iodim none = {0, 0, 0};
    if (t->fast) {
        t->nsteps = 0; /* plane_transforms */
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
static void plane_transform(fft_t *t, double *f, int inverse, int i)
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

static void plane_transforms(fft_t *t, double *f, int inverse)
{
    for (int i = 0; i < t->nxu; i++) plane_transform(t, f, inverse, i);
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
static void plans_make(fft_t *t, int a)
{
    if (t->nxu == 0) return;
    if (t->fast) plane_plans(t);
    for (int k = 0; k < t->nsteps; k++) {
        step_plan(t, &t->fwd[k], a, t->plan_flags);
        step_plan(t, &t->inv[k], a, t->plan_flags);
    }
}

static void plans_destroy(fft_t *t)
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
static void bf_apply(const fft_t *t, double *p, double *q, int n, int c0, int k1, int inverse)
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
static void fast_butterfly(fft_t *t, int inverse)
{
    int N1 = t->ny, n = t->nz / 2 + 1;
    for (int i = 0; i < t->nxu; i++)
        for (int k1 = 0; k1 <= N1 / 2; k1++) {
            int k1p = k1 ? N1 - k1 : 0;
            double *p = t->work + i * t->PS + k1 * t->RS, *q = t->work + i * t->PS + k1p * t->RS;
            bf_apply(t, p, k1p == k1 ? NULL : q, n, 0, k1, inverse);
        }
}

/* Scratch shared by every solver object (a run has one per variable
 * location, and its solves never overlap): the slab-layout array [0] and
 * the transposed array [1].  A buffer only grows; plans are executed on the
 * current pointers (FFTW new-array execution: same 64-byte alignment). */
static struct {
    double *buf;
    size_t size;
    int users;
} scratch[2];

static void scratch_reserve(int which, size_t n)
{
    if (n > scratch[which].size) {
        free(scratch[which].buf);
        scratch[which].buf = xcalloc(n, sizeof(double));
        scratch[which].size = n;
    }
    scratch[which].users++;
}

static void scratch_release(int which)
{
    if (--scratch[which].users == 0) {
        free(scratch[which].buf);
        scratch[which].buf = NULL;
        scratch[which].size = 0;
    }
}

/* Point the work arrays of t at the shared scratch (call before using them). */
static void scratch_attach(fft_t *t)
{
    t->work = scratch[0].buf;
    if (t->P > 1) t->recv = scratch[1].buf;
    t->tbuf = t->P > 1 ? t->recv : t->work;
}

/* ---- FFTW wisdom: reproducible measured plans -------------------------------
 *
 * FFTW_MEASURE times candidate algorithms and keeps the fastest, so two runs
 * (or two ranks) may pick different algorithms for the same transform and
 * round differently.  FFTW's wisdom records each choice; a planner that finds
 * a problem in its wisdom makes that plan again without measuring (and FFTW
 * itself executes the plan rebuilt from wisdom, not the measured one).  So:
 *  1. the start wisdom is imported on every rank before the first plan: the
 *     checkpoint's copy on a restart (poisson_fftw_wisdom_preset; the file
 *     is then only written if missing), otherwise [poisson] fftw_wisdom
 *     (read by rank 0, broadcast);
 *  2. the plans are made with FFTW_MEASURE (only problems missing from the
 *     wisdom are measured);
 *  3. the ranks' wisdom is merged on rank 0 (later ranks' entries imported
 *     over rank 0's), broadcast, and every rank forgets its own and imports
 *     the merged one, so all ranks hold the same wisdom;
 *  4. the plans are made again from it (FFTW_WISDOM_ONLY: an entry missing
 *     is an error), so the plans executed are the ones any later run
 *     importing this wisdom makes: a rank whose own measurement lost the
 *     merge switches to the merged choice now, not only in the next run;
 *  5. rank 0 writes the file (temporary name, then rename) when it was
 *     missing or the merged wisdom is longer (new problems were measured).
 * The merged wisdom (poisson_fftw_wisdom_used) goes into every checkpoint
 * and the output folder.  With the same wisdom, every plan of every solver
 * (pressure, Helmholtz; all their steps) is the same in every run; a plan
 * made later for a field of another alignment class is estimated (same in
 * every run too).  The wisdom depends on the problem sizes, hence on the
 * rank count: a file may hold the wisdom of several grids and rank counts. */
static struct {
    int loaded;           /* the start wisdom has been imported */
    char path[4096];      /* the file it came from ("" none) */
    char *preset;         /* wisdom of a restart (poisson_fftw_wisdom_preset) */
    int may_write;        /* the start wisdom is the file's (or the file is missing): write it when grown */
    size_t file_len;      /* length of the file's wisdom (0: missing) */
    char *used;           /* merged wisdom after the last measured set-up */
} wis;

void poisson_fftw_wisdom_preset(const char *wisdom)
{
    free(wis.preset);
    wis.preset = NULL;
    if (wisdom && !(wis.preset = strdup(wisdom))) die("out of memory");
    wis.loaded = 0;
}

const char *poisson_fftw_wisdom_used(void) { return wis.used; }

/* The file's text (malloc'd), NULL if it does not exist; why (n chars) says
 * what else went wrong (then NULL is returned and why[0] != 0). */
static char *wisdom_file_read(const char *path, char *why, size_t n)
{
    why[0] = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (errno != ENOENT) snprintf(why, n, "cannot read %s: %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 1 << 16, len = 0;
    char *s = xcalloc(cap, 1);
    for (size_t r; (r = fread(s + len, 1, cap - 1 - len, f)) > 0;) {
        len += r;
        if (len + 1 == cap) {
            s = realloc(s, 2 * cap);
            if (!s) die("out of memory reading %s", path);
            cap *= 2;
        }
    }
    int err = ferror(f);
    fclose(f);
    s[len] = 0;
    if (err) {
        snprintf(why, n, "cannot read %s", path);
        free(s);
        return NULL;
    }
    return s;
}

int poisson_fftw_wisdom_check(const char *path, char *why, size_t n)
{
    struct stat st;
    if (!path[0]) return snprintf(why, n, "empty path"), 1;
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode)) return snprintf(why, n, "%s is not a regular file", path), 1;
        char *s = wisdom_file_read(path, why, n);
        if (!s) return 1;
        /* importing is the only complete check (format, FFTW version and
         * build); harmless: the wisdom is loaded from scratch before planning */
        int ok = fftw_import_wisdom_from_string(s);
        free(s);
        if (!ok)
            return snprintf(why, n, "%s is not FFTW wisdom of this FFTW build (%s) and planner set; delete it to measure again", path,
                            fftw_version),
                   1;
        return 0;
    }
    if (errno != ENOENT) return snprintf(why, n, "%s: %s", path, strerror(errno)), 1;
    /* missing: it will be created, so its folder must be writable */
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash == dir)
        dir[1] = 0;
    else if (slash)
        *slash = 0;
    else
        snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK | X_OK) != 0)
        return snprintf(why, n, "cannot create %s: folder %s: %s", path, dir, strerror(errno)), 1;
    return 0;
}

/* Text of rank 0 (NULL allowed) to every rank of comm; NULL stays NULL. */
static char *bcast_text(const char *text, MPI_Comm comm)
{
    int me;
    MPI_Comm_rank(comm, &me);
    long len = me == 0 ? (text ? (long)strlen(text) : -1) : 0;
    MPI_Bcast(&len, 1, MPI_LONG, 0, comm);
    if (len < 0) return NULL;
    if (len > 2147483646L) die("poisson fft: FFTW wisdom of %ld bytes", len);
    char *s = xcalloc((size_t)len + 1, 1);
    if (me == 0) memcpy(s, text, (size_t)len);
    MPI_Bcast(s, (int)len, MPI_CHAR, 0, comm);
    return s;
}

/* Step 1: every rank forgets its wisdom and imports the start wisdom (once
 * per process and file). */
static void wisdom_start(const char *path, MPI_Comm comm)
{
    if (wis.loaded && !strcmp(path, wis.path)) return;
    fftw_forget_wisdom();
    wis.loaded = 1;
    snprintf(wis.path, sizeof wis.path, "%s", path);
    wis.file_len = 0;
    wis.may_write = 0;
    int me;
    MPI_Comm_rank(comm, &me);
    if (wis.preset) {
        if (!fftw_import_wisdom_from_string(wis.preset))
            die("poisson fft: the FFTW wisdom of the checkpoint is not wisdom of this FFTW build (%s)", fftw_version);
        /* the file is left as it is, unless it is missing */
        int missing = me == 0 && path[0] && access(path, F_OK) != 0;
        MPI_Bcast(&missing, 1, MPI_INT, 0, comm);
        wis.may_write = missing;
        return;
    }
    if (!path[0]) return;
    char why[4400] = "", *text0 = me == 0 ? wisdom_file_read(path, why, sizeof why) : NULL;
    int bad = why[0] != 0;
    MPI_Bcast(&bad, 1, MPI_INT, 0, comm);
    if (bad) die("poisson.fftw_wisdom: %s", why);
    char *text = bcast_text(text0, comm);
    free(text0);
    wis.may_write = 1;
    if (!text) return;
    if (!fftw_import_wisdom_from_string(text))
        die("poisson.fftw_wisdom: %s is not FFTW wisdom of this FFTW build (%s) and planner set; delete it to measure again", path,
            fftw_version);
    wis.file_len = strlen(text);
    free(text);
}

/* Step 3: merge the ranks' wisdom on rank 0 and give it to every rank. */
static void wisdom_merge(MPI_Comm comm)
{
    int me, P;
    MPI_Comm_rank(comm, &me);
    MPI_Comm_size(comm, &P);
    char *mine = fftw_export_wisdom_to_string();
    if (!mine) die("poisson fft: FFTW could not export its wisdom");
    int len = (int)strlen(mine) + 1, *lens = NULL, *displ = NULL;
    char *all = NULL;
    if (me == 0) {
        lens = xcalloc((size_t)P, sizeof(int));
        displ = xcalloc((size_t)P, sizeof(int));
    }
    MPI_Gather(&len, 1, MPI_INT, lens, 1, MPI_INT, 0, comm);
    if (me == 0) {
        long tot = 0;
        for (int r = 0; r < P; r++) displ[r] = (int)tot, tot += lens[r];
        if (tot > 2147483647L) die("poisson fft: FFTW wisdom of %ld bytes", tot);
        all = xcalloc((size_t)tot, 1);
    }
    MPI_Gatherv(mine, len, MPI_CHAR, all, lens, displ, MPI_CHAR, 0, comm);
    free(mine);
    char *merged = NULL;
    if (me == 0) {
        for (int r = 1; r < P; r++)
            if (!fftw_import_wisdom_from_string(all + displ[r])) die("poisson fft: FFTW could not import rank %d's wisdom", r);
        merged = fftw_export_wisdom_to_string();
        if (!merged) die("poisson fft: FFTW could not export its wisdom");
    }
    free(all);
    free(lens);
    free(displ);
    char *text = bcast_text(merged, comm);
    free(merged);
    fftw_forget_wisdom();
    if (!fftw_import_wisdom_from_string(text)) die("poisson fft: FFTW could not import the merged wisdom");
    free(wis.used);
    wis.used = text;
}

/* Step 5: rank 0 writes the file under a temporary name, then renames it. */
static void wisdom_write(MPI_Comm comm)
{
    size_t len = strlen(wis.used);
    if (!wis.may_write || !wis.path[0] || len <= wis.file_len) return;
    int me;
    MPI_Comm_rank(comm, &me);
    wis.file_len = len;
    if (me != 0) return;
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", wis.path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    int ok = f && fwrite(wis.used, 1, len, f) == len;
    if (f) ok = fclose(f) == 0 && ok;
    if (!ok || rename(tmp, wis.path) != 0) {
        remove(tmp);
        die_local("poisson.fftw_wisdom: cannot write %s: %s", wis.path, strerror(errno));
    }
}

/* The set-up plans of a measuring solver (steps 1–5 above); collective over
 * the grid's communicator. */
static void plans_measure(fft_t *t, int a)
{
    MPI_Comm comm = t->p->g->comm;
    wisdom_start(t->p->opt.fftw_wisdom, comm);
    plans_make(t, a);
    wisdom_merge(comm);
    plans_destroy(t);
    t->plan_flags = FFTW_MEASURE | FFTW_WISDOM_ONLY;
    plans_make(t, a);
    t->plan_flags = FFTW_MEASURE;
    wisdom_write(comm);
}

static void *fft_create(poisson_t *p)
{
    const grid_t *g = p->g;
    fft_t *t = xcalloc(1, sizeof *t);
    t->p = p;
    t->dim3 = g->dim == 3;
    t->nx = p->nu[0];
    t->ny = p->nu[1];
    t->nz = p->nu[2];
    t->periodic_x = p->ebc[0][0] == EBC_PERIODIC;
    /* the singular modes are projected and re-centred here (solve_zero_mode),
     * so poisson_solve need not copy b to remove its mean */
    p->backend_handles_singular = 1;
    t->nxu = t->nx - g->ix0;
    if (t->nxu > g->nxl) t->nxu = g->nxl;
    if (t->nxu < 0) t->nxu = 0;
    tf_setup(&t->dy, p->ebc[1][0], p->ebc[1][1], g->n[1], p->cy);
    if (t->dim3)
        tf_setup(&t->dz, p->ebc[2][0], p->ebc[2][1], g->n[2], p->cz);
    else {
        t->dz.m = 1;
        t->dz.norm = 1.0;
        t->dz.eig = xcalloc(1, sizeof(double));
    }
    if (t->dy.m != t->ny || t->dz.m != t->nz) die("poisson fft: unknown counts disagree with the transforms");
    t->plan_flags = p->opt.fftw_measure ? FFTW_MEASURE : FFTW_ESTIMATE;
    /* a plan made during the run (a field of the other alignment class) is
     * not in the wisdom of a measuring run: estimated, hence the same in
     * every run given the same wisdom */
    t->lazy_flags = FFTW_ESTIMATE;
    int nx = t->nx, ny = t->ny, nz = t->nz;
    t->fast = t->dim3 && (t->dy.periodic || (t->dy.neumann && ny % 2 == 0)) &&
              (t->dz.periodic || (t->dz.neumann && nz % 2 == 0));
    t->ynn = t->fast && t->dy.neumann;
    t->znn = t->fast && t->dz.neumann;
    t->reord = t->ynn || t->znn;
    t->scale = t->fast ? 1.0 / ((double)ny * nz) : 1.0 / (t->dy.norm * t->dz.norm);

    /* shape of a transformed plane and the eigenvalues of its rows/columns */
    double *erow_all, *ecol_all;
    if (t->dim3) {
        t->TR = ny;
        t->TC = t->fast || t->dz.periodic ? 2 * (nz / 2 + 1) : nz;
        erow_all = xcalloc((size_t)t->TR, sizeof(double));
        ecol_all = xcalloc((size_t)t->TC, sizeof(double));
        for (int r = 0; r < t->TR; r++) erow_all[r] = t->dy.eig[r];
        for (int c = 0; c < t->TC; c++) {
            int k = c / 2;
            if (t->znn) /* slot 2k: mode k; slot 2k+1: mode N−k (slot 1: empty, eigenvalue of mode 0) */
                ecol_all[c] = t->dz.eig[c % 2 == 0 || k == 0 ? k : nz - k];
            else
                ecol_all[c] = t->dz.eig[t->dz.periodic ? k : c];
        }
    } else {
        t->TR = t->dy.periodic ? ny / 2 + 1 : ny;
        t->TC = t->dy.periodic ? 2 : 1;
        erow_all = xcalloc((size_t)t->TR, sizeof(double));
        ecol_all = xcalloc((size_t)t->TC, sizeof(double));
        for (int r = 0; r < t->TR; r++) erow_all[r] = t->dy.eig[r];
    }
    int TR = t->TR, TC = t->TC;
    t->wy = xcalloc((size_t)2 * (ny / 2 + 1), sizeof(double));
    t->wz = xcalloc((size_t)2 * (nz / 2 + 1), sizeof(double));
    for (int k = 0; k <= ny / 2; k++) {
        t->wy[2 * k] = cos(M_PI * k / (2.0 * ny));
        t->wy[2 * k + 1] = -sin(M_PI * k / (2.0 * ny));
    }
    for (int k = 0; k <= nz / 2; k++) {
        t->wz[2 * k] = cos(M_PI * k / (2.0 * nz));
        t->wz[2 * k + 1] = -sin(M_PI * k / (2.0 * nz));
    }

    MPI_Comm_size(g->comm, &t->P);
    MPI_Comm_rank(g->comm, &t->me);
    int P = t->P;
    t->toff = xcalloc((size_t)nx, sizeof(long));
    t->trs = xcalloc((size_t)nx, sizeof(long));
    int owns_row0;
    t->fused = P == 1 && t->reord;
    if (P == 1) {
        /* work[i][row][col] */
        t->RS = TC;
        t->PS = (long)TR * TC;
        scratch_reserve(0, (size_t)nx * TR * TC);
        for (int i = 0; i < nx; i++) t->toff[i] = (long)i * TR * TC;
        if (t->fused) {
            /* rows and columns: blocks pair row k1 with N1−k1 for the butterfly */
            for (int i = 0; i < nx; i++) t->trs[i] = TC;
            t->trows = TR;
            t->tcols = TC;
            t->erow = erow_all;
            t->ecol = ecol_all;
            erow_all = ecol_all = NULL;
        } else {
            /* one row of TR·TC modes */
            t->trows = 1;
            t->tcols = TR * TC;
            t->erow = xcalloc(1, sizeof(double));
            t->ecol = xcalloc((size_t)TR * TC, sizeof(double));
            for (int r = 0; r < TR; r++)
                for (int c = 0; c < TC; c++) t->ecol[(long)r * TC + c] = erow_all[r] + ecol_all[c];
        }
        owns_row0 = 1;
    } else {
        /* work[row][il][col] (rows outermost: each destination's block is
         * contiguous); recv[s][rl][il][col] from each source slab s */
        t->RS = (long)t->nxu * TC;
        t->PS = TC;
        t->j0 = xcalloc((size_t)P + 1, sizeof(int));
        t->nyl = xcalloc((size_t)P, sizeof(int));
        t->nxu_r = xcalloc((size_t)P, sizeof(int));
        t->scount = xcalloc((size_t)P, sizeof(int));
        t->sdispl = xcalloc((size_t)P, sizeof(int));
        t->rcount = xcalloc((size_t)P, sizeof(int));
        t->rdispl = xcalloc((size_t)P, sizeof(int));
        for (int r = 0; r <= P; r++) t->j0[r] = (int)((long)r * TR / P);
        for (int r = 0; r < P; r++) t->nyl[r] = t->j0[r + 1] - t->j0[r];
        MPI_Allgather(&t->nxu, 1, MPI_INT, t->nxu_r, 1, MPI_INT, g->comm);
        int me = t->me, nyl = t->nyl[me];
        long disp = 0;
        for (int r = 0; r < P; r++) {
            t->scount[r] = t->nyl[r] * t->nxu * TC;
            t->sdispl[r] = t->j0[r] * t->nxu * TC;
            t->rcount[r] = nyl * t->nxu_r[r] * TC;
            t->rdispl[r] = (int)disp;
            disp += t->rcount[r];
        }
        if ((long)TR * t->nxu * TC > 2147483647L || disp > 2147483647L)
            die("poisson fft: a rank's share exceeds the MPI count range");
        scratch_reserve(0, (size_t)TR * (t->nxu > 0 ? t->nxu : 1) * TC);
        scratch_reserve(1, (size_t)(disp > 0 ? disp : 1));
        int i = 0;
        for (int s = 0; s < P; s++)
            for (int il = 0; il < t->nxu_r[s]; il++, i++) {
                t->toff[i] = t->rdispl[s] + (long)il * TC;
                t->trs[i] = (long)t->nxu_r[s] * TC;
            }
        if (i != nx) die("poisson fft: x planes of the ranks do not add up (%d != %d)", i, nx);
        t->trows = nyl;
        t->tcols = TC;
        t->erow = xcalloc((size_t)(nyl > 0 ? nyl : 1), sizeof(double));
        for (int r = 0; r < nyl; r++) t->erow[r] = erow_all[t->j0[me] + r];
        t->ecol = xcalloc((size_t)TC, sizeof(double));
        memcpy(t->ecol, ecol_all, (size_t)TC * sizeof(double));
        owns_row0 = t->j0[me] == 0 && nyl > 0;
    }
    /* singular modes: eigenvalue exactly 0 (every direction periodic or
     * Neumann; the imaginary/empty slot next to the zero mode holds 0) */
    if (p->singular && owns_row0)
        for (int c = 0; c < t->tcols && t->nzero < 4; c++)
            if (t->erow[0] + t->ecol[c] == 0.0) t->zcol[t->nzero++] = c;
    if (p->singular) {
        /* left null vector of the x operator of a singular mode: w_{i+1} cw_{i+1}
         * = w_i ce_i (the weighted row sums vanish), i.e. the cell volumes */
        t->wx = xcalloc((size_t)nx, sizeof(double));
        t->wx[0] = 1.0;
        for (int i = 0; i + 1 < nx; i++) t->wx[i + 1] = t->wx[i] * p->ce[i] / p->cw[i + 1];
    }
    free(erow_all);
    free(ecol_all);
    t->cp = xcalloc((size_t)nx * MODE_BLOCK, sizeof(double));
    t->zs = xcalloc((size_t)nx * MODE_BLOCK, sizeof(double));
    t->gam = xcalloc(MODE_BLOCK, sizeof(double));
    t->zero_sol = xcalloc((size_t)4 * nx, sizeof(double));
    t->rowlist = xcalloc(MODE_BLOCK, sizeof(int));
    if (t->fused && p->singular && !(t->nzero == 2 && t->zcol[0] == 0 && t->zcol[1] == 1))
        die("poisson fft: unexpected singular modes");
    scratch_attach(t);
    /* plans for the alignment class of fields from field_alloc */
    double *f = field_alloc(g);
    int a = fftw_alignment_of(f + G_IDX(g, 0, 0, 0)) != 0;
    free(f);
    if (t->nxu > 0) {
        if (t->fast) t->pbuf = xcalloc((size_t)ny * nz, sizeof(double));
        t->half = t->fast && nz % 2 == 0;
        if (t->half) {
            t->tw = xcalloc((size_t)nz + 2, sizeof(double));
            for (int k = 0; k <= nz / 2; k++) {
                t->tw[2 * k] = cos(2.0 * M_PI * k / nz);
                t->tw[2 * k + 1] = -sin(2.0 * M_PI * k / nz);
            }
        }
        setup_steps(t);
        if (t->fast) t->fwd_ready = xcalloc((size_t)t->nxu, 1);
    }
    if (p->opt.fftw_measure)
        plans_measure(t, a);
    else
        plans_make(t, a);
    return t;
}

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
    bf_apply(t, p, q, (B->cb - B->ca) / 2, B->ca / 2, B->k1, inverse);
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
        bf_apply(t, pair, NULL, 1, 0, 0, inverse);
        zsol[i] = pair[0];
        zsol[nx + i] = pair[1];
    }
}

static void tridiagonal_solves(fft_t *t, double lambda)
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

/* Everything up to the inverse transforms: the forward transforms of b, the
 * exchanges and the tridiagonal solves; the solution's modes are in t->work. */
static void fft_forward_and_modes(fft_t *t, double lambda, const double *b)
{
    const grid_t *g = t->p->g;
    long o = G_IDX(g, 0, 0, 0);
    scratch_attach(t);
    if (t->nxu > 0) {
        if (t->fast)
            for (int i = 0; i < t->nxu; i++) {
                /* a plane poisson_forward_plane transformed ahead is not read again */
                if (t->fwd_ready[i]) t->fwd_ready[i] = 0;
                else plane_transform(t, (double *)b + o, 0, i);
            }
        else
            for (int k = 0; k < t->nsteps; k++) step_run(t, &t->fwd[k], (double *)b + o);
        if (t->reord && !t->fused) fast_butterfly(t, 0);
    }
    if (t->P > 1)
        MPI_Alltoallv(t->work, t->scount, t->sdispl, MPI_DOUBLE, t->recv, t->rcount, t->rdispl, MPI_DOUBLE,
                      g->comm);
    tridiagonal_solves(t, lambda);
    if (t->P > 1)
        MPI_Alltoallv(t->recv, t->rcount, t->rdispl, MPI_DOUBLE, t->work, t->scount, t->sdispl, MPI_DOUBLE,
                      g->comm);
    t->p->last_iterations = 1;
    t->p->last_residual = -1.0; /* not measured (see poisson.h) */
}

static int fft_solve(poisson_t *p, void *impl, double lambda, const double *b, double *x)
{
    fft_t *t = impl;
    const grid_t *g = p->g;
    long o = G_IDX(g, 0, 0, 0);
    fft_forward_and_modes(t, lambda, b);
    if (t->nxu > 0) {
        if (t->reord && !t->fused) fast_butterfly(t, 1);
        if (t->fast) plane_transforms(t, x + o, 1);
        else
            for (int k = 0; k < t->nsteps; k++) step_run(t, &t->inv[k], x + o);
    }
    /* boundary values of Dirichlet faces (not unknowns) are zero */
    int nz = g->n[2];
    if (t->ny < g->n[1])
        for (int i = 0; i < g->nxl; i++)
            for (int k = 0; k < nz; k++) x[G_IDX(g, i, g->n[1] - 1, k)] = 0.0;
    if (t->nz < nz)
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++) x[G_IDX(g, i, j, nz - 1)] = 0.0;
    for (int i = t->nxu; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < nz; k++) x[G_IDX(g, i, j, k)] = 0.0;
    return 0;
}

/* ---- the solve in two parts ------------------------------------------------
 *
 * On one rank with the transforms by planes (every box with Neumann y or z
 * pairs, the reordered transforms, and boxes periodic in y and z), the
 * inverse transforms write x one plane at a time
 * (plane_transforms), so a caller that reads x plane by plane — the deferred
 * correction of the fluid step — can have each plane written just before it
 * reads it, while it is in cache, instead of in a pass of its own.
 * poisson_solve_begin is fft_solve up to the inverse transforms
 * (fft_forward_and_modes); poisson_solve_plane(i) is plane_transform's
 * inverse of plane i, so the result is bit-identical. */
static int fft_by_planes(const poisson_t *p)
{
    const fft_t *t = p->impl;
    const grid_t *g = p->g;
    return p->backend == &poisson_backend_fft && t && t->fast && t->P == 1 && t->nxu == g->nxl &&
           t->ny == g->n[1] && t->nz == g->n[2];
}

int poisson_solve_by_planes(const poisson_t *p) { return fft_by_planes(p); }

void poisson_solve_begin(poisson_t *p, double lambda, const double *b)
{
    if (!fft_by_planes(p)) die("poisson_solve_begin: not available for this solver");
    fft_forward_and_modes(p->impl, lambda, b);
}

void poisson_solve_plane(poisson_t *p, double *x, int i) { plane_transform(p->impl, x + G_IDX(p->g, 0, 0, 0), 1, i); }

/* The forward transform of plane i of b ahead of the solve (by planes): the
 * writer of b calls it once plane i of b is final, while the plane is still
 * in cache, and the next solve (poisson_solve or poisson_solve_begin with
 * that b) transforms only the planes not done ahead.  The same transform of
 * the same values: bit-identical.  The transformed plane goes to the shared
 * work array, so no other solve may run in between; a plane of a deferred
 * solution must have been written out (poisson_solve_plane) before. */
void poisson_forward_plane(poisson_t *p, const double *b, int i)
{
    if (!fft_by_planes(p)) die("poisson_forward_plane: not available for this solver");
    fft_t *t = p->impl;
    scratch_attach(t);
    plane_transform(t, (double *)b + G_IDX(p->g, 0, 0, 0), 0, i);
    t->fwd_ready[i] = 1;
}

static void fft_destroy(void *impl)
{
    fft_t *t = impl;
    if (!t) return;
    plans_destroy(t);
    free(t->dy.eig);
    free(t->dz.eig);
    free(t->j0);
    free(t->nyl);
    free(t->nxu_r);
    free(t->scount);
    free(t->sdispl);
    free(t->rcount);
    free(t->rdispl);
    free(t->pbuf);
    free(t->tw);
    free(t->fwd_ready);
    free(t->rowlist);
    scratch_release(0);
    if (t->P > 1) scratch_release(1);
    free(t->wy);
    free(t->wz);
    free(t->toff);
    free(t->trs);
    free(t->erow);
    free(t->ecol);
    free(t->wx);
    free(t->cp);
    free(t->zs);
    free(t->gam);
    free(t->zero_sol);
    free(t);
}

const poisson_backend_t poisson_backend_fft = {fft_create, fft_solve, fft_destroy};
