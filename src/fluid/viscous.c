/* viscous.c — the viscous term ν∇·(∇u + ∇uᵀ) = ν∇²u (constant ν,
 * ∇·∇uᵀ = ∇(∇·u) = 0; decision 2 of the reference notes: no factor ½).
 *
 * The Laplacian of each component is THE operator of src/poisson/poisson.c
 * (coefficients cw/ce/cd in x, cy and cz in y and z), so that the explicit
 * viscous term, the Crank–Nicolson Helmholtz solves and the operator tests
 * share one discretisation.  poisson.c folds the HOMOGENEOUS boundary
 * conditions into its x coefficients; a moving no-slip wall adds the
 * inhomogeneous part: with ghost = 2U − interior, the cell next to the wall
 * gets + c_wall · 2U, c_wall being the coefficient the ghost would have had.
 * In y and z the stencil is applied to the true ghosts (bc.c), which already
 * hold 2U − interior.
 *
 * wall_ghost = quadratic (docs/theory.md §4.3): the ghost of a tangential
 * component at a no-slip wall is instead the value at the ghost centre of the
 * parabola through the wall value U (distance 0), u_0 (d_0) and u_1 (d_1):
 * at distance −d_g,
 *     g_quad = a_U U + a_0 u_0 + a_1 u_1,
 *     a_U = (d_g+d_0)(d_g+d_1)/(d_0 d_1),  a_0 = −d_g(d_g+d_1)/(d_0(d_1−d_0)),
 *     a_1 = d_g(d_g+d_0)/(d_1(d_1−d_0))
 * (uniform: 8/3, −2, 1/3), exact for quadratic profiles on stretched grids
 * too.  The stored ghosts stay linear (bc.c: the face value, mean of ghost
 * and interior, is the wall velocity for every other reader); the operator
 * adds c_wall (g_quad − g_lin) at the wall cells (fluid_wall_ghost_add).
 */
#include <string.h>

#include "fluid_internal.h"

/* Coefficient of the ghost of a cell-centred x unknown at the x wall s in
 * the row of the wall cell (flux through the wall face / cell volume, as in
 * poisson_create: w at i = 0, e at i = nx−1). */
static double x_wall_coef(const grid_t *g, int s)
{
    int nx = g->n[0], axi = g->geom == GEOM_AXI;
    int i = s == 0 ? 0 : nx - 1, fw = s == 0 ? -1 : nx - 1, cc = s == 0 ? -1 : nx - 1;
    double a_face = axi ? g->gxf[fw] : 1.0, vol = (axi ? g->gxc[i] : 1.0) * g->gdxf[i];
    return a_face / (g->gdxc[cc] * vol);
}

/* The quadratic-ghost wall term of component c at the no-slip wall (d, s):
 * distances from the wall of the first two cell centres (d0, d1) and of the
 * ghost centre (dg), and the coefficient c_wall of the ghost in the row. */
static wall_quad_t wall_quad_setup(const grid_t *g, int c, int d, int s)
{
    double d0, d1, dg, cw;
    if (d == 0) {
        int nx = g->n[0];
        if (s == 0) {
            double xw = g->gxf[-1];
            d0 = g->gxc[0] - xw, d1 = g->gxc[1] - xw, dg = xw - g->gxc[-1];
        } else {
            double xw = g->gxf[nx - 1];
            d0 = xw - g->gxc[nx - 1], d1 = xw - g->gxc[nx - 2], dg = g->gxc[nx] - xw;
        }
        cw = x_wall_coef(g, s);
    } else {
        double h = d == 1 ? g->dy : g->dz;
        d0 = 0.5 * h, d1 = 1.5 * h, dg = 0.5 * h;
        cw = 1.0 / (h * h);
    }
    double aU = (dg + d0) * (dg + d1) / (d0 * d1), a0 = -dg * (dg + d1) / (d0 * (d1 - d0)),
           a1 = dg * (dg + d0) / (d1 * (d1 - d0));
    /* minus the linear ghost 2U − u_0 */
    return (wall_quad_t){.on = 1, .kU = cw * (aU - 2.0) * g->bc.vel[d][s][c], .k0 = cw * (a0 + 1.0), .k1 = cw * a1};
}

void fluid_viscous_setup(fluid_t *f)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    memset(q->xwall, 0, sizeof q->xwall);
    memset(q->wq, 0, sizeof q->wq);
    q->wq_any = 0;
    for (int c = 0; c < fluid_ncomp(g); c++)
        for (int d = 0; d < g->dim; d++)
            for (int s = 0; s < 2; s++) {
                if (d == c || g->periodic[d] || g->bc.type[d][s] != BC_NOSLIP) continue;
                if (d == 0) q->xwall[c][s] = 2.0 * g->bc.vel[0][s][c] * x_wall_coef(g, s);
                if (f->prm.wall_ghost == WALL_GHOST_QUADRATIC) {
                    q->wq[c][d][s] = wall_quad_setup(g, c, d, s);
                    q->wq_any = 1;
                }
            }
}

/* out += scale · L u_c on the unknowns of component c, u with true ghosts. */
void fluid_laplacian_add(const fluid_t *f, int c, const double *u, double scale, double *out)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const poisson_t *p = q->pv[c];
    long sx = g->sx, sy = g->sy;
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2), nx = g->n[0];
    double cy = p->cy, cz = p->cz;
    for (int i = 0; i < iend; i++) {
        int ig = i + g->ix0;
        double cw = p->cw[ig], ce = p->ce[ig], cd = p->cd[ig];
        double wall = (ig == 0 ? q->xwall[c][0] : 0.0) + (ig == nx - 1 ? q->xwall[c][1] : 0.0);
        for (int j = 0; j < nj; j++) {
            long c0 = G_IDX(g, i, j, 0);
            if (g->dim == 3) {
                for (int k = 0; k < nk; k++) {
                    long m = c0 + k;
                    double uc = u[m];
                    double L = cw * u[m - sx] + ce * u[m + sx] - cd * uc + cy * (u[m + sy] - 2.0 * uc + u[m - sy]) +
                               cz * (u[m + 1] - 2.0 * uc + u[m - 1]);
                    out[m] += scale * (L + wall);
                }
            } else {
                double uc = u[c0];
                double L = cw * u[c0 - sx] + ce * u[c0 + sx] - cd * uc + cy * (u[c0 + sy] - 2.0 * uc + u[c0 - sy]);
                out[c0] += scale * (L + wall);
            }
        }
    }
    fluid_wall_ghost_add(f, c, u, scale, out);
}

/* out += scale · (inhomogeneous wall part of L u_c): what the true operator
 * adds to poisson_apply's homogeneous one at the cells next to moving walls
 * (the right-hand side of the Crank–Nicolson Helmholtz solves). */
void fluid_wall_terms_add(const fluid_t *f, int c, double scale, double *out)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const poisson_t *p = q->pv[c];
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2), nx = g->n[0];
    /* walls at rest (the common case): every term below is 0, nothing to add
     * (this loop over every cell was 15 % of the axisymmetric bounce) */
    int moving = q->xwall[c][0] != 0.0 || q->xwall[c][1] != 0.0;
    for (int d = 1; d < g->dim; d++)
        for (int s = 0; s < 2; s++)
            moving |= d != c && !g->periodic[d] && g->bc.type[d][s] == BC_NOSLIP && g->bc.vel[d][s][c] != 0.0;
    if (!moving) return;
    for (int i = 0; i < iend; i++) {
        int ig = i + g->ix0;
        double wx = (ig == 0 ? q->xwall[c][0] : 0.0) + (ig == nx - 1 ? q->xwall[c][1] : 0.0);
        for (int j = 0; j < nj; j++)
            for (int k = 0; k < nk; k++) {
                double w = wx;
                for (int d = 1; d < g->dim; d++) {
                    if (d == c || g->periodic[d]) continue;
                    int idx = d == 1 ? j : k, nd = g->n[d];
                    double cd = d == 1 ? p->cy : p->cz;
                    if (idx == 0 && g->bc.type[d][0] == BC_NOSLIP) w += 2.0 * g->bc.vel[d][0][c] * cd;
                    if (idx == nd - 1 && g->bc.type[d][1] == BC_NOSLIP) w += 2.0 * g->bc.vel[d][1][c] * cd;
                }
                out[G_IDX(g, i, j, k)] += scale * w;
            }
    }
}

/* out += scale · (L_quad − L_lin) u_c at the wall cells of the no-slip walls
 * tangential to c (nothing with wall_ghost = linear).  u needs valid ghost
 * planes in x where the neighbour u_1 of an x-wall cell lies on the next
 * rank (one cell per rank). */
void fluid_wall_ghost_add(const fluid_t *f, int c, const double *u, double scale, double *out)
{
    const fluid_priv_t *q = fluid_priv(f);
    if (!q->wq_any) return;
    const grid_t *g = f->g;
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    for (int d = 0; d < g->dim; d++)
        for (int s = 0; s < 2; s++) {
            const wall_quad_t *w = &q->wq[c][d][s];
            if (!w->on) continue;
            /* the wall cell's range: the plane index along d fixed */
            int lo[3] = {0, 0, 0}, hi[3] = {iend, nj, nk};
            long nb; /* offset of u_1 from u_0 */
            if (d == 0) {
                int i = (s == 0 ? 0 : g->n[0] - 1) - g->ix0;
                if (i < 0 || i >= g->nxl) continue;
                lo[0] = i, hi[0] = i + 1, nb = s == 0 ? g->sx : -g->sx;
            } else {
                int m = s == 0 ? 0 : g->n[d] - 1;
                lo[d] = m, hi[d] = m + 1, nb = d == 1 ? (s == 0 ? g->sy : -g->sy) : (s == 0 ? 1 : -1);
            }
            double a = scale * w->kU, b0 = scale * w->k0, b1 = scale * w->k1;
            for (int i = lo[0]; i < hi[0]; i++)
                for (int j = lo[1]; j < hi[1]; j++)
                    for (int k = lo[2]; k < hi[2]; k++) {
                        long m = G_IDX(g, i, j, k);
                        out[m] += a + b0 * u[m] + b1 * u[m + nb];
                    }
        }
}

double fluid_laplacian_at(const fluid_t *f, int c, const double *u, int i, long m)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const poisson_t *p = q->pv[c];
    const int ig = i + g->ix0, nx = g->n[0];
    const long sx = g->sx, sy = g->sy;
    const double uc = u[m];
    double L = p->cw[ig] * u[m - sx] + p->ce[ig] * u[m + sx] - p->cd[ig] * uc + p->cy * (u[m + sy] - 2.0 * uc + u[m - sy]);
    if (g->dim == 3) L += p->cz * (u[m + 1] - 2.0 * uc + u[m - 1]);
    L += (ig == 0 ? q->xwall[c][0] : 0.0) + (ig == nx - 1 ? q->xwall[c][1] : 0.0);
    if (!q->wq_any) return L;
    /* the quadratic wall ghost at a wall cell (fluid_wall_ghost_add) */
    const long rem = m - (long)(i + 1) * sx;
    const int idx[3] = {ig, (int)(rem / sy) - 1, (int)(rem % sy) - g->gz};
    const long step[3] = {sx, sy, 1};
    for (int d = 0; d < g->dim; d++)
        for (int s = 0; s < 2; s++) {
            const wall_quad_t *w = &q->wq[c][d][s];
            if (!w->on || idx[d] != (s == 0 ? 0 : g->n[d] - 1)) continue;
            L += w->kU + w->k0 * uc + w->k1 * u[m + (s == 0 ? step[d] : -step[d])];
        }
    return L;
}

void fluid_viscous(const fluid_t *f, double *const out[3])
{
    const grid_t *g = f->g;
    for (int c = 0; c < fluid_ncomp(g); c++) {
        field_zero(g, out[c]);
        fluid_laplacian_add(f, c, f->u[c], f->prm.nu, out[c]);
    }
}
