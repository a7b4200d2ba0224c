/* diagnostics.c — discrete divergence, kinetic energy, control volumes and
 * the per-step diagnostics. */
#include <math.h>

#include "fluid_internal.h"

double fluid_cell_volume(const fluid_t *f, int c, int i)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    double yz = g->dy * (g->dim == 3 ? g->dz : 1.0);
    /* u: from x_c,i to x_c,i+1 (area factor at the face); v, w: the pressure
     * cell's x extent.  These weights make G = −Dᵀ and the advection
     * skew-symmetric (advection.c). */
    return c == 0 ? q->af[i] * g->dxc[i] * yz : q->ac[i] * g->dxf[i] * yz;
}

/* D u at cell (i,j,k): the divergence whose adjoint is the gradient of the
 * projection, so that L_P = D·G (poisson.c). */
static inline double div_at(const fluid_t *f, long m, int i)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1];
    double d = (q->af[i] * u[m] - q->af[i - 1] * u[m - g->sx]) / (q->ac[i] * g->dxf[i]) + (v[m] - v[m - g->sy]) / g->dy;
    if (g->dim == 3) d += (f->u[2][m] - f->u[2][m - 1]) / g->dz;
    return d;
}

void fluid_divergence(const fluid_t *f, double *div)
{
    const grid_t *g = f->g;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                long m = G_IDX(g, i, j, k);
                div[m] = div_at(f, m, i);
            }
}

double fluid_max_divergence(const fluid_t *f)
{
    const grid_t *g = f->g;
    double dm = 0.0;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) dm = fmax(dm, fabs(div_at(f, G_IDX(g, i, j, k), i)));
    return grid_max(g, dm);
}

double fluid_kinetic_energy(const fluid_t *f)
{
    const grid_t *g = f->g;
    double e = 0.0;
    for (int c = 0; c < fluid_ncomp(g); c++) {
        const double *u = f->u[c];
        int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
        for (int i = 0; i < iend; i++) {
            double s = 0.0;
            for (int j = 0; j < nj; j++)
                for (int k = 0; k < nk; k++) {
                    double x = u[G_IDX(g, i, j, k)];
                    s += x * x;
                }
            e += fluid_cell_volume(f, c, i) * s;
        }
    }
    e = 0.5 * grid_sum(g, e);
    return g->geom == GEOM_AXI ? 2.0 * M_PI * e : e;
}

static double max_abs_velocity(const fluid_t *f)
{
    const grid_t *g = f->g;
    double m = 0.0;
    for (int c = 0; c < fluid_ncomp(g); c++) {
        int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
        for (int i = 0; i < iend; i++)
            for (int j = 0; j < nj; j++)
                for (int k = 0; k < nk; k++) m = fmax(m, fabs(f->u[c][G_IDX(g, i, j, k)]));
    }
    return grid_max(g, m);
}

void fluid_update_diagnostics(fluid_t *f)
{
    const grid_t *g = f->g;
    f->diag.ke = fluid_kinetic_energy(f);
    f->diag.cfl = f->diag.dt * fluid_convective_rate(f);
    /* |D u| relative to the largest velocity difference across a cell */
    double dmin = fmin(g->dy, g->dim == 3 ? g->dz : g->dy);
    for (int i = 0; i < g->n[0]; i++) dmin = fmin(dmin, g->gdxf[i]);
    double umax = max_abs_velocity(f), dv = fluid_max_divergence(f);
    f->diag.div_max = umax > 0 ? dv * dmin / umax : dv;
}
