/* mg_smooth.c — the multigrid smoothers: red-black Gauss–Seidel by x planes,
 * zebra x-line relaxation for stretched x, and the residual (multigrid.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mg_internal.h"
#include "util.h"

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
 * in x, which point relaxation does not mg_smooth (Trottenberg, Oosterlee &
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
    double *x = L->x, *y = L->r; /* the mg_residual field holds the line solutions y */
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

void mg_line_setup(mg_level_t *L)
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

void mg_line_free(mg_line_t *ln)
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

void mg_smooth(mg_level_t *L, double lambda)
{
    if (L->line) {
        line_half_sweep(L, lambda, 0);
        line_half_sweep(L, lambda, 1);
    } else
        rb_sweep(L, lambda);
}

/* r = b − (L − λI)x on the unknowns; returns the global Σ r². */
double mg_residual(mg_level_t *L, double lambda, const double *x, double *r)
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

