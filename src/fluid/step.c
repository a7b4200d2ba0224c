/* step.c — one time step: low-storage third-order Runge–Kutta (Wray 1990;
 * Rai & Moin 1991) with a projection at every stage and an incremental
 * pressure correction (Kim & Moin 1985; Brown, Cortez & Minion 2001 for the
 * Crank–Nicolson pressure update).
 *
 * Stage k = 1, 2, 3 with α_k = γ_k + ζ_k:
 *   H^k   = −∇·(u⊗u)^{k−1}  [+ ν L u^{k−1} when explicit]
 *   u*    = u^{k−1} + Δt (γ_k H^k + ζ_k H^{k−1}) + α_k Δt (f − G p^{k−1})
 *           [+ α_k Δt ν/2 (L u^{k−1} + L u*) when Crank–Nicolson: the Helmholtz
 *            problem (L − λ) u* = −λ rhs − (wall terms), λ = 2/(α_k Δt ν)]
 *   stage hook (immersed boundary) on u*
 *   L φ   = D u* / (α_k Δt),   u^k = u* − α_k Δt G φ,
 *   p^k   = p^{k−1} + φ  [− α_k Δt ν/2 L φ when Crank–Nicolson].
 * Since L = D·G (poisson.c), D u^k = 0 to the solver's round-off.
 */
#include <math.h>

#include "fluid_internal.h"
#include "util.h"

static const double rk_gamma[3] = {8.0 / 15.0, 5.0 / 12.0, 3.0 / 4.0};
static const double rk_zeta[3] = {0.0, -17.0 / 60.0, -5.0 / 12.0};

/* Gradient of a cell-centred field at the unknowns of component c. */
static inline double grad_c(const grid_t *g, int c, const double *p, long m, int i)
{
    switch (c) {
    case 0: return (p[m + g->sx] - p[m]) / g->dxc[i];
    case 1: return (p[m + g->sy] - p[m]) / g->dy;
    default: return (p[m + 1] - p[m]) / g->dz;
    }
}

void fluid_project_stage(fluid_t *f, double dt_stage, int update_pressure)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    double *rhs = q->work, *phi = q->phi;
    fluid_divergence(f, rhs);
    double s = 1.0 / dt_stage;
    for (long m = 0; m < g->nalloc; m++) rhs[m] *= s;
    if (poisson_solve(q->pp, 0.0, rhs, phi) != 0)
        warn("step %ld: the pressure solve did not converge (residual %.3e)\n", f->step, q->pp->last_residual);
    f->diag.res_poisson = q->pp->last_residual;
    f->diag.it_poisson = q->pp->last_iterations;
    fluid_fill_pressure_ghosts(f, phi);
    for (int c = 0; c < fluid_ncomp(g); c++) {
        double *u = f->u[c];
        int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
        for (int i = 0; i < iend; i++)
            for (int j = 0; j < nj; j++) {
                long c0 = G_IDX(g, i, j, 0);
                for (int k = 0; k < nk; k++) u[c0 + k] -= dt_stage * grad_c(g, c, phi, c0 + k, i);
            }
    }
    if (update_pressure) {
        if (f->prm.implicit_viscous) {
            /* p += φ − (α Δt ν/2) L φ: the pressure consistent with the
             * Crank–Nicolson predictor (Brown, Cortez & Minion 2001) */
            poisson_apply(q->pp, 0.0, phi, rhs);
            double a = 0.5 * dt_stage * f->prm.nu;
            for (int i = 0; i < g->nxl; i++)
                for (int j = 0; j < g->n[1]; j++)
                    for (int k = 0; k < g->n[2]; k++) {
                        long m = G_IDX(g, i, j, k);
                        f->p[m] += phi[m] - a * rhs[m];
                    }
        } else {
            for (int i = 0; i < g->nxl; i++)
                for (int j = 0; j < g->n[1]; j++)
                    for (int k = 0; k < g->n[2]; k++) {
                        long m = G_IDX(g, i, j, k);
                        f->p[m] += phi[m];
                    }
        }
        fluid_fill_pressure_ghosts(f, f->p);
    }
    fluid_apply_bc(f);
}

void fluid_project(fluid_t *f)
{
    fluid_apply_bc(f);
    fluid_project_stage(f, 1.0, 0);
}

/* Predictor of one stage for component c (u^{k−1} → u*). */
static void predict_component(fluid_t *f, int c, int stage, double dt)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    double gam = rk_gamma[stage], zet = rk_zeta[stage], a = gam + zet, adt = a * dt;
    double *u = f->u[c], *h = q->dudt[c], *ho = q->dudt_old[c], *w = q->work;
    double fc = f->prm.body_force[c];
    int impl = f->prm.implicit_viscous;
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    if (impl) {
        /* w = (αΔtν/2) L u^{k−1}, the explicit half of Crank–Nicolson */
        field_zero(g, w);
        fluid_laplacian_add(f, c, u, 0.5 * adt * f->prm.nu, w);
    }
    for (int i = 0; i < iend; i++)
        for (int j = 0; j < nj; j++) {
            long c0 = G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) {
                long m = c0 + k;
                double du = dt * (gam * h[m] + zet * ho[m]) + adt * (fc - grad_c(g, c, f->p, m, i));
                u[m] += du + (impl ? w[m] : 0.0);
            }
        }
    if (impl) {
        /* (I − αΔtν/2 L) u* = rhs  ⇔  (L_hom − λ) u* = −λ rhs − wall terms */
        double lam = 2.0 / (adt * f->prm.nu);
        for (int i = 0; i < iend; i++)
            for (int j = 0; j < nj; j++)
                for (int k = 0; k < nk; k++) {
                    long m = G_IDX(g, i, j, k);
                    w[m] = -lam * u[m];
                }
        fluid_wall_terms_add(f, c, -1.0, w);
        if (poisson_solve(q->pv[c], lam, w, u) != 0)
            warn("step %ld: the Helmholtz solve of component %c did not converge\n", f->step, "uvw"[c]);
    }
}

void fluid_step(fluid_t *f, double dt)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    int nc = fluid_ncomp(g);
    for (int s = 0; s < 3; s++) {
        double adt = (rk_gamma[s] + rk_zeta[s]) * dt;
        /* H^k from u^{k−1} (its ghosts are valid: every stage ends with them) */
        for (int c = 0; c < nc; c++) field_zero(g, q->dudt[c]);
        fluid_advection_add(f, -1.0, q->dudt);
        if (!f->prm.implicit_viscous)
            for (int c = 0; c < nc; c++) fluid_laplacian_add(f, c, f->u[c], f->prm.nu, q->dudt[c]);
        for (int c = 0; c < nc; c++) predict_component(f, c, s, dt);
        for (int c = 0; c < nc; c++) {
            double *t = q->dudt[c];
            q->dudt[c] = q->dudt_old[c];
            q->dudt_old[c] = t;
        }
        fluid_apply_bc(f);
        if (f->stage_hook) {
            f->stage_hook(f, s, adt, f->hook_ctx);
            fluid_apply_bc(f);
        }
        fluid_project_stage(f, adt, 1);
    }
    f->time += dt;
    f->step++;
    f->diag.dt = dt;
    fluid_update_diagnostics(f);
}
