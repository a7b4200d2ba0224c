/* forcing.c — the direct forcing of every RK3 stage, the hydrodynamic force
 * and torque of each sphere, and the rigid-body update of the spheres.
 *
 * Stage k (Δt_k = (γ_k + ζ_k) Δt), fluid hooks of fluid.h:
 *
 *  before the predictor sweep (ibm_stage_begin): at the first stage the
 *  moves made between steps (carry_external_moves, on u^n), then the
 *  targets U;
 *  on each plane of the predicted velocity u* (ibm_force_plane, the fluid's
 *  plane hook: inside its sweep, while the plane is in cache, where it can):
 *     u* ← u* + α (U − u*)         at every node with α > 0,
 *  U the rigid-body velocity u_p + ω_p × r of the sphere at the start of the
 *  stage (a prescribed sphere: at its end, set_targets), i.e.
 *  f = α (U − u*)/Δt_k (β instead of α with forcing_time).  With
 *  the Crank–Nicolson viscous term and cn_forcing = predictor the plane hook
 *  gets the right-hand side of the Helmholtz solve before the solve, and u*
 *  above is the explicit predictor ũ = rhs + a L u^{k−1} (fluid.h,
 *  FLUID_HOOK_PREDICTOR): the forcing becomes a source term of the implicit
 *  solve (docs/theory.md §4.6).  Overlapping spheres: α = min(1, Σ α_p)
 *  and U the α-weighted mean of their velocities; sphere p takes the share
 *  α_p/Σα_p of the node's impulse.  With forcing_iterations = N the pair
 *  (project, force) follows N times (ibm_stage_force, after the sweep).
 *
 *  after the projection (ibm_stage_end), on u^k: each sphere's solid
 *  fraction is moved to the explicit prediction X^k = x^{k−1} + Δt_k u^{k−1}
 *  (prescribed: the prescribed motion), and
 *     I^k = ∫ α(X^k) u^k dV,   L^k = ∫ α(X^k) (x − X^k) × u^k dV,
 *     J = ρ (I^k − I^{k−1}) − ρ ∫ f dV Δt_k,
 *     K = ρ (L^k − L^{k−1} + Δt_k u × I) − ρ ∫ r × f dV Δt_k
 *  are the hydrodynamic impulses (force and torque × Δt_k) of the pressure
 *  relative to hydrostatic and the viscous stress: the momentum balance of
 *  the fluid inside the moving sphere volume (Uhlmann 2005; Kempe & Fröhlich
 *  2012; Breugem 2012) — the flux of momentum through the surface cancels
 *  because the fluid there moves with it; u × I comes from the moving
 *  reference point of L.  Taking I and L with the α of the moving sphere
 *  matters: at a steady translation through the grid the α-weighted
 *  momentum is then constant and the drag is exactly −ρ ∫ f dV; with a
 *  fixed α the band's fluid, which lags the sphere, would bias it.  A free
 *  sphere then moves by
 *     (m_p + C_v ρ V_p) Δu = J + (ρ_p − ρ) V_p g Δt_k + C_v ρ V_p Δu_prev,
 *     (I_p + C_v (ρ/ρ_p) I_p) Δω = K + C_v (ρ/ρ_p) I_p Δω_prev,
 *     x^k = x^{k−1} + Δt_k (u^{k−1} + Δu/2)     (X^k − x^k = O(Δt_k² du/dt)),
 *  where the C_v terms stabilise light spheres (virtual mass, Schwarz,
 *  Kempe & Fröhlich 2015) without changing any steady state.  Why: the
 *  explicit coupling measures the fluid's reaction to the velocity jumps
 *  of the previous stages — the projection keeps about 2/3 of a jump
 *  imposed inside a sphere and returns 1/3 as a pressure impulse, measured
 *  at the next stage, and so on (a geometric series of ratio 1/3 whose sum
 *  is the added mass ½ρV).  With that response the stage-to-stage
 *  amplification z of the plain coupling is (1 − ρ/ρ_p)/3: unstable below
 *  ρ_p/ρ = 1/4 (measured: 0.3 runs, 0.2 diverges).  With C_v = c and
 *  r = ρ_p/ρ, 3(r + c)z² + (1 − r − 4c)z + c = 0: c = 0.1 keeps |z| ≤ 0.33
 *  for r ≥ 0.2 and |z| < 1 down to r ≈ 0.05 (docs/theory.md §6b).
 *  The seed's rigid-body model (force_model = rigid, eq. 2.32) instead
 *  assumes the fluid inside moves rigidly:
 *     Δu = g Δt_k − ρ ∫ f dV Δt_k / ((ρ_p − ρ) V_p).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ibm_internal.h"
#include "util.h"

/* r × (a e_c) for a vector a e_c along axis c */
static inline void cross_axis(const double r[3], int c, double a, double out[3])
{
    switch (c) {
    case 0: out[0] = 0.0, out[1] = r[2] * a, out[2] = -r[1] * a; break;
    case 1: out[0] = -r[2] * a, out[1] = 0.0, out[2] = r[0] * a; break;
    default: out[0] = r[1] * a, out[1] = -r[0] * a, out[2] = 0.0; break;
    }
}

/* β of a node of solid fraction a (see ibm.h): the seed's β = α, or the
 * implicit relaxation over the stage with the time scale τ = κ h²/ν. */
static inline double forcing_beta(double a, double dt, double tau)
{
    if (tau <= 0.0 || a >= 1.0) return a;
    return a * dt / ((1.0 - a) * tau + a * dt);
}

/* The forcing works on the merged node lists of alpha.c: each forced node
 * once, with α = min(1, Σ_p α_p) and the target velocity the α-weighted
 * mean Ū = Σ_p (α_p/Σα) U_p(r_p) of the rigid-body velocities of the
 * spheres whose band reaches it; each sphere then takes the share α_p/Σα
 * of the node's impulse.  (A node of one sphere: Ū = U_p and its whole
 * impulse, exactly.)  Three passes: targets (set_targets), forcing of the
 * nodes (force_nodes, streaming over the node runs, as often as there are
 * forcings), and each sphere's share of the accumulated impulses
 * (sphere_sums). */

void ibm_targets_note(ibm_t *ibm)
{
    ibm_priv_t *q = ibm_priv(ibm);
    for (int p = 0; p < ibm->n; p++) {
        memcpy(q->target_vel + 6 * p, ibm->s[p].u, 3 * sizeof(double));
        memcpy(q->target_vel + 6 * p + 3, ibm->s[p].omega, 3 * sizeof(double));
    }
}

void ibm_targets_of(ibm_t *ibm, long r0, long r1, long n0, long n1)
{
    ibm_priv_t *q = ibm_priv(ibm);
    double step = q->rstep;
    int rd = q->rdir;
    if (n1 <= n0) return; /* (no nodes on this rank: node_target may be NULL) */
    memset(q->node_target + n0, 0, (size_t)(n1 - n0) * sizeof(double));
    for (long ir = r0; ir < r1; ir++) {
        const ibm_run_t *run = &q->runs[ir];
        const double *v = q->target_vel + 6 * run->p;
        const double *al = q->alpha + run->a0, *A = q->node_asum + run->u0;
        double *T = q->node_target + run->u0, r[3] = {run->r0[0], run->r0[1], run->r0[2]};
        for (int k = 0; k < run->len; k++, r[rd] += step)
            if (al[k] > 0.0) T[k] += al[k] / A[k] * ibm_rigid_velocity(v, run->c, r);
    }
}

static void mask_geometry(const grid_t *g, double v[3], double w[3]);

/* Ū at every forced node for the stage that ends at t_end, and the
 * accumulated impulses reset.  The target of a sphere is its velocity at
 * the start of the stage — the end's is not known before the stage of a
 * free sphere (explicit coupling) — except for a prescribed sphere, whose
 * motion is known: it takes its velocity at the stage's end, the velocity
 * the fluid it encloses must have then.  (Forcing towards the start's
 * velocity lags the motion by a stage: a first-order error of the force in
 * Δt, +0.74 % of the in-phase force of a sphere oscillating with 200 steps
 * a period, tests/test_ibm_oscillating.c.)  Ū is kept when neither the node
 * lists nor any target changed since it was set (spheres at rest, a fixed
 * bed, or set by the build of the node lists: the pass is skipped). */
static void set_targets(ibm_t *ibm, double t_end)
{
    ibm_priv_t *q = ibm_priv(ibm);
    q->stage_first = 1; /* this stage's forcing starts the accumulation */
    int same = q->targets_valid;
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        double v[6];
        if (s->kind == IBM_PRESCRIBED) {
            ibm_prescribed_velocity(ibm, s, t_end, v, v + 3);
            mask_geometry(ibm->g, v, v + 3);
        } else {
            memcpy(v, s->u, 3 * sizeof(double));
            memcpy(v + 3, s->omega, 3 * sizeof(double));
        }
        if (memcmp(q->target_vel + 6 * p, v, sizeof v)) {
            same = 0;
            memcpy(q->target_vel + 6 * p, v, sizeof v);
        }
    }
    if (same) return;
    q->targets_valid = 1;
    ibm_targets_of(ibm, 0, q->nruns, 0, q->nnodes);
}

/* One forcing u ← u + β (Ū − u) of the forced nodes of the node runs
 * r0 .. r1−1 (u[c]: the velocity arrays to force), the impulse added to
 * node_imp (stored, not added, when `first`: the first forcing after
 * set_targets). */
static void force_node_runs(ibm_t *ibm, double *const u_of[3], long r0, long r1, double dt, int first)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    double kappa = ibm->prm.forcing_time, nu = ibm->f->prm.nu;
    long st = q->rstride;
    /* the forcing on the explicit predictor (Crank–Nicolson, FLUID_HOOK_PREDICTOR): ũ = u + a L u^{k−1} */
    const fluid_t *f = ibm->f;
    const double pa = f->pred_a;
    int fast = kappa <= 0 && st == 1 && pa == 0.0;
    if (r1 <= r0) return;
    if (first && !fast) {
        long n0 = q->nruns_f[r0].n0, n1 = q->nruns_f[r1 - 1].n0 + q->nruns_f[r1 - 1].len;
        memset(q->node_imp + n0, 0, (size_t)(n1 - n0) * sizeof(double));
    }
    for (long ir = r0; ir < r1; ir++) {
        const ibm_node_run_t *nr = &q->nruns_f[ir];
        double *u = u_of[nr->c] + nr->m0, *J = q->node_imp + nr->n0;
        const double *A = q->node_asum + nr->n0, *T = q->node_target + nr->n0;
        int len = nr->len;
        if (fast) { /* the seed's β = α, unit stride: vectorised; the
                     * first forcing writes J without reading it */
            if (first)
                for (int k = 0; k < len; k++) {
                    double imp = (A[k] < 1.0 ? A[k] : 1.0) * (T[k] - u[k]);
                    u[k] += imp;
                    J[k] = imp;
                }
            else
                for (int k = 0; k < len; k++) {
                    double imp = (A[k] < 1.0 ? A[k] : 1.0) * (T[k] - u[k]);
                    u[k] += imp;
                    J[k] += imp;
                }
        } else if (pa != 0.0) {
            const int i = ibm_node_i(g, nr->m0), c = nr->c;
            const double *up = f->pred_u[c];
            double h = q->hcell[c][i], tau = kappa > 0 ? kappa * h * h / nu : 0.0;
            for (int k = 0; k < len; k++) {
                const double ut = u[k * st] + pa * fluid_laplacian_at(f, c, up, i, nr->m0 + k * st);
                double imp = forcing_beta(A[k] < 1.0 ? A[k] : 1.0, dt, tau) * (T[k] - ut);
                u[k * st] += imp;
                J[k] += imp;
            }
        } else if (kappa > 0) {
            double h = q->hcell[nr->c][ibm_node_i(g, nr->m0)], tau = kappa * h * h / nu;
            for (int k = 0; k < len; k++) {
                double imp = forcing_beta(A[k] < 1.0 ? A[k] : 1.0, dt, tau) * (T[k] - u[k * st]);
                u[k * st] += imp;
                J[k] += imp;
            }
        } else {
            for (int k = 0; k < len; k++) {
                double imp = (A[k] < 1.0 ? A[k] : 1.0) * (T[k] - u[k * st]);
                u[k * st] += imp;
                J[k] += imp;
            }
        }
    }
}

/* Every forced node once (the forcing iterations). */
static void force_nodes(ibm_t *ibm, double dt)
{
    force_node_runs(ibm, ibm->f->u, 0, ibm_priv(ibm)->n_nruns, dt, 0);
}

/* Per-sphere sums over the runs (in storage order, each sphere's sums
 * carried from run to run), overwritten in sum_all:
 *  impulses: each sphere's share α_p/Σα of the accumulated forcing
 *            impulses, ∫ f dV Δt and its moment, into IBM_FIMP..IBM_TIMP+2;
 *  momentum: ∫ α_p u dV and ∫ α_p r × u dV into IBM_MOM..IBM_ANG+2.
 * Along a run only the run coordinate z of r = r⊥ + z e_run varies, so the
 * moment of the values a_k e_c of a run is r⊥ × e_c Σa_k + e_run × e_c
 * Σ z_k a_k: two sums per run instead of a cross product per node. */
void ibm_sums_zero(ibm_t *ibm, double *sum_all, int impulses, int momentum)
{
    for (int p = 0; p < ibm->n; p++)
        for (int d = 0; d < 6; d++) {
            if (impulses) sum_all[(long)p * IBM_NSUM + IBM_FIMP + d] = 0.0;
            if (momentum) sum_all[(long)p * IBM_NSUM + IBM_MOM + d] = 0.0;
        }
}

void ibm_sums_of(ibm_t *ibm, double *sum_all, long r0, long r1, int impulses, int momentum)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    long st = q->rstride;
    double step = q->rstep, e_run[3] = {0, 0, 0};
    int rd = q->rdir;
    e_run[rd] = 1.0;
    for (long ir = r0; ir < r1; ir++) {
        const ibm_run_t *run = &q->runs[ir];
        int c = run->c;
        double *sum = sum_all + (long)run->p * IBM_NSUM, t0[3], t1[3];
        const double *al = q->alpha + run->a0, *A = q->node_asum + run->u0, *imp = q->node_imp + run->u0;
        const double *u = ibm->f->u[c] + run->m0;
        double vol = q->vol[c][ibm_node_i(g, run->m0)], z0 = run->r0[rd], rperp[3] = {run->r0[0], run->r0[1], run->r0[2]};
        double j0 = 0, j1 = 0, m0 = 0, m1 = 0;
        rperp[rd] = 0.0;
        if (impulses && momentum) /* one loop: four independent sums, one load of α */
            for (int k = 0; k < run->len; k++) {
                double share = al[k] > 0.0 ? al[k] / A[k] * imp[k] : 0.0, a = al[k] * u[k * st], z = z0 + k * step;
                j0 += share;
                j1 += z * share;
                m0 += a;
                m1 += z * a;
            }
        else if (impulses)
            for (int k = 0; k < run->len; k++) {
                double share = al[k] > 0.0 ? al[k] / A[k] * imp[k] : 0.0;
                j0 += share;
                j1 += (z0 + k * step) * share;
            }
        else if (momentum)
            for (int k = 0; k < run->len; k++) {
                double a = al[k] * u[k * st];
                m0 += a;
                m1 += (z0 + k * step) * a;
            }
        if (impulses) {
            cross_axis(rperp, c, j0 * vol, t0);
            cross_axis(e_run, c, j1 * vol, t1);
            sum[IBM_FIMP + c] += j0 * vol;
            for (int d = 0; d < 3; d++) sum[IBM_TIMP + d] += t0[d] + t1[d];
        }
        if (momentum) {
            cross_axis(rperp, c, m0 * vol, t0);
            cross_axis(e_run, c, m1 * vol, t1);
            sum[IBM_MOM + c] += m0 * vol;
            for (int d = 0; d < 3; d++) sum[IBM_ANG + d] += t0[d] + t1[d];
        }
    }
}

static void sphere_sums(ibm_t *ibm, double *sum_all, int impulses, int momentum)
{
    ibm_sums_zero(ibm, sum_all, impulses, momentum);
    ibm_sums_of(ibm, sum_all, 0, ibm_priv(ibm)->nruns, impulses, momentum);
}

void ibm_momentum(ibm_t *ibm, double *sum_all) { sphere_sums(ibm, sum_all, 0, 1); }

static void reduce_sums(ibm_t *ibm)
{
    ibm_priv_t *q = ibm_priv(ibm);
    if (ibm->g->nranks > 1)
        MPI_Allreduce(MPI_IN_PLACE, q->sum, ibm->n * IBM_NSUM, MPI_DOUBLE, MPI_SUM, ibm->g->comm);
}

/* Node lists at the current xa, then I and L into mom_prev. */
void ibm_rebuild_geometry(ibm_t *ibm)
{
    double w0 = wtime();
    ibm_priv_t *q = ibm_priv(ibm);
    memset(q->sum, 0, (size_t)ibm->n * IBM_NSUM * sizeof(double));
    ibm_build_nodes(ibm, q->sum, 0);
    double w1 = wtime();
    reduce_sums(ibm);
    for (int p = 0; p < ibm->n; p++)
        for (int d = 0; d < 6; d++) q->mom_prev[6 * p + d] = q->sum[(long)p * IBM_NSUM + IBM_MOM + d];
    ibm->wall_alpha += w1 - w0;
    ibm->wall_integrals += wtime() - w1;
}

/* The shortest displacement from a to b (periodic directions: the nearest
 * image). */
static void displacement(const grid_t *g, const double a[3], const double b[3], double dx[3])
{
    for (int d = 0; d < 3; d++) {
        dx[d] = b[d] - a[d];
        if (d < g->dim && g->periodic[d]) dx[d] -= g->L[d] * round(dx[d] / g->L[d]);
    }
}

/* Fixed and external spheres do not move within a fluid step: an external
 * one is moved between steps only (by the coupling), and its α stays
 * where it was put over the three stages. */
static inline int still_within_step(const ibm_sphere_t *s) { return s->kind == IBM_FIXED || s->kind == IBM_EXTERNAL; }

/* Is the solid fraction of sphere s held where the step started over its
 * three stages?  Fixed and external spheres, and free ones with
 * free_alpha = step: those move (x, u, ω change at every stage) but their α
 * is moved between steps, like an external sphere's, with the whole jump
 * counted (xpred = x: λ = 1 in carry_external_moves). */
static inline int alpha_held(const ibm_t *ibm, const ibm_sphere_t *s)
{
    return still_within_step(s) || (s->kind == IBM_FREE && ibm->prm.free_alpha_per_step);
}

/* Do all spheres keep their position and velocity over the fluid step
 * (fixed spheres, and external ones, which the coupling moves between
 * steps)?  Then the solid fraction and the targets Ū stay as they are over
 * the three stages, the forcing impulses accumulate at the nodes, and the
 * hydrodynamic impulse of the step is taken once, at its end: the
 * momentum difference telescopes, Σ_k (I^k − I^{k−1}) = I^3 − I^0
 * (docs/theory.md §6b). */
static int step_frozen(const ibm_t *ibm)
{
    for (int p = 0; p < ibm->n; p++)
        if (!still_within_step(&ibm->s[p])) return 0;
    return 1;
}

/* Fixed and external spheres set to new centres x from outside (the
 * coupling, between steps): α at the new centres, and the momentum I^0, L^0
 * from which the next step's impulse is counted.  Over a move δ = x − xa,
 * the fluid momentum inside the sphere changes from I_old (old α, carried
 * from the end of the last step) to I_new (new α).  The part of the move
 * that the last step's velocity predicts, δ_p = xpred − xa, is the motion
 * of the sphere during that step, which a sphere moved within the step
 * (prescribed) counts in its force; the rest (e.g. a collision resolved by
 * the DEM within the step) is not counted, as when α is rebuilt at the new
 * centre.  Along the move, I^0 = I_old + (1 − λ)(I_new − I_old) with
 * λ = δ_p·δ/|δ|² clamped to [0, 1] (λ = 1: the whole change is counted, the impulses
 * telescope over the steps; λ = 0: I^0 = I_new), L likewise about the new
 * centre (L_old − δ × I_old).  Returns whether any sphere moved (then the
 * node lists are rebuilt here). */
static int carry_external_moves(ibm_t *ibm)
{
    ibm_priv_t *q = ibm_priv(ibm);
    int moved = 0;
    double *lam = xcalloc((size_t)ibm->n, sizeof(double)), *old = xcalloc(6 * (size_t)ibm->n, sizeof(double));
    char *mv = xcalloc((size_t)ibm->n, 1);
    for (int p = 0; p < ibm->n; p++) {
        ibm_sphere_t *s = &ibm->s[p];
        if (!alpha_held(ibm, s) || !memcmp(s->xa, s->x, sizeof s->x)) continue;
        double dx[3], dp[3], *I = q->mom_prev + 6 * p, *L = I + 3, dd = 0, dpd = 0;
        displacement(ibm->g, s->xa, s->x, dx);
        displacement(ibm->g, s->xa, s->xpred, dp);
        for (int d = 0; d < 3; d++) dd += dx[d] * dx[d], dpd += dp[d] * dx[d];
        /* clamped to [0, 1]: a move shorter than the predicted one (a sphere stopped by a
         * collision: δ ≪ δ_p) would otherwise extrapolate I^0 beyond I_old and I_new */
        lam[p] = dd > 0 ? dpd / dd : 0.0;
        lam[p] = lam[p] < 0 ? 0.0 : lam[p] > 1 ? 1.0 : lam[p];
        L[0] -= dx[1] * I[2] - dx[2] * I[1];
        L[1] -= dx[2] * I[0] - dx[0] * I[2];
        L[2] -= dx[0] * I[1] - dx[1] * I[0];
        memcpy(old + 6 * p, I, 6 * sizeof(double));
        memcpy(s->xa, s->x, sizeof s->x);
        moved = mv[p] = 1;
    }
    if (moved) {
        ibm_build_nodes(ibm, q->sum, 1); /* the targets too: the step starts with them */
        reduce_sums(ibm);
        for (int p = 0; p < ibm->n; p++)
            if (mv[p])
                for (int d = 0; d < 6; d++) {
                    double now = q->sum[(long)p * IBM_NSUM + IBM_MOM + d];
                    q->mom_prev[6 * p + d] = old[6 * p + d] + (1.0 - lam[p]) * (now - old[6 * p + d]);
                }
    }
    free(lam);
    free(old);
    free(mv);
    return moved;
}

/* Spheres moved from outside (coupling).  When every sphere is fixed or
 * external, the move is applied at the start of the next fluid step
 * (carry_external_moves from ibm_stage_force): between steps the solid
 * fraction stays the one the last step used, so a checkpoint or a rollback
 * taken there holds the centres (xa) of the carried momentum and a restart
 * rebuilds it exactly.  Otherwise at once: free and prescribed spheres take
 * the momentum at their new solid fraction. */
void ibm_update_geometry(ibm_t *ibm)
{
    ibm_priv_t *q = ibm_priv(ibm);
    if (!q->built) {
        for (int p = 0; p < ibm->n; p++) memcpy(ibm->s[p].xa, ibm->s[p].x, sizeof ibm->s[p].x);
        ibm_rebuild_geometry(ibm);
        return;
    }
    if (step_frozen(ibm)) return;
    carry_external_moves(ibm);
    double *keep = xcalloc(6 * (size_t)ibm->n, sizeof(double));
    memcpy(keep, q->mom_prev, 6 * (size_t)ibm->n * sizeof(double));
    for (int p = 0; p < ibm->n; p++) memcpy(ibm->s[p].xa, ibm->s[p].x, sizeof ibm->s[p].x);
    ibm_rebuild_geometry(ibm);
    for (int p = 0; p < ibm->n; p++)
        if (alpha_held(ibm, &ibm->s[p]))
            memcpy(q->mom_prev + 6 * p, keep + 6 * p, 6 * sizeof(double));
    free(keep);
}

/* Before the predictor sweep of a stage: the moves made since the last step
 * (stage 0), the targets Ū, and the promises to the fluid (fluid.h): the
 * stage hook below only reads u* unless there are forcing iterations, and
 * in a step where nothing moves (frozen) the stage-end hook of stages 0 and
 * 1 reads nothing, so the fluid may fuse the forcing, the divergence and
 * the correction into its sweeps (docs/theory.md §1). */
void ibm_stage_begin(fluid_t *f, int stage, double dt_stage, void *ctx)
{
    ibm_t *ibm = ctx;
    ibm_priv_t *q = ibm_priv(ibm);
    double w0 = wtime();
    if (stage == 0) {
        q->t_step = 0.0;
        q->t_stage0 = f->time;
        memset(q->imp_step, 0, (size_t)ibm->n * 6 * sizeof(double));
        q->frozen = step_frozen(ibm);
        /* the moves made since the last step (ibm_update_geometry) */
        if (q->frozen || ibm->prm.free_alpha_per_step) carry_external_moves(ibm);
        f->hook_flags = (ibm->prm.forcing_iterations == 0 ? FLUID_HOOK_KEEPS_USTAR : 0) |
                        (q->frozen ? FLUID_HOOK_IDLE_UK : 0) | (ibm->prm.forcing_predictor ? FLUID_HOOK_PREDICTOR : 0);
    }
    double w1 = wtime();
    /* the impulses accumulate over the stages until the targets are set again */
    q->stage_first = 0;
    if (stage == 0 || !q->frozen) set_targets(ibm, q->t_stage0 + q->t_step + dt_stage);
    ibm->wall_alpha += w1 - w0;
    ibm->wall_forcing += wtime() - w1;
}

/* Plane i of the predicted velocity (all its components): the forcing. */
void ibm_force_plane(fluid_t *f, double *const ustar[3], int stage, double dt_stage, int i, void *ctx)
{
    (void)f;
    (void)stage;
    ibm_t *ibm = ctx;
    ibm_priv_t *q = ibm_priv(ibm);
    long np = (long)ibm->g->nxl + 1, any = 0;
    for (int c = 0; c < ibm->g->dim; c++) any |= q->plane_nrun[c * np + i + 1] > q->plane_nrun[c * np + i];
    if (!any) return; /* (most planes of a scene with few spheres: not even timed) */
    double w0 = wtime();
    for (int c = 0; c < ibm->g->dim; c++)
        force_node_runs(ibm, ustar, q->plane_nrun[c * np + i], q->plane_nrun[c * np + i + 1], dt_stage,
                        q->stage_first);
    ibm->wall_forcing += wtime() - w0;
}

/* After the sweep (u* forced by the plane hook, ghosts filled): the extra
 * forcing iterations, (project, force) N times, and the impulses of the
 * stage before the solid fraction moves. */
void ibm_stage_force(fluid_t *f, int stage, double dt_stage, void *ctx)
{
    (void)stage;
    ibm_t *ibm = ctx;
    ibm_priv_t *q = ibm_priv(ibm);
    double w0 = wtime();
    for (int it = 0; it < ibm->prm.forcing_iterations; it++) {
        fluid_stage_project(f, dt_stage);
        force_nodes(ibm, dt_stage);
    }
    if (!q->frozen) sphere_sums(ibm, q->sum, 1, 0);
    ibm->wall_forcing += wtime() - w0;
}

/* Mask the components a geometry does not have: axisymmetric spheres move
 * along the axis (y) only and do not rotate; discs move in the plane and
 * rotate about z. */
static void mask_geometry(const grid_t *g, double v[3], double w[3])
{
    if (g->geom == GEOM_AXI) {
        v[0] = v[2] = 0.0;
        w[0] = w[1] = w[2] = 0.0;
    } else if (g->dim == 2) {
        v[2] = 0.0;
        w[0] = w[1] = 0.0;
    }
}

/* Where the solid fraction of sphere s goes at the end of a stage of
 * length dt ending at t_end: the explicit prediction. */
static void predict_centre(const ibm_t *ibm, ibm_sphere_t *s, double dt, double t_end)
{
    double u1[3], w1[3];
    if (s->kind == IBM_FREE && ibm->prm.free_alpha_per_step) return; /* α held over the step */
    switch (s->kind) {
    case IBM_FIXED:
    case IBM_EXTERNAL: memcpy(s->xa, s->x, sizeof s->xa); return; /* moved between steps only */
    case IBM_PRESCRIBED:
        ibm_prescribed_velocity(ibm, s, t_end, u1, w1);
        mask_geometry(ibm->g, u1, w1);
        for (int c = 0; c < 3; c++) s->xa[c] = s->x[c] + 0.5 * dt * (s->u[c] + u1[c]);
        return;
    default:
        for (int c = 0; c < 3; c++) s->xa[c] = s->x[c] + dt * s->u[c];
    }
}

/* Put a coordinate back in the domain along the periodic directions. */
static void wrap_periodic(const grid_t *g, double x[3])
{
    for (int d = 0; d < g->dim; d++)
        if (g->periodic[d]) {
            double L = g->L[d];
            while (x[d] < g->x0[d]) x[d] += L;
            while (x[d] >= g->x0[d] + L) x[d] -= L;
        }
}

/* Advance sphere p over the stage from the reduced sums (I^k, L^k about
 * X^k = xa, and the forcing impulses); J, K: its hydrodynamic impulses. */
static void update_sphere(ibm_t *ibm, int p, double dt, double t_end, double J[3], double K[3])
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    ibm_sphere_t *s = &ibm->s[p];
    const double *sum = q->sum + (long)p * IBM_NSUM, *prev = q->mom_prev + 6 * p;
    double rho = ibm->f->prm.rho, V = ibm_volume(ibm, p), m = ibm_mass(ibm, p), I = ibm_inertia(ibm, p);
    /* u × I with I the mean over the stage (≈ V u × u = 0 for a rigid interior) */
    double Im[3];
    for (int c = 0; c < 3; c++) Im[c] = 0.5 * (sum[IBM_MOM + c] + prev[c]);
    double uxI[3] = {s->u[1] * Im[2] - s->u[2] * Im[1], s->u[2] * Im[0] - s->u[0] * Im[2],
                     s->u[0] * Im[1] - s->u[1] * Im[0]};
    int rigid = ibm->prm.force_model == IBM_FORCE_RIGID;
    double u0[3], w0[3], du[3] = {0, 0, 0}, dw[3] = {0, 0, 0};
    memcpy(u0, s->u, sizeof u0);
    memcpy(w0, s->omega, sizeof w0);
    /* the reference point of L moves with the solid fraction: not so for
     * fixed and external spheres, whose α stays where it is over the step */
    double dt_ref = alpha_held(ibm, s) ? 0.0 : dt;
    for (int c = 0; c < 3; c++) {
        J[c] = rho * (sum[IBM_MOM + c] - prev[c] - sum[IBM_FIMP + c]);
        K[c] = rho * (sum[IBM_ANG + c] - prev[3 + c] + dt_ref * uxI[c] - sum[IBM_TIMP + c]);
    }
    switch (s->kind) {
    case IBM_FREE: {
        double rp = s->density;
        if (!rigid) {
            double mv = ibm->prm.virtual_mass * rho * V, Iv = ibm->prm.virtual_mass * rho / rp * I;
            for (int c = 0; c < 3; c++) {
                double W = (rp - rho) * V * ibm->prm.gravity[c];
                du[c] = (J[c] + W * dt + mv * s->du_prev[c]) / (m + mv);
                dw[c] = (K[c] + Iv * s->dw_prev[c]) / (I + Iv);
            }
        } else {
            /* eq. 2.32–2.33 with the pressure relative to hydrostatic */
            for (int c = 0; c < 3; c++) {
                du[c] = ibm->prm.gravity[c] * dt - rho * sum[IBM_FIMP + c] / ((rp - rho) * V);
                dw[c] = -rho * rp / (rp - rho) * sum[IBM_TIMP + c] / I;
            }
        }
        mask_geometry(g, du, dw);
        for (int c = 0; c < 3; c++) {
            s->x[c] += dt * (s->u[c] + 0.5 * du[c]);
            s->u[c] += du[c];
            s->omega[c] += dw[c];
            s->du_prev[c] = du[c];
            s->dw_prev[c] = dw[c];
        }
        break;
    }
    case IBM_FIXED: break;
    case IBM_PRESCRIBED:
        ibm_prescribed_velocity(ibm, s, t_end, s->u, s->omega);
        mask_geometry(g, s->u, s->omega);
        memcpy(s->x, s->xa, sizeof s->x);
        for (int c = 0; c < 3; c++) {
            du[c] = s->u[c] - u0[c];
            dw[c] = s->omega[c] - w0[c];
        }
        break;
    case IBM_EXTERNAL: memcpy(s->x, s->xa, sizeof s->x); break;
    }
    if (rigid) {
        /* the rigid interior of eq. 2.32: ρ V Δu − ρ ∫ f, ρ (I/ρ_p) Δω − ρ ∫ r × f */
        double If = s->density > 0 ? I / s->density : 0.0;
        for (int c = 0; c < 3; c++) {
            J[c] = rho * (V * du[c] - sum[IBM_FIMP + c]);
            K[c] = rho * (If * dw[c] - sum[IBM_TIMP + c]);
        }
    }
    double none[3] = {0, 0, 0};
    mask_geometry(g, J, none);
    if (g->geom == GEOM_AXI) K[0] = K[1] = K[2] = 0.0;
    if (g->dim == 2) K[0] = K[1] = 0.0;
    wrap_periodic(g, s->x);
}

void ibm_stage_end(fluid_t *f, int stage, double dt_stage, void *ctx)
{
    ibm_t *ibm = ctx;
    ibm_priv_t *q = ibm_priv(ibm);
    q->t_step += dt_stage;
    double t_end = q->t_stage0 + q->t_step;
    if (q->frozen) {
        /* nothing moves within the step: one impulse for the whole step */
        if (stage < 2) return;
        double w0 = wtime();
        sphere_sums(ibm, q->sum, 1, 1);
        reduce_sums(ibm);
        for (int p = 0; p < ibm->n; p++) {
            double J[3], K[3];
            update_sphere(ibm, p, q->t_step, t_end, J, K);
            for (int d = 0; d < 3; d++) {
                ibm->s[p].force[d] = J[d] / q->t_step;
                ibm->s[p].torque[d] = K[d] / q->t_step;
                ibm->s[p].xpred[d] = ibm->s[p].xa[d] + q->t_step * ibm->s[p].u[d];
            }
            for (int d = 0; d < 6; d++) q->mom_prev[6 * p + d] = q->sum[(long)p * IBM_NSUM + IBM_MOM + d];
        }
        ibm->wall_integrals += wtime() - w0;
        return;
    }
    /* move the solid fraction to the predicted centres */
    int moved = 0;
    for (int p = 0; p < ibm->n; p++) {
        ibm_sphere_t *s = &ibm->s[p];
        double xa0[3];
        memcpy(xa0, s->xa, sizeof xa0);
        predict_centre(ibm, s, dt_stage, t_end);
        wrap_periodic(ibm->g, s->xa);
        moved |= memcmp(xa0, s->xa, sizeof xa0) != 0;
    }
    double w0 = wtime();
    if (moved) ibm_build_nodes(ibm, q->sum, 0);
    double w1 = wtime();
    if (!moved) ibm_momentum(ibm, q->sum);
    reduce_sums(ibm);
    for (int p = 0; p < ibm->n; p++) {
        double J[3], K[3];
        update_sphere(ibm, p, dt_stage, t_end, J, K);
        for (int d = 0; d < 3; d++) {
            q->imp_step[6 * p + d] += J[d];
            q->imp_step[6 * p + 3 + d] += K[d];
        }
        for (int d = 0; d < 6; d++) q->mom_prev[6 * p + d] = q->sum[(long)p * IBM_NSUM + IBM_MOM + d];
    }
    if (stage == 2)
        for (int p = 0; p < ibm->n; p++) {
            ibm_sphere_t *s = &ibm->s[p];
            /* a free sphere whose α was held: its own motion over the step,
             * all of it counted when α is moved (λ = 1) */
            int own = s->kind == IBM_FREE && ibm->prm.free_alpha_per_step;
            for (int d = 0; d < 3; d++) {
                s->force[d] = q->imp_step[6 * p + d] / q->t_step;
                s->torque[d] = q->imp_step[6 * p + 3 + d] / q->t_step;
                s->xpred[d] = own ? s->x[d] : s->xa[d] + q->t_step * s->u[d];
            }
        }
    ibm->wall_alpha += w1 - w0;
    ibm->wall_integrals += wtime() - w1;
}
