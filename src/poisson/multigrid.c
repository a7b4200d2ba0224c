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
 * interpolation, boundary conditions folded into its rows (build_transfer).
 * Restriction: its adjoint in the volume-weighted inner product, except for
 * cell-centred directions under the point smoother, which use the
 * volume-weighted mean of the two children.  Both keep Σ w r, so a
 * compatible residual stays compatible.
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

#include "poisson.h"
#include "util.h"

#define MG_GATHER_CELLS 4096 /* levels at most this large (16³) live on rank 0 alone */
#define MG_ANISOTROPY 1.5     /* halve a direction if its spacing ≤ 1.5 × the smallest one */
#define MG_COARSE_TOL 1e-8    /* coarsest-level CG: residual reduction */

enum { LINK_NONE = 0, LINK_COARSEN, LINK_GATHER };

/* One row of a 1-D transfer operator: up to 4 (index, weight) pairs. */
typedef struct {
    int n;
    int idx[4];
    double w[4];
} mg_row_t;

typedef struct {
    grid_t *g;      /* NULL on ranks that take no part in this level */
    poisson_t *op;  /* L on this level (level 0: the caller's) */
    int own;        /* g and op belong to the hierarchy */
    double *x, *r;  /* solution/correction and residual */
    const double *b;
    double *bbuf;   /* storage of b on coarse levels */
    double *dgy, *dgz; /* y and z parts of the diagonal of L, BC folded (index j, k) */
    double *rowbuf;    /* one row of the smoother */
    double *zbuf;      /* prolongation: coarse rows interpolated along z */
    /* link to the next level */
    int link, coarsen[3];
    mg_row_t *rst[3]; /* restriction rows, indexed by the coarse (local) index */
    mg_row_t *prl[3]; /* prolongation rows, indexed by the fine (local) index */
    /* coarsest level: CG work fields */
    double *cg_z, *cg_d, *cg_q;
    /* gather link: packing buffers */
    double *pack, *gathered;
    struct mg_line *line; /* x-line relaxation data, NULL for point smoothing */
} mg_level_t;

typedef struct {
    int nlev;
    mg_level_t *lev;
    double *bcopy; /* copy of b when it aliases x */
} mg_t;

/* ---------------------------------------------------------------- helpers */

static int level_nu(const mg_level_t *L, int d) { return L->op->nu[d]; }

/* Number of local x unknowns of a level (the last rank may own one less). */
static int local_nux(const mg_level_t *L)
{
    int n = L->op->nu[0] - L->g->ix0;
    return n < L->g->nxl ? n : L->g->nxl;
}

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

/* ------------------------------------------------------------- smoothing */

/* Stencil of L − λI at cell c (the same arithmetic as poisson_apply). */
#define STENCIL_3D(x, c)                                                                                       \
    (cw * x[c - sx] + ce * x[c + sx] - cdl * x[c] + cy * (x[c + sy] - 2.0 * x[c] + x[c - sy]) +                \
     cz * (x[c + 1] - 2.0 * x[c] + x[c - 1]))
#define STENCIL_2D(x, c) (cw * x[c - sx] + ce * x[c + sx] - cdl * x[c] + cy * (x[c + sy] - 2.0 * x[c] + x[c - sy]))

/* Red-black Gauss–Seidel on plane i (local) for one colour: every unknown of
 * colour (i_global + j + k) mod 2 is set so that its row of (L − λI)x = b
 * holds.  Points of one colour do not touch each other, so the result does
 * not depend on the order or on the decomposition.  Each contiguous row (k
 * in 3-D, j in 2-D) is updated for all points into a buffer — vectorisable,
 * since only the other colour is read — and the points of this colour are
 * copied back. */
static void rb_plane(mg_level_t *L, double lambda, int i, int colour)
{
    const grid_t *g = L->g;
    const poisson_t *op = L->op;
    double *x = L->x, *tmp = L->rowbuf;
    const double *b = L->b;
    int nu1 = level_nu(L, 1), nu2 = level_nu(L, 2), d3 = g->dim == 3;
    /* the row direction (stride 1), and the second uniform direction (stride s2; none in 2-D) */
    int n = d3 ? nu2 : nu1, nrows = d3 ? nu1 : 1, ig = i + g->ix0;
    long sx = g->sx, s2 = d3 ? g->sy : 0;
    double cin = d3 ? op->cz : op->cy, c2 = d3 ? op->cy : 0.0;
    const double *dgin = d3 ? L->dgz : L->dgy;
    double cw = op->cw[ig], ce = op->ce[ig], cdl = op->cd[ig] + lambda;
    for (int r = 0; r < nrows; r++) {
        double *xr = x + G_IDX(g, i, r, 0);
        const double *br = b + G_IDX(g, i, r, 0);
        double dout = cdl + (d3 ? L->dgy[r] : 0.0); /* diagonal from x (and y in 3-D) */
        double inv = 1.0 / (dout + 2.0 * cin);      /* interior of the row */
#define RB_UPDATE(k, invd)                                                                                     \
    (xr[k] + (cw * xr[(k) - sx] + ce * xr[(k) + sx] - cdl * xr[k] + c2 * (xr[(k) + s2] - 2.0 * xr[k] + xr[(k) - s2]) + \
              cin * (xr[(k) + 1] - 2.0 * xr[k] + xr[(k) - 1]) - br[k]) *                                                \
                 (invd))
        for (int k = 0; k < n; k++) tmp[k] = RB_UPDATE(k, inv);
        tmp[0] = RB_UPDATE(0, 1.0 / (dout + dgin[0])); /* ends of the row: BC folded in the diagonal */
        tmp[n - 1] = RB_UPDATE(n - 1, 1.0 / (dout + dgin[n - 1]));
#undef RB_UPDATE
        for (int k = (ig + r + colour) & 1; k < n; k += 2) xr[k] = tmp[k];
    }
}

/* Periodic y/z ghosts of plane i (as grid_halo_yz: z first, then whole y rows). */
static void periodic_ghosts_plane(const grid_t *g, double *f, int i)
{
    int ny = g->n[1], nz = g->n[2];
    if (g->dim == 3 && g->periodic[2])
        for (int j = 0; j < ny; j++) {
            f[G_IDX(g, i, j, -1)] = f[G_IDX(g, i, j, nz - 1)];
            f[G_IDX(g, i, j, nz)] = f[G_IDX(g, i, j, 0)];
        }
    if (g->periodic[1]) {
        memcpy(f + G_IDX(g, i, -1, -g->gz), f + G_IDX(g, i, ny - 1, -g->gz), (size_t)g->sy * sizeof(double));
        memcpy(f + G_IDX(g, i, ny, -g->gz), f + G_IDX(g, i, 0, -g->gz), (size_t)g->sy * sizeof(double));
    }
}

/* One red-black sweep in a single pass over memory: red on plane i, then
 * black on plane i−1, whose red neighbours are all new by then.  The ghosts
 * filled at the start stay valid for the black points (a Neumann or
 * Dirichlet ghost mirrors the point itself, not yet updated) except periodic
 * images, refreshed plane by plane, and the x ghost planes, exchanged before
 * the black points of the first and last planes.  Same arithmetic, hence the
 * same bits, as two half-sweeps with a full ghost fill in between. */
static void rb_sweep(mg_level_t *L, double lambda)
{
    const grid_t *g = L->g;
    poisson_fill_ghosts(L->op, L->x);
    int nux = local_nux(L);
    for (int i = 0; i < nux; i++) {
        rb_plane(L, lambda, i, 0);
        periodic_ghosts_plane(g, L->x, i);
        if (i >= 2) rb_plane(L, lambda, i - 1, 1);
    }
    grid_halo_x(g, L->x);
    if (nux >= 1) rb_plane(L, lambda, 0, 1);
    if (nux >= 2) rb_plane(L, lambda, nux - 1, 1);
}

/* ---------------------------------------------------- x-line relaxation */

/* Zebra line Gauss–Seidel along x: the lines (j, k) of one colour
 * ((j + k) mod 2) are solved exactly for their x values while the other
 * colour is held.  Used when x is stretched: thin wall cells couple strongly
 * in x, which point relaxation does not smooth (Trottenberg, Oosterlee &
 * Schüller 2001, §5.1).  A line crosses the slabs: each rank eliminates its
 * interior rows (Thomas), leaving one separator unknown (its last row); the P
 * separator equations of a line form a tridiagonal system that every rank
 * solves after one allgather (partition method).  The line solves are exact,
 * so the iterates do not depend on the rank count beyond round-off. */
typedef struct mg_line {
    double lambda; /* λ of the current factorisation (NAN: none) */
    int m;         /* local unknown rows; the last one is the separator */
    int nl[2];     /* lines of each colour */
    int *cls;      /* class (same y/z diagonal) of line (j, k): cls[j * nu2 + k] */
    double dyz[9]; /* y/z diagonal of each class */
    double *cp, *iden, *a, *c; /* [class][m]: Thomas factors of the interior rows, responses a, c */
    double nb[18]; /* [class][2]: right neighbour's a_0, c_0 */
    double *ysend, *yrecv, *red, *all, *sep, *work;
} mg_line_t;

/* Solve the interior rows (0..m−2) of a class for right-hand side f, in place. */
static void line_thomas(const mg_line_t *ln, const poisson_t *op, int ix0, int cl, double *f, long stride)
{
    int n = ln->m - 1;
    const double *cp = ln->cp + (long)cl * ln->m, *iden = ln->iden + (long)cl * ln->m;
    f[0] *= iden[0];
    for (int i = 1; i < n; i++) f[i * stride] = (f[i * stride] + op->cw[ix0 + i] * f[(i - 1) * stride]) * iden[i];
    for (int i = n - 2; i >= 0; i--) f[i * stride] -= cp[i] * f[(i + 1) * stride];
}

/* Factorise the interior rows of every class for λ and exchange the first
 * row's responses with the left neighbour (collective on the level). */
static void line_factorise(mg_level_t *L, double lambda)
{
    mg_line_t *ln = L->line;
    const poisson_t *op = L->op;
    const grid_t *g = L->g;
    int m = ln->m, ix0 = g->ix0;
    for (int cl = 0; cl < 9; cl++) {
        double *cp = ln->cp + (long)cl * m, *iden = ln->iden + (long)cl * m;
        double *a = ln->a + (long)cl * m, *c = ln->c + (long)cl * m;
        for (int i = 0; i < m - 1; i++) {
            /* row i: −cw δ_{i−1} + D δ_i − ce δ_{i+1} (the SPD form −(L − λI)) */
            double D = op->cd[ix0 + i] + lambda + ln->dyz[cl];
            double den = i == 0 ? D : D + op->cw[ix0 + i] * cp[i - 1];
            iden[i] = 1.0 / den;
            cp[i] = -op->ce[ix0 + i] * iden[i];
        }
        if (m >= 2) {
            for (int i = 0; i < m - 1; i++) a[i] = c[i] = 0.0;
            a[0] = op->cw[ix0];
            c[m - 2] = op->ce[ix0 + m - 2];
            line_thomas(ln, op, ix0, cl, a, 1);
            line_thomas(ln, op, ix0, cl, c, 1);
        }
    }
    /* What the left neighbour needs: δ_first = y_0 + a_0 δ_left + c_0 δ_sep
     * (with no interior row, δ_first is the separator itself). */
    double send[18];
    for (int cl = 0; cl < 9; cl++) {
        send[2 * cl] = m >= 2 ? ln->a[(long)cl * m] : 0.0;
        send[2 * cl + 1] = m >= 2 ? ln->c[(long)cl * m] : 1.0;
    }
    memset(ln->nb, 0, sizeof ln->nb);
    MPI_Sendrecv(send, 18, MPI_DOUBLE, g->left, 21, ln->nb, 18, MPI_DOUBLE, g->right, 21, g->comm, MPI_STATUS_IGNORE);
    ln->lambda = lambda;
}

/* Loop over the lines (j, k) of one colour in a fixed order; l counts them. */
#define FOR_LINES(colour)                                                                                      \
    for (int j = 0, l = 0; j < nu1; j++)                                                                       \
        for (int k = g->dim == 3 ? (j + colour) & 1 : ((j + colour) & 1 ? nu2 : 0); k < nu2; k += 2, l++)

static void line_half_sweep(mg_level_t *L, double lambda, int colour)
{
    mg_line_t *ln = L->line;
    const grid_t *g = L->g;
    const poisson_t *op = L->op;
    double *x = L->x, *y = L->r; /* the residual field holds the line solutions y */
    const double *b = L->b;
    if (ln->lambda != lambda) line_factorise(L, lambda);
    poisson_fill_ghosts(op, x);
    int m = ln->m, ix0 = g->ix0, nu1 = level_nu(L, 1), nu2 = level_nu(L, 2), P = g->nranks;
    long sx = g->sx, sy = g->sy;
    double cy = op->cy, cz = op->cz;
    int nl = ln->nl[colour];
    /* 1. −r on the lines and forward elimination of the interior rows, plane
     * by plane in x so that all lines advance together (k is contiguous). */
    for (int i = 0; i < m; i++) {
        double cw = op->cw[ix0 + i], ce = op->ce[ix0 + i], cdl = op->cd[ix0 + i] + lambda;
        const double *iden = ln->iden + i;
        FOR_LINES(colour) {
            long c = G_IDX(g, i, j, k);
            double ax = g->dim == 3 ? STENCIL_3D(x, c) : STENCIL_2D(x, c);
            double v = ax - b[c]; /* −r */
            if (i < m - 1) v = (i == 0 ? v : v + cw * y[c - sx]) * iden[(long)ln->cls[j * nu2 + k] * m];
            y[c] = v;
        }
    }
    /* 2. back-substitution of the interior rows */
    for (int i = m - 3; i >= 0; i--) {
        const double *cp = ln->cp + i;
        FOR_LINES(colour) {
            long c = G_IDX(g, i, j, k);
            y[c] -= cp[(long)ln->cls[j * nu2 + k] * m] * y[c + sx];
        }
    }
    /* 3. the right neighbour's y_0, then one reduced row per line:
     * sub δ_sep,q−1 + diag δ_sep,q + sup δ_sep,q+1 = rhs */
    FOR_LINES(colour) ln->ysend[l] = m >= 2 ? y[G_IDX(g, 0, j, k)] : 0.0;
    memset(ln->yrecv, 0, (size_t)nl * sizeof(double));
    if (P > 1)
        MPI_Sendrecv(ln->ysend, nl, MPI_DOUBLE, g->left, 22, ln->yrecv, nl, MPI_DOUBLE, g->right, 22, g->comm,
                     MPI_STATUS_IGNORE);
    int is = ix0 + m - 1;
    double cws = op->cw[is], ces = op->ce[is];
    FOR_LINES(colour) {
        int cl = ln->cls[j * nu2 + k];
        long cs = G_IDX(g, m - 1, j, k);
        double Ds = op->cd[is] + lambda + ln->dyz[cl];
        double yp = 0.0, ap = 1.0, cpv = 0.0; /* δ_{m−2} = yp + ap δ_left + cpv δ_sep */
        if (m >= 2) {
            yp = y[cs - sx];
            ap = ln->a[(long)cl * m + m - 2];
            cpv = ln->c[(long)cl * m + m - 2];
        }
        double *row = ln->red + 4L * l;
        row[0] = -cws * ap;
        row[1] = Ds - cws * cpv - ces * ln->nb[2 * cl];
        row[2] = -ces * ln->nb[2 * cl + 1];
        row[3] = y[cs] + cws * yp + ces * ln->yrecv[l]; /* y[cs] holds −r of the separator */
    }
    /* 4. every rank solves the P separator unknowns of every line */
    if (P > 1)
        MPI_Allgather(ln->red, 4 * nl, MPI_DOUBLE, ln->all, 4 * nl, MPI_DOUBLE, g->comm);
    else
        memcpy(ln->all, ln->red, 4L * nl * sizeof(double));
    double *w = ln->work, *v = ln->work + P;
    for (int l = 0; l < nl; l++) {
        for (int q = 0; q < P; q++) {
            const double *row = ln->all + 4L * ((long)q * nl + l);
            double den = q == 0 ? row[1] : row[1] - row[0] * w[q - 1];
            w[q] = row[2] / den;
            v[q] = (row[3] - (q == 0 ? 0.0 : row[0] * v[q - 1])) / den;
        }
        for (int q = P - 2; q >= 0; q--) v[q] -= w[q] * v[q + 1];
        ln->sep[2 * l] = g->rank > 0 ? v[g->rank - 1] : 0.0;
        ln->sep[2 * l + 1] = v[g->rank];
    }
    /* 5. x += δ, δ = y + a δ_left + c δ_sep (δ = δ_sep on the separator) */
    for (int i = 0; i < m; i++) {
        const double *a = ln->a + i, *cc = ln->c + i;
        FOR_LINES(colour) {
            long c = G_IDX(g, i, j, k);
            if (i < m - 1) {
                long o = (long)ln->cls[j * nu2 + k] * m;
                x[c] += y[c] + a[o] * ln->sep[2 * l] + cc[o] * ln->sep[2 * l + 1];
            } else
                x[c] += ln->sep[2 * l + 1];
        }
    }
}
#undef FOR_LINES

static void line_setup(mg_level_t *L)
{
    const grid_t *g = L->g;
    int m = local_nux(L), nu1 = level_nu(L, 1), nu2 = level_nu(L, 2);
    mg_line_t *ln = xcalloc(1, sizeof *ln);
    L->line = ln;
    ln->m = m;
    ln->lambda = NAN;
    ln->cls = xcalloc((size_t)nu1 * nu2, sizeof(int));
    for (int cl = 0; cl < 9; cl++) ln->dyz[cl] = L->dgy[nu1 / 2] + L->dgz[nu2 / 2];
    for (int j = 0; j < nu1; j++)
        for (int k = 0; k < nu2; k++) {
            int jc = j == 0 ? 0 : j == nu1 - 1 ? 2 : 1, kc = k == 0 ? 0 : k == nu2 - 1 ? 2 : 1;
            ln->cls[j * nu2 + k] = 3 * jc + kc;
            ln->dyz[3 * jc + kc] = L->dgy[j] + L->dgz[k];
            ln->nl[(j + k) & 1]++;
        }
    if (g->dim != 3) { /* 2-D: lines j, colour j mod 2 */
        ln->nl[0] = (nu1 + 1) / 2;
        ln->nl[1] = nu1 / 2;
    }
    int nlmax = ln->nl[0] > ln->nl[1] ? ln->nl[0] : ln->nl[1];
    ln->cp = xcalloc((size_t)9 * m, sizeof(double));
    ln->iden = xcalloc((size_t)9 * m, sizeof(double));
    ln->a = xcalloc((size_t)9 * m, sizeof(double));
    ln->c = xcalloc((size_t)9 * m, sizeof(double));
    ln->ysend = xcalloc((size_t)nlmax, sizeof(double));
    ln->yrecv = xcalloc((size_t)nlmax, sizeof(double));
    ln->red = xcalloc((size_t)4 * nlmax, sizeof(double));
    ln->all = xcalloc((size_t)4 * nlmax * g->nranks, sizeof(double));
    ln->sep = xcalloc((size_t)2 * nlmax, sizeof(double));
    ln->work = xcalloc((size_t)2 * g->nranks, sizeof(double));
}

static void line_free(mg_line_t *ln)
{
    if (!ln) return;
    free(ln->cls);
    free(ln->cp);
    free(ln->iden);
    free(ln->a);
    free(ln->c);
    free(ln->ysend);
    free(ln->yrecv);
    free(ln->red);
    free(ln->all);
    free(ln->sep);
    free(ln->work);
    free(ln);
}

static void smooth(mg_level_t *L, double lambda)
{
    if (L->line) {
        line_half_sweep(L, lambda, 0);
        line_half_sweep(L, lambda, 1);
    } else
        rb_sweep(L, lambda);
}

/* r = b − (L − λI)x on the unknowns; returns the global Σ r². */
static double residual(mg_level_t *L, double lambda, const double *x, double *r)
{
    const grid_t *g = L->g;
    const poisson_t *op = L->op;
    poisson_fill_ghosts(op, (double *)x);
    int nux = local_nux(L), nu1 = level_nu(L, 1), nu2 = level_nu(L, 2);
    long sx = g->sx, sy = g->sy;
    double cy = op->cy, cz = op->cz, s = 0.0;
    const double *b = L->b;
    for (int i = 0; i < nux; i++) {
        int ig = i + g->ix0;
        double cw = op->cw[ig], ce = op->ce[ig], cdl = op->cd[ig] + lambda;
        for (int j = 0; j < nu1; j++) {
            long c0 = G_IDX(g, i, j, 0);
            if (g->dim == 3) {
                for (int k = 0; k < nu2; k++) {
                    long c = c0 + k;
                    double v = b[c] - STENCIL_3D(x, c);
                    r[c] = v;
                    s += v * v;
                }
            } else {
                double v = b[c0] - STENCIL_2D(x, c0);
                r[c0] = v;
                s += v * v;
            }
        }
    }
    return grid_sum(g, s);
}

/* ------------------------------------------------------------ transfers */

/* Restriction of the fine residual F->r into the coarse right-hand side. */
static void restrict_residual(mg_level_t *F, mg_level_t *C)
{
    const grid_t *gf = F->g, *gc = C->g;
    double *r = F->r, *bc = C->bbuf;
    grid_halo(gf, r); /* face-centred rows reach one fine point beyond the slab or the period */
    int nux = local_nux(C), nu1 = level_nu(C, 1), nu2 = level_nu(C, 2);
    for (int I = 0; I < nux; I++) {
        const mg_row_t *rx = &F->rst[0][I];
        for (int J = 0; J < nu1; J++) {
            const mg_row_t *ry = &F->rst[1][J];
            double *out = bc + G_IDX(gc, I, J, 0);
            for (int K = 0; K < nu2; K++) out[K] = 0.0;
            for (int a = 0; a < rx->n; a++)
                for (int bb = 0; bb < ry->n; bb++) {
                    double wxy = rx->w[a] * ry->w[bb];
                    const double *in = r + G_IDX(gf, rx->idx[a], ry->idx[bb], 0);
                    for (int K = 0; K < nu2; K++) {
                        const mg_row_t *rz = &F->rst[2][K];
                        double s = 0.0;
                        for (int c = 0; c < rz->n; c++) s += rz->w[c] * in[rz->idx[c]];
                        out[K] += wxy * s;
                    }
                }
        }
    }
}

/* x_fine += P e_coarse, as a tensor product: when z is coarsened, every
 * coarse row is first interpolated along z into F->zbuf (coarse x, y; fine
 * z), so the x–y part is contiguous multiply-adds. */
static void prolong_add(mg_level_t *F, mg_level_t *C)
{
    const grid_t *gf = F->g, *gc = C->g;
    double *e = C->x, *x = F->x;
    grid_halo(gc, e); /* rows refer to the neighbour slab or the periodic image in x */
    int nux = local_nux(F), nu1 = level_nu(F, 1), nu2 = level_nu(F, 2);
    int zc = F->coarsen[2], nyc = gc->n[1];
    if (zc)
        for (int I = -1; I <= gc->nxl; I++)
            for (int J = 0; J < nyc; J++) {
                const double *in = e + G_IDX(gc, I, J, 0);
                double *zr = F->zbuf + ((long)(I + 1) * nyc + J) * nu2;
                for (int k = 0; k < nu2; k++) {
                    const mg_row_t *pz = &F->prl[2][k];
                    double s = 0.0;
                    for (int c = 0; c < pz->n; c++) s += pz->w[c] * in[pz->idx[c]];
                    zr[k] = s;
                }
            }
    for (int i = 0; i < nux; i++) {
        const mg_row_t *px = &F->prl[0][i];
        for (int j = 0; j < nu1; j++) {
            const mg_row_t *py = &F->prl[1][j];
            double *out = x + G_IDX(gf, i, j, 0);
            for (int a = 0; a < px->n; a++)
                for (int bb = 0; bb < py->n; bb++) {
                    double wxy = px->w[a] * py->w[bb];
                    if (zc) {
                        const double *zr = F->zbuf + ((long)(px->idx[a] + 1) * nyc + py->idx[bb]) * nu2;
                        for (int k = 0; k < nu2; k++) out[k] += wxy * zr[k];
                    } else {
                        const double *in = e + G_IDX(gc, px->idx[a], py->idx[bb], 0);
                        for (int k = 0; k < nu2; k++) out[k] += wxy * in[k];
                    }
                }
        }
    }
}

/* Gather the cells of a distributed level into its copy on rank 0, and back. */
static void gather_level(mg_level_t *F, mg_level_t *C, const double *src, double *dst)
{
    const grid_t *g = F->g;
    int nxl = g->nxl, n1 = g->n[1], n2 = g->n[2];
    long cnt = (long)nxl * n1 * n2, m = 0;
    for (int i = 0; i < nxl; i++)
        for (int j = 0; j < n1; j++)
            for (int k = 0; k < n2; k++) F->pack[m++] = src[G_IDX(g, i, j, k)];
    MPI_Gather(F->pack, (int)cnt, MPI_DOUBLE, F->gathered, (int)cnt, MPI_DOUBLE, 0, g->comm);
    if (!C->g) return;
    m = 0;
    for (int i = 0; i < C->g->nxl; i++)
        for (int j = 0; j < n1; j++)
            for (int k = 0; k < n2; k++) dst[G_IDX(C->g, i, j, k)] = F->gathered[m++];
}

static void scatter_add_level(mg_level_t *F, mg_level_t *C, const double *src, double *dst)
{
    const grid_t *g = F->g;
    int nxl = g->nxl, n1 = g->n[1], n2 = g->n[2];
    long cnt = (long)nxl * n1 * n2, m = 0;
    if (C->g)
        for (int i = 0; i < C->g->nxl; i++)
            for (int j = 0; j < n1; j++)
                for (int k = 0; k < n2; k++) F->gathered[m++] = src[G_IDX(C->g, i, j, k)];
    MPI_Scatter(F->gathered, (int)cnt, MPI_DOUBLE, F->pack, (int)cnt, MPI_DOUBLE, 0, g->comm);
    m = 0;
    for (int i = 0; i < nxl; i++)
        for (int j = 0; j < n1; j++)
            for (int k = 0; k < n2; k++) {
                double v = F->pack[m++];
                if (poisson_is_unknown(F->op, i, j, k)) dst[G_IDX(g, i, j, k)] += v;
            }
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
 * the zero-mean subspace by projecting the residual and the preconditioned
 * residual. */
static void coarse_solve(mg_level_t *L, double lambda)
{
    const grid_t *g = L->g;
    poisson_t *op = L->op;
    int sing = op->singular && lambda == 0.0;
    double *x = L->x, *r = L->r, *z = L->cg_z, *d = L->cg_d, *q = L->cg_q;
    int nux = local_nux(L), nu1 = level_nu(L, 1), nu2 = level_nu(L, 2);
    long nunk = (long)op->nu[0] * nu1 * nu2;
    residual(L, lambda, x, r);
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

/* The part of a V-cycle after the residual L->r of the current x is known:
 * coarse-grid correction and post-smoothing. */
static void correct(mg_t *m, int l, double lambda, const poisson_opts_t *o)
{
    mg_level_t *L = &m->lev[l], *C = &m->lev[l + 1];
    if (L->link == LINK_GATHER) {
        /* the same grid on rank 0 solves for the correction */
        gather_level(L, C, L->r, C->bbuf);
        if (C->g) {
            field_zero(C->g, C->x);
            vcycle(m, l + 1, lambda, o);
        }
        scatter_add_level(L, C, C->x, L->x);
        return;
    }
    restrict_residual(L, C);
    /* The restriction keeps Σ w r = 0; remove the round-off left over. */
    if (C->op->singular && lambda == 0.0) poisson_add_constant(C->op, C->bbuf, -poisson_weighted_mean(C->op, C->bbuf));
    field_zero(C->g, C->x);
    vcycle(m, l + 1, lambda, o);
    prolong_add(L, C);
    for (int s = 0; s < o->mg_post; s++) smooth(L, lambda);
}

/* Pre-smoothing (none before a gather: the copy on rank 0 smooths), then the
 * residual; returns its global Σ r². */
static double presmooth_residual(mg_level_t *L, double lambda, const poisson_opts_t *o)
{
    if (L->link != LINK_GATHER)
        for (int s = 0; s < o->mg_pre; s++) smooth(L, lambda);
    return residual(L, lambda, L->x, L->r);
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

/* ------------------------------------------------------------- set-up */

/* Prolongation row of fine point ig (global) of direction d: coarse GLOBAL
 * indices and weights, boundary conditions folded in (Neumann: mirror,
 * Dirichlet ghost: antisymmetric mirror, Dirichlet face: the boundary value
 * 0 drops out, periodic: wrapped), so a row only refers to coarse unknowns. */
static mg_row_t prolong_row(const mg_level_t *F, const mg_level_t *C, int d, int ig)
{
    const grid_t *gf = F->g, *gc = C->g;
    const poisson_t *op = F->op;
    int face = (int)op->loc == d, nc = gc->n[d], nuc = C->op->nu[d], per = op->ebc[d][0] == EBC_PERIODIC;
    mg_row_t row = {0, {0, 0, 0, 0}, {0, 0, 0, 0}};
    int lo;
    double wlo;
    if (face && ig % 2 == 1) { /* fine face 2I+1 is coarse face I */
        row.n = 1;
        row.idx[0] = (ig - 1) / 2;
        row.w[0] = 1.0;
        return row;
    }
    lo = face ? ig / 2 - 1 : (ig % 2 == 0 ? ig / 2 - 1 : ig / 2);
    if (d == 0) { /* linear interpolation in the stretched coordinate */
        double a = face ? gc->gxf[lo] : gc->gxc[lo], b = face ? gc->gxf[lo + 1] : gc->gxc[lo + 1];
        double p = face ? gf->gxf[ig] : gf->gxc[ig];
        wlo = (b - p) / (b - a);
    } else
        wlo = face ? 0.5 : (ig % 2 == 0 ? 0.25 : 0.75);
    int idx[2] = {lo, lo + 1};
    double w[2] = {wlo, 1.0 - wlo};
    for (int e = 0; e < 2; e++) {
        int I = idx[e];
        double we = w[e];
        if (per)
            I = (I % nc + nc) % nc;
        else if (I < 0 || I >= nuc) {
            int s = I < 0 ? 0 : 1;
            ebc_t t = op->ebc[d][s];
            if (t == EBC_DIRICHLET_FACE) continue; /* boundary value 0 */
            I = s ? nuc - 1 : 0;
            if (t == EBC_DIRICHLET_GHOST) we = -we;
        }
        int k;
        for (k = 0; k < row.n && row.idx[k] != I; k++) {}
        if (k == row.n) {
            row.idx[row.n] = I;
            row.w[row.n++] = 0.0;
        }
        row.w[k] += we;
    }
    return row;
}

/* Local index of global index ig on a level, for direction d: x indices are
 * shifted by the slab's first cell and a periodic image is taken into the
 * ghost range −1..nxl; y and z are not distributed. */
static int to_local(const grid_t *g, int d, int ig)
{
    if (d != 0) return ig;
    int l = ig - g->ix0;
    if (g->periodic[0]) {
        if (l < -1) l += g->n[0];
        if (l > g->nxl) l -= g->n[0];
    }
    return l;
}

static double dir_weight(const mg_level_t *L, int d, int ig) { return d == 0 ? poisson_x_weight(L->op, ig) : 1.0; }

/* Rows of the 1-D transfers of direction d between fine level F and coarse
 * level C (both present on this rank, same decomposition).  Prolongation:
 * linear interpolation (prolong_row).  Restriction: its adjoint in the
 * weighted inner product, R = W_c⁻¹ Pᵀ W_f (¼ ½ ¼ for faces, ⅛ ⅜ ⅜ ⅛ for
 * cells on a uniform grid); with point smoothing a cell-centred direction
 * uses the volume-weighted mean of the two children instead (measured: V(2,2)
 * factor 0.10 against 0.17 in 3-D; with line smoothing the adjoint gives 0.025
 * against 0.23).  Both keep Σ w r exactly when P reproduces constants
 * (periodic and Neumann directions, i.e. whenever the problem can be
 * singular). */
static void build_transfer(mg_level_t *F, mg_level_t *C, int d, int adjoint)
{
    const grid_t *gf = F->g, *gc = C->g;
    int nf = d == 0 ? gf->nxl : gf->n[d], nc = d == 0 ? gc->nxl : gc->n[d];
    mg_row_t *R = xcalloc((size_t)nc, sizeof(mg_row_t)), *P = xcalloc((size_t)nf, sizeof(mg_row_t));
    F->rst[d] = R;
    F->prl[d] = P;
    if (!F->coarsen[d]) {
        for (int i = 0; i < nf; i++) P[i] = (mg_row_t){1, {i, 0, 0, 0}, {1.0, 0, 0, 0}};
        for (int i = 0; i < nc; i++) R[i] = (mg_row_t){1, {i, 0, 0, 0}, {1.0, 0, 0, 0}};
        return;
    }
    int off_f = d == 0 ? gf->ix0 : 0, off_c = d == 0 ? gc->ix0 : 0;
    int nfg = gf->n[d], nuf = F->op->nu[d], nuc = C->op->nu[d], per = gf->periodic[d];
    double wscale = d == 0 ? 1.0 : 0.5; /* W_f / W_c of a uniform direction */
    for (int i = 0; i < nf; i++) {
        int ig = i + off_f;
        if (ig >= nuf) continue;
        P[i] = prolong_row(F, C, d, ig);
        for (int e = 0; e < P[i].n; e++) P[i].idx[e] = to_local(gc, d, P[i].idx[e]);
    }
    int face = (int)F->op->loc == d;
    for (int I = 0; I < nc; I++) {
        int Ig = I + off_c;
        if (Ig >= nuc) continue;
        mg_row_t row = {0, {0, 0, 0, 0}, {0, 0, 0, 0}};
        if (!face && !adjoint) {
            double ws = 0.0;
            for (int c = 0; c < 2; c++) {
                row.idx[c] = to_local(gf, d, 2 * Ig + c);
                row.w[c] = dir_weight(F, d, 2 * Ig + c);
                ws += row.w[c];
            }
            row.n = 2;
            row.w[0] /= ws;
            row.w[1] /= ws;
            R[I] = row;
            continue;
        }
        for (int c = -1; c <= 2; c++) { /* the fine points whose rows can refer to coarse Ig */
            int ig = 2 * Ig + c;
            if (per)
                ig = (ig % nfg + nfg) % nfg;
            else if (ig < 0 || ig >= nuf)
                continue;
            mg_row_t pr = prolong_row(F, C, d, ig);
            double w = 0.0;
            for (int e = 0; e < pr.n; e++)
                if (pr.idx[e] == Ig) w += pr.w[e];
            if (w == 0.0) continue;
            w *= d == 0 ? dir_weight(F, 0, ig) / dir_weight(C, 0, Ig) : wscale;
            row.idx[row.n] = to_local(gf, d, ig);
            row.w[row.n++] = w;
        }
        R[I] = row;
    }
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
                if (mmin >= 1) line_setup(L);
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
        for (int d = 0; d < 3; d++) build_transfer(F, C, d, line);
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
        line_free(L->line);
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
    /* Convergence is tested on the residual computed after pre-smoothing
     * (the one the cycle restricts), so the fine level needs one residual
     * per cycle; the solve stops there, and last_residual is exactly the
     * residual of the returned x. */
    double bn = sqrt(sum_squares(L0, b)), rn = 0.0;
    int it = 0, rc = 0;
    if (bn > 0.0)
        for (;;) {
            rn = sqrt(L0->link == LINK_NONE ? residual(L0, lambda, x, L0->r) : presmooth_residual(L0, lambda, &p->opt));
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
