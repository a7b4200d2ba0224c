/* timestep.c — the time step allowed by the stability of RK3.
 *
 * Convective limit: central advection has imaginary eigenvalues bounded by
 * Σ_d |u_d|/Δ_d; RK3 is stable on the imaginary axis up to √3, so
 * CFL = Δt · max_cells Σ_d |u_d|/Δ_d ≤ cfl (default 0.5).
 * Viscous limit (explicit only): the eigenvalues of νL are real, negative and
 * bounded by ν ρ(L) with ρ(L) ≤ max row sum of |L| (Gershgorin; 4Σ_d 1/Δ_d²
 * on a uniform grid, the exact spectral radius in the limit); RK3 is stable on
 * the negative real axis up to 2.51, so Fo = Δt ν ρ(L)/4 ≤ fourier
 * (default 0.5, stable up to 0.628).
 * With the quadratic wall ghost the wall-cell rows change (viscous.c): in a
 * uniform direction the row −3u_0 + u_1 (times 1/Δ²) becomes −4u_0 + (4/3)u_1,
 * Gershgorin 16/3 instead of 4; the 1-D operator keeps real negative
 * eigenvalues (positive off-diagonal products) and its spectral radius is
 * 8/√3 = 4.62 (n ≥ 8; 4 with the linear ghost), so the bound stays safe,
 * 15 % above the true value in that direction.
 */
#include <float.h>
#include <math.h>

#include "fluid_internal.h"
#include "util.h"

double fluid_convective_rate(const fluid_t *f)
{
    const grid_t *g = f->g;
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0, r = 0.0;
    for (int i = 0; i < g->nxl; i++) {
        double rdx = 1.0 / g->dxf[i];
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                long m = G_IDX(g, i, j, k);
                double s = dmax(fabs(u[m]), fabs(u[m - g->sx])) * rdx + dmax(fabs(v[m]), fabs(v[m - g->sy])) * rdy;
                if (w) s += dmax(fabs(w[m]), fabs(w[m - 1])) * rdz;
                r = dmax(r, s);
            }
    }
    return grid_max(g, r);
}

/* ρ(L)/4 bound: max over the velocity locations of the Gershgorin row sum / 4
 * (x rows, plus the largest y and z rows) */
static double viscous_rate(const fluid_t *f)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    double r = 0.0;
    for (int c = 0; c < fluid_ncomp(g); c++) {
        const poisson_t *p = q->pv[c];
        const wall_quad_t *wx = q->wq[c][0];
        double rx = 0.0;
        for (int i = 0; i < p->nu[0]; i++) {
            /* L_quad − L_lin = k0 u_0 + k1 u_1 (+ const) in a wall row: k1 on
             * the neighbour away from the wall (e at the low wall, w at the high) */
            double cw = p->cw[i], ce = p->ce[i], cd = p->cd[i];
            if (i == 0 && wx[0].on) cd -= wx[0].k0, ce += wx[0].k1;
            if (i == p->nu[0] - 1 && wx[1].on) cd -= wx[1].k0, cw += wx[1].k1;
            rx = fmax(rx, fabs(cw) + fabs(ce) + fabs(cd));
        }
        /* y, z: the largest row sum over 4 (1/Δ² at a linear-ghost or interior row) */
        double ceff[3] = {0.0, p->cy, p->cz};
        for (int d = 1; d < 3; d++)
            for (int s = 0; s < 2; s++) {
                const wall_quad_t *w = &q->wq[c][d][s];
                double cc = d == 1 ? p->cy : p->cz;
                if (w->on) ceff[d] = fmax(ceff[d], 0.25 * (fabs(-3.0 * cc + w->k0) + fabs(cc + w->k1)));
            }
        r = fmax(r, rx + 4.0 * (ceff[1] + ceff[2]));
    }
    return 0.25 * r;
}

double fluid_viscous_limit(const fluid_t *f)
{
    const fluid_params_t *prm = &f->prm;
    return prm->nu > 0 ? prm->fourier / (prm->nu * viscous_rate(f)) : INFINITY;
}

/* viscous = auto: can a step be implicit?  A fixed step above the explicit
 * limit, or an adaptive one whose dt_max (if any) allows more than the
 * ratio times it (the Helmholtz solvers are made only then). */
int fluid_auto_may_be_implicit(const fluid_t *f)
{
    const fluid_params_t *prm = &f->prm;
    if (!isfinite(f->dt_viscous)) return 0;
    if (prm->dt_fixed > 0) return prm->dt_fixed > f->dt_viscous;
    return !(prm->dt_max > 0) || prm->dt_max > prm->viscous_auto_ratio * f->dt_viscous;
}

int fluid_step_is_implicit(const fluid_t *f, double dt)
{
    const int mode = f->prm.implicit_viscous;
    /* a last step stretched by round-off to land on t_end (sim.c) stays explicit */
    return mode == FLUID_VISCOUS_IMPLICIT || (mode == FLUID_VISCOUS_AUTO && dt > f->dt_viscous * (1 + 1e-6));
}

double fluid_stable_dt(const fluid_t *f)
{
    const fluid_params_t *prm = &f->prm;
    const grid_t *g = f->g;
    if (prm->dt_fixed > 0) return prm->dt_fixed;
    /* Velocity scales that exist before the flow does, so that a fluid at
     * rest set in motion by a moving wall or a body force does not take a
     * huge first step: the wall speed, and √(|f| Δ) (a cell crossed after
     * accelerating from rest for Δt ≈ √(Δ/|f|)). */
    double dmin = fmin(g->dy, g->dim == 3 ? g->dz : g->dy);
    for (int i = 0; i < g->n[0]; i++) dmin = fmin(dmin, g->gdxf[i]);
    double uw = 0.0, fb = 0.0;
    for (int d = 0; d < 3; d++) {
        fb = fmax(fb, fabs(prm->body_force[d]));
        for (int s = 0; s < 2; s++)
            for (int c = 0; c < 3; c++) uw = fmax(uw, fabs(g->bc.vel[d][s][c]));
    }
    double rate = fmax(fluid_convective_rate(f), fmax(uw / dmin, sqrt(fb / dmin)));
    double dt = rate > 0 ? prm->cfl / rate : DBL_MAX;
    double dt_visc = prm->nu > 0 ? prm->fourier / (prm->nu * viscous_rate(f)) : DBL_MAX;
    if (prm->dt_max > 0) dt = fmin(dt, prm->dt_max);
    /* explicit: the viscous limit too; auto: unless the other limits allow
     * more than the ratio times it and the Helmholtz solvers exist (the step
     * is then implicit, fluid_step_is_implicit) */
    const int mode = prm->implicit_viscous;
    if (mode == FLUID_VISCOUS_EXPLICIT ||
        (mode == FLUID_VISCOUS_AUTO && !(dt > prm->viscous_auto_ratio * dt_visc && fluid_auto_may_be_implicit(f))))
        dt = fmin(dt, dt_visc);
    /* implicit, at rest, unforced and without dt_max: nothing limits the step;
     * take the explicit viscous one */
    if (dt == DBL_MAX) dt = dt_visc;
    if (dt == DBL_MAX) die("fluid_stable_dt: nothing limits the time step (inviscid fluid at rest): set dt or dt_max");
    return dt;
}
