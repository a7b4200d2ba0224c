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

static inline __attribute__((always_inline)) void div_line(const double *restrict u, const double *restrict v,
                                                            const double *restrict w, double *restrict div, long c0,
                                                            long len, long sx, long sy, double a, double b, double rdy,
                                                            double rdz, double scale, int is3d)
{
    for (long m = c0; m < c0 + len; m++) {
        double d = a * u[m] - b * u[m - sx] + (v[m] - v[m - sy]) * rdy;
        if (is3d) d += (w[m] - w[m - 1]) * rdz;
        div[m] = scale * d;
    }
}

void fluid_divergence_scaled(const fluid_t *f, double scale, double *div)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    for (int i = 0; i < g->nxl; i++) {
        double a = q->af[i] / (q->ac[i] * g->dxf[i]), b = q->af[i - 1] / (q->ac[i] * g->dxf[i]);
        FLUID_FOR_LINES(g, i, g->n[1], g->n[2], c0, len)
        {
            if (w) div_line(u, v, w, div, c0, len, g->sx, g->sy, a, b, rdy, rdz, scale, 1);
            else div_line(u, v, w, div, c0, len, g->sx, g->sy, a, b, rdy, rdz, scale, 0);
        }
    }
}

void fluid_divergence(const fluid_t *f, double *div) { fluid_divergence_scaled(f, 1.0, div); }

/* max |D u| (into m[0]) and max over the cells of the convective rate
 * Σ_d max(|u_d| at the two faces)/Δ_d (into m[1]) along one line: the
 * divergence is the one of div_line (the same per-i coefficients), written
 * without branches or divisions so that the loop vectorises. */
static inline __attribute__((always_inline)) void div_cfl_line(const double *restrict u, const double *restrict v,
                                                                const double *restrict w, long c0, long len, long sx,
                                                                long sy, double a, double b, double rdx, double rdy,
                                                                double rdz, double *m, int is3d)
{
    double dm = m[0], sm = m[1];
    for (long c = c0; c < c0 + len; c++) {
        double d = a * u[c] - b * u[c - sx] + (v[c] - v[c - sy]) * rdy;
        double s = dmax(fabs(u[c]), fabs(u[c - sx])) * rdx + dmax(fabs(v[c]), fabs(v[c - sy])) * rdy;
        if (is3d) {
            d += (w[c] - w[c - 1]) * rdz;
            s += dmax(fabs(w[c]), fabs(w[c - 1])) * rdz;
        }
        dm = dmax(dm, fabs(d));
        sm = dmax(sm, s);
    }
    m[0] = dm;
    m[1] = sm;
}

/* this rank's max |D u| and max convective rate, updating m[0], m[1] */
static void divergence_cfl_rate(const fluid_t *f, double *m)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    for (int i = 0; i < g->nxl; i++) {
        double a = q->af[i] / (q->ac[i] * g->dxf[i]), b = q->af[i - 1] / (q->ac[i] * g->dxf[i]), rdx = 1.0 / g->dxf[i];
        FLUID_FOR_LINES(g, i, g->n[1], g->n[2], c0, len)
        {
            if (w) div_cfl_line(u, v, w, c0, len, g->sx, g->sy, a, b, rdx, rdy, rdz, m, 1);
            else div_cfl_line(u, v, w, c0, len, g->sx, g->sy, a, b, rdx, rdy, rdz, m, 0);
        }
    }
}

double fluid_max_divergence(const fluid_t *f)
{
    double loc[2] = {0.0, 0.0};
    divergence_cfl_rate(f, loc);
    return grid_max(f->g, loc[0]);
}

/* Σ V u² (this rank) and max |u| over the unknowns of component c. */
static void component_stats(const fluid_t *f, int c, double *e, double *umax)
{
    const grid_t *g = f->g;
    const double *u = f->u[c];
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    double m = 0.0, sum = 0.0;
    for (int i = 0; i < iend; i++) {
        double s = 0.0;
        for (int j = 0; j < nj; j++) {
            const double *r = u + G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) {
                s += r[k] * r[k];
                m = dmax(m, fabs(r[k]));
            }
        }
        sum += fluid_cell_volume(f, c, i) * s;
    }
    *e += sum;
    *umax = dmax(*umax, m);
}

double fluid_kinetic_energy(const fluid_t *f)
{
    const grid_t *g = f->g;
    double e = 0.0, m = 0.0;
    for (int c = 0; c < fluid_ncomp(g); c++) component_stats(f, c, &e, &m);
    e = 0.5 * grid_sum(g, e);
    return g->geom == GEOM_AXI ? 2.0 * M_PI * e : e;
}

/* One sweep over the cells for the divergence and the convective rate (and,
 * unless the last projection gave them, one per component for the energy and
 * max |u|), two reductions. */
void fluid_update_diagnostics(fluid_t *f, const double *stats)
{
    const grid_t *g = f->g;
    double loc[3] = {0, 0, 0}, glob[3]; /* max |D u|, max Σ|u_d|/Δ_d, max |u| */
    divergence_cfl_rate(f, loc);
    double e = 0.0;
    if (stats) {
        e = stats[0];
        loc[2] = stats[1];
    } else
        for (int c = 0; c < fluid_ncomp(g); c++) component_stats(f, c, &e, &loc[2]);
    MPI_Allreduce(loc, glob, 3, MPI_DOUBLE, MPI_MAX, g->comm);
    e = 0.5 * grid_sum(g, e);
    f->diag.ke = g->geom == GEOM_AXI ? 2.0 * M_PI * e : e;
    f->diag.cfl = f->diag.dt * glob[1];
    /* |D u| relative to the largest velocity over the smallest cell */
    double dmin = fmin(g->dy, g->dim == 3 ? g->dz : g->dy);
    for (int i = 0; i < g->n[0]; i++) dmin = fmin(dmin, g->gdxf[i]);
    f->diag.div_max = glob[2] > 0 ? glob[0] * dmin / glob[2] : glob[0];
}
