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
 */
#include <string.h>

#include "fluid_internal.h"

void fluid_viscous_setup(fluid_t *f)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    int nx = g->n[0], axi = g->geom == GEOM_AXI;
    memset(q->xwall, 0, sizeof q->xwall);
    if (g->periodic[0]) return;
    for (int c = 1; c < fluid_ncomp(g); c++)
        for (int s = 0; s < 2; s++) {
            if (g->bc.type[0][s] != BC_NOSLIP) continue;
            /* cell-centred in x: flux through the wall face / cell volume, as in
             * poisson_create (w at i = 0, e at i = nx−1) */
            int i = s == 0 ? 0 : nx - 1, fw = s == 0 ? -1 : nx - 1, cc = s == 0 ? -1 : nx - 1;
            double a_face = axi ? g->gxf[fw] : 1.0, vol = (axi ? g->gxc[i] : 1.0) * g->gdxf[i];
            double coef = a_face / (g->gdxc[cc] * vol);
            q->xwall[c][s] = 2.0 * g->bc.vel[0][s][c] * coef;
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

void fluid_viscous(const fluid_t *f, double *const out[3])
{
    const grid_t *g = f->g;
    for (int c = 0; c < fluid_ncomp(g); c++) {
        field_zero(g, out[c]);
        fluid_laplacian_add(f, c, f->u[c], f->prm.nu, out[c]);
    }
}
