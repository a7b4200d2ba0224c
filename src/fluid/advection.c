/* advection.c — the advection term ∇·(u⊗u) in the energy-conserving
 * divergence form on the MAC grid (Morinishi et al. 1998; Verstappen &
 * Veldman 2003).
 *
 * For each momentum control volume (the cell centred on the unknown: for u_i
 * from x_c,i to x_c,i+1, for v and w the pressure cell shifted by half a cell
 * along their own direction) the term is
 *     N = (1/V) Σ_faces F_f ū_f,
 * with F_f the convecting volume flux through the face and ū_f the ARITHMETIC
 * MEAN of the two unknowns the face separates.  The fluxes are the half sums
 * of the mass fluxes of the two pressure cells the control volume overlaps,
 * so Σ_f F_f = ½(V_a D_a + V_b D_b) = 0 whenever the pressure cells are
 * divergence-free.  Then Σ V u·N = Σ_f F_f ½(u_a u_b − u_b u_a) + Σ ½u²·Σ F = 0:
 * the term neither creates nor destroys discrete kinetic energy
 * E = ½ Σ V u² (V: fluid_cell_volume), on uniform and stretched grids, with
 * walls (zero normal flux) and periodic faces, and in axisymmetric geometry,
 * where areas and volumes carry the factor r (fluxes r_f u, volumes r dr dz).
 * In the axisymmetric (r, z) equations without swirl the divergence form
 * (1/r)∂r(r u_r u_r) + ∂z(u_z u_r) has no extra metric term: the hoop term
 * −u_θ²/r vanishes.  On a stretched x grid the mean ū_f is first order
 * locally but the scheme stays second order globally (Verstappen & Veldman).
 */
#include "fluid_internal.h"

/* The kernels below compute, on the unknowns of each component, the
 * advection term N = ∇·(u⊗u) and the Laplacian L u (the stencil of
 * viscous.c, fused here; the tests check that both agree) and from them the
 * explicit right-hand side of a Runge–Kutta stage, H = ca·N + cv·L u.  In
 * the fused mode they also apply the predictor in the same sweep:
 *     u* = u + dg·H + dz·H_old + α Δt (f − G p) + ce·L u,
 * written over H_old (which is read at the same point first).  The loops run
 * plane by plane (i), line by line (j in 3-D), and the three components
 * inside, so that the lines of u, v, w a line needs are still in cache for
 * the next component; the innermost loop runs along a contiguous line (k in
 * 3-D, j in 2-D: FLUID_FOR_LINES) and is instantiated for 3-D and 2-D and
 * for each mode (is3d, fused are constants after inlining) so that it
 * vectorises. */
#define KERNEL static inline __attribute__((always_inline)) void

/* per-i coefficients of a line of one component */
typedef struct {
    double rv, wa, wb, afw, af0, afe; /* advection metric */
    double cw, ce, cd, cy, cz, xw;    /* viscous stencil, moving-wall term */
    double ag, af;                    /* α Δt / Δ of the pressure gradient, α Δt f_c */
} coef_t;

/* the stage's scalars */
typedef struct {
    double ca, cv, dg, dz, ce;
    const double *p;
} stage_t;

/* `hstore`: H is kept for the next stage (not after the last one); `hold`:
 * the predictor has a ζ H_old term (not in the first stage, ζ_1 = 0, where
 * H_old is not read).  Dropping them saves three streams over memory each. */
#define PREDICT(Hd, US, m, h, Lu, sp)                                                         \
    do {                                                                                      \
        if (hstore) Hd[m] = h;                                                                \
        if (fused) {                                                                          \
            double s_ = q0 + st->dg * h;                                                      \
            if (hold) s_ += st->dz * US[m];                                                   \
            US[m] = s_ + k->af - k->ag * (p[m + sp] - p[m]) + st->ce * Lu;                    \
        }                                                                                     \
    } while (0)

/* u-momentum: control volume a_f,i Δx_c,i × Δy × Δz around face i. */
KERNEL u_line(const double *restrict u, const double *restrict v, const double *restrict w, double *restrict Hd,
              double *restrict US, long c0, long len, long sx, long sy, double rdy, double rdz, const coef_t *k,
              const stage_t *st, int is3d, int fused, int hold, int hstore)
{
    const double *restrict p = st->p;
    for (long c = c0; c < c0 + len; c++) {
        double uc = u[c], q0 = uc;
        double Fe = k->af0 * uc + k->afe * u[c + sx], Fw = k->afw * u[c - sx] + k->af0 * uc;
        double X = (Fe * (uc + u[c + sx]) - Fw * (u[c - sx] + uc)) * 0.5 * k->rv;
        double Vn = k->wa * v[c] + k->wb * v[c + sx], Vs = k->wa * v[c - sy] + k->wb * v[c + sx - sy];
        double Y = (Vn * (uc + u[c + sy]) - Vs * (u[c - sy] + uc)) * 0.5 * rdy;
        double Lu = k->cw * u[c - sx] + k->ce * u[c + sx] - k->cd * uc + k->cy * (u[c + sy] + u[c - sy]);
        double Z = 0.0;
        if (is3d) {
            double Wt = k->wa * w[c] + k->wb * w[c + sx], Wb = k->wa * w[c - 1] + k->wb * w[c + sx - 1];
            Z = (Wt * (uc + u[c + 1]) - Wb * (u[c - 1] + uc)) * 0.5 * rdz;
            Lu += k->cz * (u[c + 1] + u[c - 1]);
        }
        double h = st->ca * (X + Y + Z) + st->cv * Lu;
        PREDICT(Hd, US, c, h, Lu, sx);
    }
}

/* v-momentum: control volume a_c,i Δx_f,i × Δy × Δz around y-face j. */
KERNEL v_line(const double *restrict u, const double *restrict v, const double *restrict w, double *restrict Hd,
              double *restrict US, long c0, long len, long sx, long sy, double rdy, double rdz, const coef_t *k,
              const stage_t *st, int is3d, int fused, int hold, int hstore)
{
    const double *restrict p = st->p;
    for (long c = c0; c < c0 + len; c++) {
        double vc = v[c], q0 = vc;
        double Ue = k->af0 * (u[c] + u[c + sy]), Uw = k->afw * (u[c - sx] + u[c - sx + sy]);
        double X = (Ue * (vc + v[c + sx]) - Uw * (v[c - sx] + vc)) * k->rv;
        double Vn = vc + v[c + sy], Vs = v[c - sy] + vc;
        double Y = (Vn * Vn - Vs * Vs) * 0.25 * rdy;
        double Lu = k->cw * v[c - sx] + k->ce * v[c + sx] - k->cd * vc + k->cy * (v[c + sy] + v[c - sy]) + k->xw;
        double Z = 0.0;
        if (is3d) {
            double Wt = w[c] + w[c + sy], Wb = w[c - 1] + w[c - 1 + sy];
            Z = (Wt * (vc + v[c + 1]) - Wb * (v[c - 1] + vc)) * 0.25 * rdz;
            Lu += k->cz * (v[c + 1] + v[c - 1]);
        }
        double h = st->ca * (X + Y + Z) + st->cv * Lu;
        PREDICT(Hd, US, c, h, Lu, sy);
    }
}

/* w-momentum (3-D only): control volume Δx_f,i × Δy × Δz around z-face k. */
KERNEL w_line(const double *restrict u, const double *restrict v, const double *restrict w, double *restrict Hd,
              double *restrict US, long c0, long len, long sx, long sy, double rdy, double rdz, const coef_t *k,
              const stage_t *st, int fused, int hold, int hstore)
{
    const double *restrict p = st->p;
    for (long c = c0; c < c0 + len; c++) {
        double wc = w[c], q0 = wc;
        double Ue = u[c] + u[c + 1], Uw = u[c - sx] + u[c - sx + 1];
        double X = (Ue * (wc + w[c + sx]) - Uw * (w[c - sx] + wc)) * k->rv;
        double Vn = v[c] + v[c + 1], Vs = v[c - sy] + v[c - sy + 1];
        double Y = (Vn * (wc + w[c + sy]) - Vs * (w[c - sy] + wc)) * 0.25 * rdy;
        double Wt = wc + w[c + 1], Wb = w[c - 1] + wc;
        double Z = (Wt * Wt - Wb * Wb) * 0.25 * rdz;
        double Lu = k->cw * w[c - sx] + k->ce * w[c + sx] - k->cd * wc + k->cy * (w[c + sy] + w[c - sy]) +
                    k->cz * (w[c + 1] + w[c - 1]) + k->xw;
        double h = st->ca * (X + Y + Z) + st->cv * Lu;
        PREDICT(Hd, US, c, h, Lu, 1);
    }
}

/* The per-i coefficients of component c at local x index i. */
static void line_coefs(const fluid_t *f, int c, int i, double adt, coef_t *k)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *af = q->af, *ac = q->ac;
    const poisson_t *L = q->pv[c];
    int ig = i + g->ix0;
    if (c == 0) {
        k->rv = 1.0 / (af[i] * g->dxc[i]);
        /* v, w at the u-cell's y/z faces: the volume-weighted mean of the two
         * pressure cells (weights a_c Δx_f, summing to 2 a_f Δx_c up to O(h³)) */
        k->wa = 0.5 * ac[i] * g->dxf[i] * k->rv;
        k->wb = 0.5 * ac[i + 1] * g->dxf[i + 1] * k->rv;
        k->afw = 0.5 * af[i - 1];
        k->af0 = 0.5 * af[i];
        k->afe = 0.5 * af[i + 1];
    } else {
        /* v, w: radial fluxes a_f u at the cell's x faces, all products ¼ */
        k->rv = 0.25 / (ac[i] * g->dxf[i]);
        k->af0 = af[i];
        k->afw = af[i - 1];
        k->wa = k->wb = k->afe = 0.0;
    }
    k->cy = L->cy;
    k->cz = L->cz;
    k->cw = L->cw[ig];
    k->ce = L->ce[ig];
    k->cd = L->cd[ig] + 2.0 * (k->cy + k->cz);
    k->xw = (ig == 0 ? q->xwall[c][0] : 0.0) + (ig == g->n[0] - 1 ? q->xwall[c][1] : 0.0);
    k->ag = adt * (c == 0 ? 1.0 / g->dxc[i] : c == 1 ? 1.0 / g->dy : 1.0 / g->dz);
    k->af = adt * f->prm.body_force[c];
}

/* Each line kernel instantiated with constant flags (is3d_, fused_, hold_,
 * hstore_) for the modes used: the right-hand side alone, and the fused
 * predictor of the first (no H_old), middle and last (H not kept) stages. */
#define LINE_VARIANTS_MODES(fn, args)                                                           \
    do {                                                                                        \
        if (!fused) { const int fused_ = 0, hold_ = 0, hstore_ = 1; fn args; }                 \
        else if (!hold) { const int fused_ = 1, hold_ = 0, hstore_ = 1; fn args; }             \
        else if (hstore) { const int fused_ = 1, hold_ = 1, hstore_ = 1; fn args; }            \
        else { const int fused_ = 1, hold_ = 1, hstore_ = 0; fn args; }                        \
    } while (0)
#define LINE_VARIANTS_3D(fn, args)          \
    do {                                    \
        const int is3d_ = 1;                \
        (void)is3d_;                        \
        LINE_VARIANTS_MODES(fn, args);      \
    } while (0)
#define LINE_VARIANTS(fn, args)                  \
    do {                                         \
        if (is3d) LINE_VARIANTS_3D(fn, args);    \
        else {                                   \
            const int is3d_ = 0;                 \
            LINE_VARIANTS_MODES(fn, args);       \
        }                                        \
    } while (0)

/* One sweep over the unknowns of every component: H[c] = ca·N_c + cv·L u_c
 * (unless H is NULL), and when US is given the predictor u* written over
 * US[c] (= H_old on entry, read only when st->dz ≠ 0).  Ghosts of u must be
 * valid. */
static void rhs_sweep(const fluid_t *f, const stage_t *st, double adt, double *const H[3], double *const US[3],
                      double div_scale, double *div, const fluid_ahead_t *ahead, const fluid_ahead_t *done,
                      const fluid_ahead_t *after_div)
{
    const grid_t *g = f->g;
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    long sx = g->sx, sy = g->sy;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    int is3d = g->dim == 3, fused = US != NULL, nc = fluid_ncomp(g);
    int hold = fused && st->dz != 0.0, hstore = H != NULL;
    int iend[3], nj[3], nk[3];
    for (int c = 0; c < nc; c++) {
        iend[c] = fluid_iend(g, c);
        nj[c] = fluid_nu(g, c, 1);
        nk[c] = fluid_nu(g, c, 2);
    }
    double *nous[3] = {NULL, NULL, NULL};
    double *const *us = fused ? US : nous;
    for (int i = 0; i < g->nxl; i++) {
        /* the planes of u and p this plane reads (i − 1 … i + 1) made final */
        if (ahead) ahead->fn(ahead->ctx, i);
        coef_t k[3];
        for (int c = 0; c < nc; c++) line_coefs(f, c, i, adt, &k[c]);
        int nl = is3d ? g->n[1] : 1;
        for (int jl = 0; jl < nl; jl++)
            for (int c = 0; c < nc; c++) {
                if (i >= iend[c] || (is3d && jl >= nj[c])) continue;
                long c0 = G_IDX(g, i, jl, 0), len = is3d ? nk[c] : nj[c];
                double *Hc = H ? H[c] : NULL;
                if (c == 0) LINE_VARIANTS(u_line, (u, v, w, Hc, us[0], c0, len, sx, sy, rdy, rdz, &k[0], st, is3d_,
                                                   fused_, hold_, hstore_));
                else if (c == 1) LINE_VARIANTS(v_line, (u, v, w, Hc, us[1], c0, len, sx, sy, rdy, rdz, &k[1], st,
                                                        is3d_, fused_, hold_, hstore_));
                else if (is3d) LINE_VARIANTS_3D(w_line, (u, v, w, Hc, us[2], c0, len, sx, sy, rdy, rdz, &k[2], st,
                                                         fused_, hold_, hstore_));
            }
        /* plane i of u* is written: the plane hook (forcing) and then, with
         * plane i of u* final (and plane i − 1, which D u* also reads), its
         * divergence while it is in cache */
        if (done) done->fn(done->ctx, i);
        if (div) fluid_divergence_interior_plane(f, (const double *const *)US, div_scale, div, i);
        if (after_div) after_div->fn(after_div->ctx, i);
    }
}

/* The quadratic-ghost wall terms (viscous.c) of cv·L u in H and of
 * (dg·cv + ce)·L u in the predictor: a pass over the wall cells after the
 * sweep (u is still u^{k−1}). */
static void wall_ghost_terms(const fluid_t *f, double cv, double dg, double ce, double *const H[3],
                             double *const US[3])
{
    for (int c = 0; c < fluid_ncomp(f->g); c++) {
        if (H && cv != 0.0) fluid_wall_ghost_add(f, c, f->u[c], cv, H[c]);
        if (US && dg * cv + ce != 0.0) fluid_wall_ghost_add(f, c, f->u[c], dg * cv + ce, US[c]);
    }
}

void fluid_rhs(const fluid_t *f, double ca, double cv, double *const out[3])
{
    stage_t st = {.ca = ca, .cv = cv, .p = f->p};
    rhs_sweep(f, &st, 0.0, out, NULL, 0.0, NULL, NULL, NULL, NULL);
    wall_ghost_terms(f, cv, 0.0, 0.0, out, NULL);
}

void fluid_rhs_predict(const fluid_t *f, double ca, double cv, double dg, double dz, double adt, double ce,
                       double *const H[3], double *const US[3])
{
    fluid_rhs_predict_div(f, ca, cv, dg, dz, adt, ce, H, US, 0.0, NULL, NULL, NULL, NULL);
}

void fluid_rhs_predict_div(const fluid_t *f, double ca, double cv, double dg, double dz, double adt, double ce,
                           double *const H[3], double *const US[3], double div_scale, double *div,
                           const fluid_ahead_t *ahead, const fluid_ahead_t *done, const fluid_ahead_t *after_div)
{
    stage_t st = {.ca = ca, .cv = cv, .dg = dg, .dz = dz, .ce = ce, .p = f->p};
    rhs_sweep(f, &st, adt, H, US, div_scale, f->g->dim == 3 ? div : NULL, ahead, done, after_div);
    /* the wall terms change u* next to walls only: cells fluid_interior leaves out */
    wall_ghost_terms(f, cv, dg, ce, H, US);
}

void fluid_advection(const fluid_t *f, double *const out[3]) { fluid_rhs(f, 1.0, 0.0, out); }
