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
 *   hooks of a particle module (the immersed boundary): stage begin before
 *   the predictor; the plane hook on each plane of u* (inside the predictor
 *   sweep where it can be); the stage hook on u*
 *   [Crank–Nicolson with FLUID_HOOK_PREDICTOR: the plane hook on the
 *    right-hand side before the solve, forming the explicit predictor
 *    ũ = rhs + α_k Δt ν/2 L u^{k−1} (the whole viscous term explicit) at its
 *    nodes; the solve's right-hand side is then rhs + the forcing]
 *   L φ   = D u* / (α_k Δt),   u^k = u* − α_k Δt G φ,
 *   p^k   = p^{k−1} + φ  [− α_k Δt ν/2 L φ when Crank–Nicolson],
 *   stage-end hook (immersed boundary: particle update) on u^k.
 * Since L = D·G (poisson.c), D u^k = 0 to the solver's round-off.
 */
#include <math.h>

#include "fluid_internal.h"
#include "util.h"

const double fluid_rk_gamma[3] = {8.0 / 15.0, 5.0 / 12.0, 3.0 / 4.0};
const double fluid_rk_zeta[3] = {0.0, -17.0 / 60.0, -5.0 / 12.0};

/* Stride and inverse spacing of the gradient of a cell-centred field at the
 * unknowns of component c (x: per i). */
static inline long grad_stride(const grid_t *g, int c) { return c == 0 ? g->sx : c == 1 ? g->sy : 1; }
static inline double grad_rdx(const grid_t *g, int c, int i)
{
    return c == 0 ? 1.0 / g->dxc[i] : c == 1 ? 1.0 / g->dy : 1.0 / g->dz;
}

/* u^k = u* − α Δt G φ on the unknowns of every component of x plane i,
 * line by line with the components inside (as the right-hand side sweep of
 * advection.c), so that each line of φ is read from memory once for the
 * three components.  With `ei`, also accumulate Σ u² per component (ei) and
 * max |u| (*um) of the projected field for the diagnostics.  With `fuse_p`
 * the pressure update p += φ (explicit viscous terms) is done on the lines of
 * u, whose unknowns are the pressure cells except the plane beyond an x wall
 * (pressure_plane_add). */
static inline void correct_plane(fluid_t *f, const double *restrict ph, double dt_stage, int fuse_p, int i,
                                 double *ei, double *um)
{
    const grid_t *g = f->g;
    int nc = fluid_ncomp(g), is3d = g->dim == 3;
    double *restrict p = f->p;
    int nl = is3d ? g->n[1] : 1;
    for (int jl = 0; jl < nl; jl++)
        for (int c = 0; c < nc; c++) {
            if (i >= fluid_iend(g, c) || (is3d && jl >= fluid_nu(g, c, 1))) continue;
            double *restrict u = f->u[c];
            long c0 = G_IDX(g, i, jl, 0), len = is3d ? fluid_nu(g, c, 2) : fluid_nu(g, c, 1), s = grad_stride(g, c);
            double ac = dt_stage * grad_rdx(g, c, i);
            if (!ei)
                for (long m = c0; m < c0 + len; m++) u[m] -= ac * (ph[m + s] - ph[m]);
            else {
                double e = ei[c], x_max = *um;
                for (long m = c0; m < c0 + len; m++) {
                    double x = u[m] - ac * (ph[m + s] - ph[m]);
                    u[m] = x;
                    e += x * x;
                    x_max = dmax(x_max, fabs(x));
                }
                ei[c] = e;
                *um = x_max;
            }
            if (c == 0 && fuse_p)
                for (long m = c0; m < c0 + len; m++) p[m] += ph[m];
        }
}

/* p += φ on x plane i (the planes correct_plane leaves: beyond an x wall) */
static void pressure_plane_add(fluid_t *f, const double *restrict ph, int i)
{
    const grid_t *g = f->g;
    double *restrict p = f->p;
    FLUID_FOR_LINES(g, i, g->n[1], g->n[2], c0, len)
    for (long m = c0; m < c0 + len; m++) p[m] += ph[m];
}

/* The correction of every plane, with the diagnostics' sums (`stats`: Σ V u²
 * in stats[0], max |u| in stats[1]) and, plane by plane once u^k is final
 * there, its part of max |D u| and of the convective rate (div_cfl; the rest
 * once the ghosts are filled). */
static void correct_velocity(fluid_t *f, const double *restrict ph, double dt_stage, int fuse_p, double *stats,
                             double *div_cfl)
{
    const grid_t *g = f->g;
    int nc = fluid_ncomp(g);
    double e[3] = {0.0, 0.0, 0.0}, um = stats ? stats[1] : 0.0;
    for (int i = 0; i < g->nxl; i++) {
        double ei[3] = {0.0, 0.0, 0.0};
        correct_plane(f, ph, dt_stage, fuse_p, i, stats ? ei : NULL, &um);
        if (stats)
            for (int c = 0; c < nc; c++) e[c] += fluid_cell_volume(f, c, i) * ei[c];
        if (div_cfl) fluid_div_cfl_interior_plane(f, i, div_cfl);
    }
    if (stats) {
        stats[0] += e[0] + e[1] + e[2];
        stats[1] = um;
    }
}

/* The pressure correction φ of a stage into q->work, ghosts filled:
 * L φ = D(u*)/(αΔt), solved in place (div_ready: q->work already holds the
 * right-hand side).  With `by_planes` the solve stops before writing φ,
 * which the deferred correction then writes plane by plane
 * (poisson_solve_plane; ghosts filled there). */
static double *solve_correction(fluid_t *f, double dt_stage, int div_ready, int by_planes)
{
    fluid_priv_t *q = fluid_priv(f);
    double *phi = q->work;
    if (!div_ready) fluid_divergence_scaled(f, 1.0 / dt_stage, phi);
    if (by_planes)
        poisson_solve_begin(q->pp, 0.0, phi);
    else if (poisson_solve(q->pp, 0.0, phi, phi) != 0)
        warn("step %ld: the pressure solve did not converge (residual %.3e)\n", f->step, q->pp->last_residual);
    f->diag.res_poisson = q->pp->last_residual;
    f->diag.it_poisson = q->pp->last_iterations;
    if (!by_planes) fluid_fill_pressure_ghosts(f, phi);
    return phi;
}

/* The projection of a stage.  div_ready: q->work already holds D(u*)/(αΔt)
 * (the fused sweep of fluid_step).  div_cfl (3-D, or NULL): receives this
 * rank's max |D u^k| and convective rate, computed in the correction sweep
 * and completed after the ghost fill. */
static void project_stage(fluid_t *f, double dt_stage, int update_pressure, double *stats, int div_ready,
                          double *div_cfl)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    double *phi = solve_correction(f, dt_stage, div_ready, 0);
    /* u −= α Δt G φ [and p += φ with explicit viscous terms], one sweep */
    int fuse_p = update_pressure && !f->implicit_step;
    correct_velocity(f, phi, dt_stage, fuse_p, stats, div_cfl);
    if (update_pressure) {
        if (f->implicit_step) {
            /* p += φ − (α Δt ν/2) L φ: the pressure consistent with the
             * Crank–Nicolson predictor (Brown, Cortez & Minion 2001) */
            const poisson_t *pp = q->pp;
            double a = 0.5 * dt_stage * f->prm.nu, cy = a * pp->cy, cz = a * pp->cz;
            long sx = g->sx, sy = g->sy;
            double *restrict p = f->p;
            const double *restrict ph = phi;
            for (int i = 0; i < g->nxl; i++) {
                int ig = i + g->ix0;
                /* φ − a L φ with the stencil of poisson.c (φ's ghosts are filled) */
                double cw = a * pp->cw[ig], ce = a * pp->ce[ig], cd = 1.0 + a * pp->cd[ig] + 2.0 * (cy + cz);
                FLUID_FOR_LINES(g, i, g->n[1], g->n[2], c0, len)
                {
                    if (g->dim == 3)
                        for (long m = c0; m < c0 + len; m++)
                            p[m] += cd * ph[m] - cw * ph[m - sx] - ce * ph[m + sx] - cy * (ph[m + sy] + ph[m - sy]) -
                                    cz * (ph[m + 1] + ph[m - 1]);
                    else
                        for (long m = c0; m < c0 + len; m++)
                            p[m] += cd * ph[m] - cw * ph[m - sx] - ce * ph[m + sx] - cy * (ph[m + sy] + ph[m - sy]);
                }
            }
        } else {
            /* p += φ on the planes the sweep of u above did not cover */
            for (int i = fluid_iend(g, 0); i < g->nxl; i++) pressure_plane_add(f, phi, i);
        }
        fluid_fill_pressure_ghosts(f, f->p);
    }
    fluid_apply_bc(f);
    if (div_cfl) fluid_div_cfl_rest(f, div_cfl);
}

/* The correction of stage k deferred into the predictor sweep of stage k + 1
 * (theory §1, step 1.5): u^k = u* − αΔt G φ and p += φ are applied to x plane
 * i + 1 just before the sweep reaches plane i, so the corrected planes are
 * still in cache when the predictor reads them, instead of a sweep of their
 * own over u, p and φ.  The edge planes 0 and nxl − 1 go first, since the x
 * halo and the ghost planes (read by the sweep's first and last planes) come
 * from them; an inner plane's ghosts come from that plane only.  The same
 * operations on the same values as project_stage: bit-identical.  φ stays in
 * q->work, where the sweep writes D u* of plane i after planes i and i + 1 are
 * corrected: plane i of φ is no longer read by then (the correction of plane i'
 * reads φ at i' and i' + 1). */
typedef struct {
    fluid_t *f;
    double *phi;
    double dt_stage;
    int next;      /* first inner plane not yet corrected */
    int by_planes; /* φ itself written plane by plane (poisson_solve_plane), just ahead of its use */
    int phi_next;  /* first inner plane of φ not yet written */
} deferred_correction_t;

/* φ written on the inner planes up to n (by_planes), with their ghosts: the
 * correction of plane n reads φ on planes n and n + 1. */
static void deferred_phi(deferred_correction_t *d, int n)
{
    fluid_t *f = d->f;
    poisson_t *pp = fluid_priv(f)->pp;
    if (n > f->g->nxl - 2) n = f->g->nxl - 2;
    for (; d->phi_next <= n; d->phi_next++) {
        poisson_solve_plane(pp, d->phi, d->phi_next);
        poisson_fill_ghosts_plane(pp, d->phi, d->phi_next);
    }
}

static void deferred_plane(deferred_correction_t *d, int i)
{
    correct_plane(d->f, d->phi, d->dt_stage, 1, i, NULL, NULL);
    if (i >= fluid_iend(d->f->g, 0)) pressure_plane_add(d->f, d->phi, i);
}

static void deferred_start(deferred_correction_t *d)
{
    fluid_t *f = d->f;
    int nxl = f->g->nxl;
    if (d->by_planes) {
        /* φ on the edge planes (and their ghosts, the x halo), then on plane 1,
         * which the correction of plane 0 reads */
        poisson_t *pp = fluid_priv(f)->pp;
        poisson_solve_plane(pp, d->phi, 0);
        if (nxl > 1) poisson_solve_plane(pp, d->phi, nxl - 1);
        poisson_fill_ghosts_edges(pp, d->phi);
        d->phi_next = 1;
        deferred_phi(d, 1);
    }
    deferred_plane(d, 0);
    if (nxl > 1) deferred_plane(d, nxl - 1);
    poisson_fill_ghosts_edges(fluid_priv(f)->pp, f->p);
    fluid_apply_bc_edges(f);
    d->next = 1;
}

/* fluid_ahead_t: planes up to i + 1 final before the sweep reads them */
static void deferred_ahead(void *ctx, int i)
{
    deferred_correction_t *d = ctx;
    fluid_t *f = d->f;
    for (; d->next <= i + 1 && d->next <= f->g->nxl - 2; d->next++) {
        if (d->by_planes) deferred_phi(d, d->next + 1);
        deferred_plane(d, d->next);
        poisson_fill_ghosts_plane(fluid_priv(f)->pp, f->p, d->next);
        fluid_apply_bc_plane(f, d->next);
    }
}

void fluid_project_stage(fluid_t *f, double dt_stage, int update_pressure, double *stats)
{
    project_stage(f, dt_stage, update_pressure, stats, 0, NULL);
}

void fluid_stage_project(fluid_t *f, double dt_stage)
{
    fluid_apply_bc(f); /* the caller changed u* (forcing): its ghosts enter D u* */
    fluid_project_stage(f, dt_stage, 1, NULL);
}

void fluid_project(fluid_t *f)
{
    fluid_apply_bc(f);
    fluid_project_stage(f, 1.0, 0, NULL);
}

/* Crank–Nicolson: u[c] holds the explicit part rhs = u* of the predictor;
 * solve (I − αΔtν/2 L) u* = rhs  ⇔  (L_hom − λ) u* = −λ rhs − wall terms.
 * With the quadratic wall ghost, L = L_lin + C where the solvers carry L_lin
 * only (the transforms need ghost = ±interior); C u* goes to the right-hand
 * side, evaluated at u^{k−1} (u_prev) for a first solve, then at that
 * solution for a second one.  The steady state satisfies the quadratic
 * discretisation exactly either way; the second solve is for stability: with
 * C lagged once, a step amplifies the wall modes for νΔt/Δ² > 8.3 (1-D
 * eigenvalue analysis, docs/theory.md §4.3); with two solves (an even number)
 * every νΔt/Δ² is stable. */
static void helmholtz_component(fluid_t *f, int c, double adt, const double *u_prev)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    double *restrict u = f->u[c], *restrict w = q->work;
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    double lam = 2.0 / (adt * f->prm.nu);
    for (int i = 0; i < iend; i++)
        FLUID_FOR_LINES(g, i, nj, nk, c0, len)
        for (long m = c0; m < c0 + len; m++) w[m] = -lam * u[m];
    fluid_wall_terms_add(f, c, -1.0, w);
    fluid_wall_ghost_add(f, c, u_prev, -1.0, w);
    int fail = poisson_solve(q->pv[c], lam, w, u) != 0;
    if (q->wq_any) {
        /* the x-wall neighbour u_1 may be on the next rank */
        if (!g->periodic[0] && g->nxl < 2) grid_halo_x(g, u);
        fluid_wall_ghost_add(f, c, u_prev, 1.0, w);
        fluid_wall_ghost_add(f, c, u, -1.0, w);
        fail |= poisson_solve(q->pv[c], lam, w, u) != 0;
    }
    if (fail) warn("step %ld: the Helmholtz solve of component %c did not converge\n", f->step, "uvw"[c]);
}

/* The plane hook inside the predictor sweep (fluid_ahead_t of the sweep's
 * `done`): the stage's u* arrays are passed, they become f->u only after
 * the sweep. */
typedef struct {
    fluid_t *f;
    double *const *us;
    int stage;
    double adt;
} plane_hook_call_t;

static void plane_hook_at(void *ctx, int i)
{
    plane_hook_call_t *c = ctx;
    c->f->plane_hook(c->f, c->us, c->stage, c->adt, i, c->f->hook_ctx);
}

/* The forward transforms of the pressure solve inside the predictor sweep
 * (theory §1, step 1.1c; fluid_ahead_t of the sweep's `after_div`): once
 * the sweep has written the interior cells of D u* on plane i, the ghosts
 * of plane i of u* are filled (the values fluid_apply_bc gives them after
 * the sweep), the plane's cells next to the y and z faces follow, and the
 * plane's forward transform is taken while it is in cache; the solve then
 * transforms only the planes of the edges, which read the x ghosts.  The
 * same operations on the same values: bit-identical. */
typedef struct {
    fluid_t *f;
    double *const *us;
    double scale;
    int ilo, ihi;
} forward_plane_call_t;

static void forward_plane_at(void *ctx, int i)
{
    forward_plane_call_t *c = ctx;
    if (i < c->ilo || i >= c->ihi) return;
    fluid_priv_t *q = fluid_priv(c->f);
    fluid_apply_bc_plane_of(c->f, c->us, i);
    fluid_divergence_rest_plane(c->f, (const double *const *)c->us, c->scale, q->work, i);
    poisson_forward_plane(q->pp, q->work, i);
}

void fluid_step(fluid_t *f, double dt)
{
    const grid_t *g = f->g;
    fluid_priv_t *q = fluid_priv(f);
    int nc = fluid_ncomp(g);
    double stats[2] = {0.0, 0.0}, div_cfl[2] = {0.0, 0.0};
    f->implicit_step = fluid_step_is_implicit(f, dt);
    int is3d = g->dim == 3, impl = f->implicit_step;
    /* Decided after the stage-begin hook of stage 0 (its promises,
     * f->hook_flags, hold for the step):
     * - plane hook inside the predictor sweep (theory §1, step 1.1b) when
     *   nothing changes u* after the sweep: 3-D, explicit, no quadratic wall
     *   ghost (whose terms the sweep adds afterwards);
     * - fused divergence (step 1.1): D u* computed in the predictor sweep
     *   unless something changes u* between the sweep and the projection (a
     *   stage hook that changes u*, a plane hook outside the sweep, the
     *   Crank–Nicolson solves), 3-D only;
     * - deferred correction (step 1.5): the correction of stages 1 and 2
     *   done inside the next predictor sweep, when nothing reads u^k in
     *   between (no stage-end hook, or one that promised not to) and the
     *   sweep is the fused one. */
    int fuse_plane = 0, fuse_div = 0, defer = 0, fwd_planes = 0, pred = 0;
    deferred_correction_t dc = {.f = f};
    fluid_ahead_t ahead = {deferred_ahead, &dc};
    plane_hook_call_t phc = {.f = f};
    fluid_ahead_t done = {plane_hook_at, &phc};
    forward_plane_call_t fpc = {.f = f};
    fluid_ahead_t after_div = {forward_plane_at, &fpc};
    fluid_interior_planes(g, &fpc.ilo, &fpc.ihi);
    int pending = 0;
    for (int s = 0; s < 3; s++) {
        double adt = (fluid_rk_gamma[s] + fluid_rk_zeta[s]) * dt;
        if (f->stage_begin_hook) f->stage_begin_hook(f, s, adt, f->hook_ctx);
        if (s == 0) {
            int keeps = !f->stage_hook || (f->hook_flags & FLUID_HOOK_KEEPS_USTAR);
            /* Crank–Nicolson with the forcing on the explicit predictor */
            pred = impl && f->plane_hook && (f->hook_flags & FLUID_HOOK_PREDICTOR);
            fuse_plane = f->plane_hook && is3d && (!impl || pred) && !q->wq_any;
            fuse_div = is3d && !impl && keeps && (!f->plane_hook || fuse_plane);
            defer = fuse_div && (!f->stage_end_hook || (f->hook_flags & FLUID_HOOK_IDLE_UK));
            /* forward transforms in the sweep (step 1.1c) when D u* is
             * final there: no wall terms after the sweep, a solver by planes */
            fwd_planes = fuse_div && !q->wq_any && poisson_solve_by_planes(q->pp);
            if (f->prm.unfused) fuse_plane = fuse_div = defer = fwd_planes = 0;
        }
        /* H^k = −∇·(u⊗u) [+ νLu] from u^{k−1} (its ghosts are valid: every
         * stage ends with them) into spare, and the predictor
         * u* = u^{k−1} + Δt(γH^k + ζH^{k−1}) + αΔt(f − G p) [+ αΔtν/2 L u^{k−1}]
         * over h (which held H^{k−1}), in one sweep; then rotate:
         * u ← u*, h ← H^k, spare ← u^{k−1} (free).  The last stage's H is
         * not needed (ζ_1 = 0: the first stage of the next step does not
         * read H_old), so it is not stored. */
        if (pending) deferred_start(&dc);
        phc.us = q->h;
        phc.stage = s;
        phc.adt = adt;
        fpc.us = q->h;
        fpc.scale = 1.0 / adt;
        /* the forcing on the explicit predictor: u^{k−1} is f->u during the sweep */
        f->pred_a = pred ? 0.5 * adt * f->prm.nu : 0.0;
        for (int c = 0; c < nc; c++) f->pred_u[c] = pred ? f->u[c] : NULL;
        fluid_rhs_predict_div(f, -1.0, impl ? 0.0 : f->prm.nu, dt * fluid_rk_gamma[s], dt * fluid_rk_zeta[s], adt,
                              impl ? 0.5 * adt * f->prm.nu : 0.0, s < 2 ? q->spare : NULL, q->h, 1.0 / adt,
                              fuse_div ? q->work : NULL, pending ? &ahead : NULL, fuse_plane ? &done : NULL,
                              fwd_planes ? &after_div : NULL);
        pending = 0;
        for (int c = 0; c < nc; c++) {
            double *old = f->u[c];
            f->u[c] = q->h[c];
            q->h[c] = q->spare[c];
            q->spare[c] = old;
        }
        if (pred && !fuse_plane) {
            /* the forcing of the right-hand side before the solve (u^{k−1}, now
             * in spare, has valid ghosts) */
            for (int c = 0; c < nc; c++) f->pred_u[c] = q->spare[c];
            for (int i = 0; i < g->nxl; i++) f->plane_hook(f, f->u, s, adt, i, f->hook_ctx);
        }
        f->pred_a = 0.0;
        if (impl)
            for (int c = 0; c < nc; c++) helmholtz_component(f, c, adt, q->spare[c] /* u^{k−1} */);
        if (f->plane_hook && !fuse_plane && !pred)
            for (int i = 0; i < g->nxl; i++) f->plane_hook(f, f->u, s, adt, i, f->hook_ctx);
        fluid_apply_bc(f);
        if (fuse_div) fluid_divergence_rest(f, 1.0 / adt, q->work, fwd_planes);
        if (f->stage_hook) {
            f->stage_hook(f, s, adt, f->hook_ctx);
            if (!(f->hook_flags & FLUID_HOOK_KEEPS_USTAR)) fluid_apply_bc(f);
        }
        if (defer && s < 2) {
            /* where the solver allows it, φ itself is written plane by plane inside the next sweep */
            dc.by_planes = poisson_solve_by_planes(q->pp);
            dc.phi = solve_correction(f, adt, 1, dc.by_planes);
            dc.dt_stage = adt;
            pending = 1;
        } else
            project_stage(f, adt, 1, s == 2 ? stats : NULL, fuse_div, s == 2 && is3d ? div_cfl : NULL);
        if (f->stage_end_hook) f->stage_end_hook(f, s, adt, f->hook_ctx);
    }
    f->time += dt;
    f->step++;
    f->implicit_steps += impl;
    f->diag.dt = dt;
    if (f->prm.hold_flow) {
        /* the energy, max |u| and convective rate of the projection are those before the correction */
        fluid_hold_flow_rate(f, dt);
        fluid_update_diagnostics(f, NULL, NULL);
    } else
        fluid_update_diagnostics(f, stats, is3d ? div_cfl : NULL);
}
