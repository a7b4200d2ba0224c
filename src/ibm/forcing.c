/* forcing.c — the direct forcing of every RK3 stage, the hydrodynamic force
 * and torque of each sphere, and the rigid-body update of the spheres.
 *
 * Stage k (Δt_k = (γ_k + ζ_k) Δt), fluid hooks of fluid.h:
 *
 *  before the projection (ibm_stage_force), on the predicted velocity u*:
 *     u* ← u* + α (U − u*)         at every node with α > 0,
 *  U the rigid-body velocity u_p + ω_p × r of the sphere at the start of the
 *  stage, i.e. f = α (U − u*)/Δt_k.  Overlapping spheres: α = min(1, Σ α_p)
 *  and U the α-weighted mean of their velocities; sphere p takes the share
 *  α_p/Σα_p of the node's impulse.  With forcing_iterations = N the pair
 *  (force, project) is done N extra times before the final forcing.
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
 *  where the C_v terms are the virtual-mass stabilisation of Schwarz,
 *  Kempe & Fröhlich (2015): the explicit coupling feels the fluid's
 *  reaction (added mass) to the velocity change of the previous stage, and
 *  is unstable when that reaction exceeds the particle's inertia (ρ_p/ρ
 *  below about 1); adding C_v ρ V_p (Δu − Δu_prev) leaves every steady
 *  state unchanged and makes light particles stable (docs/theory.md §6b).
 *  The seed's rigid-body model (force_model = rigid, eq. 2.32) instead
 *  assumes the fluid inside moves rigidly:
 *     Δu = g Δt_k − ρ ∫ f dV Δt_k / ((ρ_p − ρ) V_p).
 */
#include <math.h>
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

static inline int node_i(const grid_t *g, long m) { return (int)(m / g->sx) - 1; }

/* One forcing of the current velocity; adds the impulse ∫ f dV Δt_k of each
 * sphere and its moment to sum[IBM_FIMP..]. */
static void force_pass(ibm_t *ibm, double dt)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    fluid_t *f = ibm->f;
    double r[3];
    /* Σ α_p and Σ α_p U_p at every node */
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        for (long e = q->start[p]; e < q->start[p + 1]; e++) {
            const ibm_node_t *nd = &q->nodes[e];
            ibm_node_offset(ibm, nd, s, r);
            q->asum[nd->c][nd->m] += nd->alpha;
            q->aux[nd->c][nd->m] += nd->alpha * ibm_rigid_velocity(s, nd->c, r);
        }
    }
    /* force each node once: u ← u + β (U − u); keep the impulse in aux and
     * mark the node done by the sign of asum */
    double kappa = ibm->prm.forcing_time, nu = f->prm.nu;
    for (long e = 0; e < q->nnodes; e++) {
        const ibm_node_t *nd = &q->nodes[e];
        double A = q->asum[nd->c][nd->m];
        if (A <= 0.0) continue;
        double a = fmin(A, 1.0), beta = a;
        if (kappa > 0 && a < 1.0) {
            double h = q->hcell[nd->c][node_i(g, nd->m)], tau = kappa * h * h / nu;
            beta = a * dt / ((1.0 - a) * tau + a * dt);
        }
        double *u = &f->u[nd->c][nd->m];
        double imp = beta * (q->aux[nd->c][nd->m] / A - *u);
        *u += imp;
        q->aux[nd->c][nd->m] = imp;
        q->asum[nd->c][nd->m] = -A;
    }
    /* each sphere's share α_p/Σα of the impulse, and its moment */
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        double *sum = q->sum + (long)p * IBM_NSUM, t[3];
        for (long e = q->start[p]; e < q->start[p + 1]; e++) {
            const ibm_node_t *nd = &q->nodes[e];
            double J = nd->alpha / -q->asum[nd->c][nd->m] * q->aux[nd->c][nd->m] * q->vol[nd->c][node_i(g, nd->m)];
            sum[IBM_FIMP + nd->c] += J;
            ibm_node_offset(ibm, nd, s, r);
            cross_axis(r, nd->c, J, t);
            for (int d = 0; d < 3; d++) sum[IBM_TIMP + d] += t[d];
        }
    }
    for (long e = 0; e < q->nnodes; e++) {
        const ibm_node_t *nd = &q->nodes[e];
        q->asum[nd->c][nd->m] = 0.0;
        q->aux[nd->c][nd->m] = 0.0;
    }
}

/* ∫ α_p u dV and ∫ α_p r × u dV of every sphere on this rank into
 * sum[IBM_MOM..IBM_ANG+2]. */
void ibm_momentum(ibm_t *ibm, double *sum_all)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    double r[3], t[3];
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        double *sum = sum_all + (long)p * IBM_NSUM;
        for (int d = 0; d < 6; d++) sum[IBM_MOM + d] = 0.0;
        for (long e = q->start[p]; e < q->start[p + 1]; e++) {
            const ibm_node_t *nd = &q->nodes[e];
            double a = nd->alpha * ibm->f->u[nd->c][nd->m] * q->vol[nd->c][node_i(g, nd->m)];
            sum[IBM_MOM + nd->c] += a;
            ibm_node_offset(ibm, nd, s, r);
            cross_axis(r, nd->c, a, t);
            for (int d = 0; d < 3; d++) sum[IBM_ANG + d] += t[d];
        }
    }
}

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
    ibm_build_nodes(ibm);
    double w1 = wtime();
    memset(q->sum, 0, (size_t)ibm->n * IBM_NSUM * sizeof(double));
    ibm_momentum(ibm, q->sum);
    reduce_sums(ibm);
    for (int p = 0; p < ibm->n; p++)
        for (int d = 0; d < 6; d++) q->mom_prev[6 * p + d] = q->sum[(long)p * IBM_NSUM + IBM_MOM + d];
    ibm->wall_alpha += w1 - w0;
    ibm->wall_integrals += wtime() - w1;
}

void ibm_update_geometry(ibm_t *ibm)
{
    for (int p = 0; p < ibm->n; p++) memcpy(ibm->s[p].xa, ibm->s[p].x, sizeof ibm->s[p].x);
    ibm_rebuild_geometry(ibm);
}

void ibm_stage_force(fluid_t *f, int stage, double dt_stage, void *ctx)
{
    ibm_t *ibm = ctx;
    ibm_priv_t *q = ibm_priv(ibm);
    double w0 = wtime();
    if (stage == 0) {
        q->t_step = 0.0;
        q->t_stage0 = f->time;
        memset(q->imp_step, 0, (size_t)ibm->n * 6 * sizeof(double));
    }
    memset(q->sum, 0, (size_t)ibm->n * IBM_NSUM * sizeof(double));
    for (int it = 0; it < ibm->prm.forcing_iterations; it++) {
        force_pass(ibm, dt_stage);
        fluid_stage_project(f, dt_stage);
    }
    force_pass(ibm, dt_stage);
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
    switch (s->kind) {
    case IBM_FIXED: memcpy(s->xa, s->x, sizeof s->xa); return;
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
    for (int c = 0; c < 3; c++) {
        J[c] = rho * (sum[IBM_MOM + c] - prev[c] - sum[IBM_FIMP + c]);
        K[c] = rho * (sum[IBM_ANG + c] - prev[3 + c] + dt * uxI[c] - sum[IBM_TIMP + c]);
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
    if (moved) ibm_build_nodes(ibm);
    double w1 = wtime();
    ibm_momentum(ibm, q->sum);
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
        for (int p = 0; p < ibm->n; p++)
            for (int d = 0; d < 3; d++) {
                ibm->s[p].force[d] = q->imp_step[6 * p + d] / q->t_step;
                ibm->s[p].torque[d] = q->imp_step[6 * p + 3 + d] / q->t_step;
            }
    ibm->wall_alpha += w1 - w0;
    ibm->wall_integrals += wtime() - w1;
}
