/* multigrid.c — geometric multigrid V-cycles for (L − λI) x = b on the MAC
 * grid (poisson_backend_mg), for every variable location, boundary
 * combination, geometry and stretched x; docs/theory.md §5.2.
 *
 * Hierarchy.  Each coarse level is a grid_t of half the cells in the
 * directions being coarsened, built by grid_create() with the same domain,
 * boundary conditions and stretching map, so its x faces are exactly every
 * other fine face (checked) and its operator is L REDISCRETISED on that
 * grid by poisson_create_operator() — the same definition as the fine one,
 * stretched and axisymmetric metric included.  A direction is halved while
 * its cell count is even and ≥ 4 and, with the point smoother, its spacing
 * is within MG_ANISOTROPY of the smallest (semi-coarsening keeps the coarse
 * grids isotropic); with the x-line smoother (stretched x) y and z are
 * halved first and x only once they are exhausted.  The sequence of grids
 * does not depend on the rank count.  Levels are distributed like the fine
 * grid (slabs in x) until a level is small (≤ MG_GATHER_CELLS) or its
 * successor's nx does not divide among the ranks; that level is gathered
 * onto rank 0 and the rest of the hierarchy runs there.
 *
 * Transfers (per direction, tensor products).  Prolongation: linear
 * interpolation, boundary conditions folded into its rows (mg_build_transfer).
 * Restriction: its adjoint in the volume-weighted inner product, except for
 * cell-centred directions under the point smoother, which use the
 * volume-weighted mean of the two children.  Both keep Σ w r, so a
 * compatible mg_residual stays compatible.
 *
 * Smoothers: red-black Gauss–Seidel, colour (i_global + j + k) mod 2, in one
 * pass over memory per sweep (uniform x); zebra x-line Gauss–Seidel with the
 * lines solved exactly across the slabs (stretched x).  Neither depends on
 * the decomposition beyond round-off.  Coarsest level: conjugate gradients
 * (Jacobi-preconditioned, in the inner product weighted by the cell volumes,
 * for which L is symmetric).
 *
 * Start: x = 0 (poisson_solve passes x as output and x may alias b).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mg_internal.h"
#include "util.h"

/* ---------------------------------------------------------------- helpers */

/* Diagonal contribution of a uniform direction with the BC folded in: the
 * ghost of a Neumann face equals the interior value (coefficient −1 instead
 * of −2), of a Dirichlet-ghost face minus it (−3); a Dirichlet face's
 * boundary value is a fixed 0. */
static double *uniform_diag(const poisson_t *op, int d, double c)
{
    int n = op->nu[d];
    double *a = xcalloc((size_t)n, sizeof(double));
    for (int j = 0; j < n; j++) a[j] = 2.0 * c;
    if (op->ebc[d][0] == EBC_PERIODIC) {
        if (n == 1) a[0] = 0.0; /* the point is its own neighbour */
        return a;
    }
    for (int s = 0; s < 2; s++) {
        int j = s ? n - 1 : 0;
        if (op->ebc[d][s] == EBC_NEUMANN) a[j] -= c;
        if (op->ebc[d][s] == EBC_DIRICHLET_GHOST) a[j] += c;
    }
    return a;
}

static double sum_squares(const mg_level_t *L, const double *f)
{
    const grid_t *g = L->g;
    int nux = local_nux(L), nu1 = level_nu(L, 1), nu2 = level_nu(L, 2);
    double s = 0.0;
    for (int i = 0; i < nux; i++)
        for (int j = 0; j < nu1; j++) {
            const double *row = f + G_IDX(g, i, j, 0);
            for (int k = 0; k < nu2; k++) s += row[k] * row[k];
        }
    return grid_sum(g, s);
}

/* ------------------------------------------------------- coarsest level */

static double wdot(const mg_level_t *L, const double *u, const double *v)
{
    const grid_t *g = L->g;
    int nux = local_nux(L), nu1 = level_nu(L, 1), nu2 = level_nu(L, 2);
    double s = 0.0;
    for (int i = 0; i < nux; i++) {
        double w = poisson_x_weight(L->op, i + g->ix0), si = 0.0;
        for (int j = 0; j < nu1; j++)
            for (int k = 0; k < nu2; k++) {
                long c = G_IDX(g, i, j, k);
                si += u[c] * v[c];
            }
        s += w * si;
    }
    return grid_sum(g, s);
}

/* Solve (L − λI)x = b on the coarsest level by conjugate gradients on −(L − λI),
 * which is symmetric positive (semi-)definite in the volume-weighted inner
 * product, preconditioned by its diagonal.  A singular problem is kept in
 * the zero-mean subspace by projecting the mg_residual and the preconditioned
 * mg_residual. */
static void coarse_solve(mg_level_t *L, double lambda)
{
    const grid_t *g = L->g;
    poisson_t *op = L->op;
    int sing = op->singular && lambda == 0.0;
    double *x = L->x, *r = L->r, *z = L->cg_z, *d = L->cg_d, *q = L->cg_q;
    int nux = local_nux(L), nu1 = level_nu(L, 1), nu2 = level_nu(L, 2);
    long nunk = (long)op->nu[0] * nu1 * nu2;
    mg_residual(L, lambda, x, r);
    if (sing) poisson_add_constant(op, r, -poisson_weighted_mean(op, r));
#define PRECONDITION()                                                                                        \
    do {                                                                                                        \
        for (int i = 0; i < nux; i++) {                                                                         \
            double di = op->cd[i + g->ix0] + lambda;                                                            \
            for (int j = 0; j < nu1; j++)                                                                       \
                for (int k = 0; k < nu2; k++) {                                                                 \
                    long c = G_IDX(g, i, j, k);                                                                 \
                    double dd = di + L->dgy[j] + L->dgz[k];                                                     \
                    z[c] = dd > 0.0 ? r[c] / dd : r[c];                                                         \
                }                                                                                               \
        }                                                                                                       \
        if (sing) poisson_add_constant(op, z, -poisson_weighted_mean(op, z));                                  \
    } while (0)
    PRECONDITION();
    double rz = wdot(L, r, z), r0 = wdot(L, r, r);
    if (r0 == 0.0) return;
    field_copy(g, d, z);
    for (long it = 0; it < 4 * nunk + 100; it++) {
        poisson_apply(op, lambda, d, q); /* q = (L − λI) d; the SPD operator is −q */
        double dq = -wdot(L, d, q);
        if (!(dq > 0.0)) break;
        double alpha = rz / dq;
        for (int i = 0; i < nux; i++)
            for (int j = 0; j < nu1; j++)
                for (int k = 0; k < nu2; k++) {
                    long c = G_IDX(g, i, j, k);
                    x[c] -= alpha * d[c]; /* d is a direction for −(L − λI): x moves along −d */
                    r[c] += alpha * q[c];
                }
        if (sing) poisson_add_constant(op, r, -poisson_weighted_mean(op, r));
        if (wdot(L, r, r) <= MG_COARSE_TOL * MG_COARSE_TOL * r0) break;
        PRECONDITION();
        double rz1 = wdot(L, r, z), beta = rz1 / rz;
        rz = rz1;
        for (int i = 0; i < nux; i++)
            for (int j = 0; j < nu1; j++)
                for (int k = 0; k < nu2; k++) {
                    long c = G_IDX(g, i, j, k);
                    d[c] = z[c] + beta * d[c];
                }
    }
#undef PRECONDITION
}

/* --------------------------------------------------------------- V-cycle */

static void vcycle(mg_t *m, int l, double lambda, const poisson_opts_t *o);

/* The part of a V-cycle after the mg_residual L->r of the current x is known:
 * coarse-grid correction and post-smoothing. */
static void correct(mg_t *m, int l, double lambda, const poisson_opts_t *o)
{
    mg_level_t *L = &m->lev[l], *C = &m->lev[l + 1];
    if (L->link == LINK_GATHER) {
        /* the same grid on rank 0 solves for the correction */
        mg_gather_level(L, C, L->r, C->bbuf);
        if (C->g) {
            field_zero(C->g, C->x);
            vcycle(m, l + 1, lambda, o);
        }
        mg_scatter_add_level(L, C, C->x, L->x);
        return;
    }
    mg_restrict_residual(L, C);
    /* The restriction keeps Σ w r = 0; remove the round-off left over. */
    if (C->op->singular && lambda == 0.0) poisson_add_constant(C->op, C->bbuf, -poisson_weighted_mean(C->op, C->bbuf));
    field_zero(C->g, C->x);
    vcycle(m, l + 1, lambda, o);
    mg_prolong_add(L, C);
    for (int s = 0; s < o->mg_post; s++) mg_smooth(L, lambda);
}

/* Pre-smoothing (none before a gather: the copy on rank 0 smooths), then the
 * mg_residual; returns its global Σ r². */
static double presmooth_residual(mg_level_t *L, double lambda, const poisson_opts_t *o)
{
    if (L->link != LINK_GATHER)
        for (int s = 0; s < o->mg_pre; s++) mg_smooth(L, lambda);
    return mg_residual(L, lambda, L->x, L->r);
}

static void vcycle(mg_t *m, int l, double lambda, const poisson_opts_t *o)
{
    mg_level_t *L = &m->lev[l];
    if (!L->g) return; /* this rank has no part in this level */
    if (L->link == LINK_NONE) {
        coarse_solve(L, lambda);
        return;
    }
    presmooth_residual(L, lambda, o);
    correct(m, l, lambda, o);
}

static void level_alloc(mg_level_t *L, int coarsest)
{
    const grid_t *g = L->g;
    L->r = field_alloc(g);
    L->dgy = uniform_diag(L->op, 1, L->op->cy);
    L->dgz = uniform_diag(L->op, 2, L->op->cz);
    L->rowbuf = xcalloc((size_t)(g->n[1] > g->n[2] ? g->n[1] : g->n[2]), sizeof(double));
    if (L->own) {
        L->x = field_alloc(g);
        L->bbuf = field_alloc(g);
        L->b = L->bbuf;
    }
    if (coarsest) {
        L->cg_z = field_alloc(g);
        L->cg_d = field_alloc(g);
        L->cg_q = field_alloc(g);
    }
}

static int can_halve(int n) { return n % 2 == 0 && n >= 4; }

static void *mg_create(poisson_t *p)
{
    const grid_t *g0 = p->g;
    int P = g0->nranks, dim = g0->dim;
    /* 1. The sequence of grids (global, independent of the rank count).
     * Uniform x: point smoothing, so every direction whose spacing is within
     * MG_ANISOTROPY of the smallest is halved (full coarsening on isotropic
     * grids, semi-coarsening otherwise).  Stretched x: x-line relaxation with
     * coarsening in y and z only — robust for any x spacing, since the lines
     * absorb strong x coupling and the y/z coarsening the strong y/z coupling
     * where cells are wide (Trottenberg et al. 2001, §5.1-5.2); x is halved
     * only once y and z are exhausted. */
    int line = g0->stretch != STRETCH_UNIFORM && !g0->periodic[0];
    enum { MAXLEV = 64 };
    int dims[MAXLEV][3], coarsen[MAXLEV][3], nlev = 1;
    for (int d = 0; d < 3; d++) dims[0][d] = g0->n[d];
    for (;;) {
        int *n = dims[nlev - 1], *cf = coarsen[nlev - 1], any = 0;
        double h[3] = {0, 0, 0}, hmin = 1e300;
        for (int d = line; d < dim; d++) {
            h[d] = g0->L[d] / n[d];
            hmin = fmin(hmin, h[d]);
        }
        for (int d = 0; d < 3; d++) {
            cf[d] = d >= line && d < dim && can_halve(n[d]) && h[d] <= MG_ANISOTROPY * hmin;
            any |= cf[d];
        }
        if (!any && line && can_halve(n[0])) any = cf[0] = 1; /* y/z exhausted: x last */
        if (!any || nlev == MAXLEV) {
            for (int d = 0; d < 3; d++) cf[d] = 0;
            break;
        }
        for (int d = 0; d < 3; d++) dims[nlev][d] = cf[d] ? n[d] / 2 : n[d];
        nlev++;
    }
    /* 2. Where the hierarchy leaves the slabs for rank 0: the first level
     * that is small, or whose successor's nx does not divide among the ranks,
     * is gathered whole onto rank 0 (an exact copy) and coarsened there. */
    int gather_at = -1;
    for (int s = 0; P > 1 && s < nlev; s++) {
        long cells = (long)dims[s][0] * dims[s][1] * dims[s][2];
        if (cells <= MG_GATHER_CELLS || (s + 1 < nlev && dims[s + 1][0] % P != 0)) {
            gather_at = s;
            break;
        }
    }
    /* 3. Build the levels; a gather inserts a copy of level gather_at on rank 0. */
    mg_t *m = xcalloc(1, sizeof *m);
    m->nlev = nlev + (gather_at >= 0);
    m->lev = xcalloc((size_t)m->nlev, sizeof(mg_level_t));
    MPI_Comm self = MPI_COMM_SELF;
    int l = 0;
    for (int s = 0; s < nlev; s++) {
        int copies = s == gather_at ? 2 : 1;
        for (int c = 0; c < copies; c++, l++) {
            mg_level_t *L = &m->lev[l];
            int serial = gather_at >= 0 && (s > gather_at || c == 1);
            for (int d = 0; d < 3; d++) L->coarsen[d] = c == 0 && copies == 2 ? 0 : coarsen[s][d];
            L->link = s == nlev - 1 && c == copies - 1 ? LINK_NONE : (copies == 2 && c == 0 ? LINK_GATHER : LINK_COARSEN);
            if (l == 0) {
                L->g = (grid_t *)g0;
                L->op = p;
            } else if (!serial || g0->rank == 0) {
                L->g = grid_create(g0->geom, dims[s], g0->L, g0->x0, &g0->bc, g0->stretch, g0->stretch_beta,
                                   serial ? self : g0->comm);
                L->op = poisson_create_operator(L->g, p->loc);
                L->own = 1;
            }
            if (L->g) level_alloc(L, L->link == LINK_NONE);
            if (L->g && line) {
                /* every rank of the level needs a row (a Dirichlet face can leave none) */
                int mloc = local_nux(L), mmin;
                MPI_Allreduce(&mloc, &mmin, 1, MPI_INT, MPI_MIN, L->g->comm);
                if (mmin >= 1) mg_line_setup(L);
            }
        }
    }
    /* 4. Transfers. */
    for (l = 0; l + 1 < m->nlev; l++) {
        mg_level_t *F = &m->lev[l], *C = &m->lev[l + 1];
        if (!F->g) continue;
        if (F->link == LINK_GATHER) {
            long cnt = (long)F->g->nxl * F->g->n[1] * F->g->n[2];
            F->pack = xcalloc((size_t)cnt, sizeof(double));
            F->gathered = xcalloc((size_t)cnt * (F->g->rank == 0 ? F->g->nranks : 1), sizeof(double));
            continue;
        }
        /* The coarse x faces must be every other fine face (same stretching map). */
        if (F->coarsen[0])
            for (int I = -1; I < C->g->n[0]; I++)
                if (fabs(C->g->gxf[I] - F->g->gxf[2 * I + 1]) > 1e-12 * F->g->L[0])
                    die("multigrid: coarse x face %d is not fine face %d", I, 2 * I + 1);
        for (int d = 0; d < 3; d++) mg_build_transfer(F, C, d, line);
        if (F->coarsen[2]) F->zbuf = xcalloc((size_t)(C->g->nxl + 2) * C->g->n[1] * F->g->n[2], sizeof(double));
    }
    return m;
}

static void mg_destroy(void *impl)
{
    mg_t *m = impl;
    if (!m) return;
    for (int l = 0; l < m->nlev; l++) {
        mg_level_t *L = &m->lev[l];
        for (int d = 0; d < 3; d++) {
            free(L->rst[d]);
            free(L->prl[d]);
        }
        free(L->r);
        free(L->dgy);
        free(L->dgz);
        free(L->rowbuf);
        free(L->zbuf);
        free(L->cg_z);
        free(L->cg_d);
        free(L->cg_q);
        free(L->pack);
        free(L->gathered);
        mg_line_free(L->line);
        if (L->own) {
            free(L->x);
            free(L->bbuf);
            poisson_free(L->op);
            grid_free(L->g);
        }
    }
    free(m->lev);
    free(m->bcopy);
    free(m);
}

/* ---------------------------------------------------------------- solve */

static int mg_solve(poisson_t *p, void *impl, double lambda, const double *b, double *x)
{
    mg_t *m = impl;
    mg_level_t *L0 = &m->lev[0];
    const grid_t *g = p->g;
    if (b == x) {
        if (!m->bcopy) m->bcopy = field_alloc(g);
        field_copy(g, m->bcopy, b);
        b = m->bcopy;
    }
    L0->b = b;
    L0->x = x;
    /* Start from zero: every unknown (and the boundary values, through the
     * ghost fill) of x is written. */
    int nux = local_nux(L0);
    for (int i = 0; i < nux; i++)
        for (int j = 0; j < p->nu[1]; j++)
            for (int k = 0; k < p->nu[2]; k++) x[G_IDX(g, i, j, k)] = 0.0;
    /* Convergence is tested on the mg_residual computed after pre-smoothing
     * (the one the cycle restricts), so the fine level needs one mg_residual
     * per cycle; the solve stops there, and last_residual is exactly the
     * mg_residual of the returned x. */
    double bn = sqrt(sum_squares(L0, b)), rn = 0.0;
    int it = 0, rc = 0;
    if (bn > 0.0)
        for (;;) {
            rn = sqrt(L0->link == LINK_NONE ? mg_residual(L0, lambda, x, L0->r) : presmooth_residual(L0, lambda, &p->opt));
            if (rn <= p->opt.mg_tol * bn) break;
            if (it == p->opt.mg_max_cycles || !isfinite(rn)) {
                rc = -1;
                break;
            }
            if (L0->link == LINK_NONE)
                coarse_solve(L0, lambda);
            else
                correct(m, 0, lambda, &p->opt);
            it++;
        }
    poisson_fill_ghosts(p, x);
    p->last_residual = bn > 0.0 ? rn / bn : 0.0;
    p->last_iterations = it;
    return rc;
}

const poisson_backend_t poisson_backend_mg = {mg_create, mg_solve, mg_destroy};
