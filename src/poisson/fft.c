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
 * by plane into a buffer that stays in cache (fft_plane_transforms), and on one
 * rank the butterflies run inside the tridiagonal sweeps (blocks pair rows
 * k1 and N1−k1), so this path makes no more passes over memory than a
 * transform from the field; with several ranks the pair of rows may be split
 * among them and the butterfly is a pass of its own (fft_fast_butterfly).
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
#include <fftw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fft_internal.h"
#include "util.h"


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

/* The set-up plans of a measuring solver (steps 1–5 above); collective over
 * the grid's communicator. */
static void plans_measure(fft_t *t, int a)
{
    MPI_Comm comm = t->p->g->comm;
    fft_wisdom_start(t->p->opt.fftw_wisdom, comm);
    fft_plans_make(t, a);
    fft_wisdom_merge(comm);
    fft_plans_destroy(t);
    t->plan_flags = FFTW_MEASURE | FFTW_WISDOM_ONLY;
    fft_plans_make(t, a);
    t->plan_flags = FFTW_MEASURE;
    fft_wisdom_write(comm);
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
    fft_direction_setup(&t->dy, p->ebc[1][0], p->ebc[1][1], g->n[1], p->cy);
    if (t->dim3)
        fft_direction_setup(&t->dz, p->ebc[2][0], p->ebc[2][1], g->n[2], p->cz);
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
        fft_setup_steps(t);
        if (t->fast) t->fwd_ready = xcalloc((size_t)t->nxu, 1);
    }
    if (p->opt.fftw_measure)
        plans_measure(t, a);
    else
        fft_plans_make(t, a);
    return t;
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
                else fft_plane_transform(t, (double *)b + o, 0, i);
            }
        else
            for (int k = 0; k < t->nsteps; k++) fft_step_run(t, &t->fwd[k], (double *)b + o);
        if (t->reord && !t->fused) fft_fast_butterfly(t, 0);
    }
    if (t->P > 1)
        MPI_Alltoallv(t->work, t->scount, t->sdispl, MPI_DOUBLE, t->recv, t->rcount, t->rdispl, MPI_DOUBLE,
                      g->comm);
    fft_tridiagonal_solves(t, lambda);
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
        if (t->reord && !t->fused) fft_fast_butterfly(t, 1);
        if (t->fast) fft_plane_transforms(t, x + o, 1);
        else
            for (int k = 0; k < t->nsteps; k++) fft_step_run(t, &t->inv[k], x + o);
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
 * (fft_plane_transforms), so a caller that reads x plane by plane — the deferred
 * correction of the fluid step — can have each plane written just before it
 * reads it, while it is in cache, instead of in a pass of its own.
 * poisson_solve_begin is fft_solve up to the inverse transforms
 * (fft_forward_and_modes); poisson_solve_plane(i) is fft_plane_transform's
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

void poisson_solve_plane(poisson_t *p, double *x, int i) { fft_plane_transform(p->impl, x + G_IDX(p->g, 0, 0, 0), 1, i); }

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
    fft_plane_transform(t, (double *)b + G_IDX(p->g, 0, 0, 0), 0, i);
    t->fwd_ready[i] = 1;
}

static void fft_destroy(void *impl)
{
    fft_t *t = impl;
    if (!t) return;
    fft_plans_destroy(t);
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
