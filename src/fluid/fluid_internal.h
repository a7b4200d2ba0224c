/* fluid_internal.h — private state of the fluid solver, shared by the files
 * of src/fluid/ only (the public interface is include/fluid.h). */
#ifndef IBMDEM_FLUID_INTERNAL_H
#define IBMDEM_FLUID_INTERNAL_H

#include "fluid.h"

/* Quadratic wall ghost (wall_ghost = quadratic) at one no-slip wall for one
 * tangential component: the viscous operator with the quadratic ghost minus
 * the one with the linear ghost, at the wall cell, is
 *     c_wall (g_quad − g_lin) = kU + k0 u_0 + k1 u_1
 * (u_0 the wall cell, u_1 its neighbour away from the wall; kU includes the
 * wall velocity).  viscous.c sets and applies it. */
typedef struct {
    int on;
    double kU, k0, k1;
} wall_quad_t;

typedef struct {
    poisson_t *pp;         /* VAR_P: projection (L = D·G) */
    poisson_t *pv[3];      /* L of each velocity location: the Crank–Nicolson Helmholtz
                            * solvers when implicit, the operator alone when explicit */
    /* Runge–Kutta storage, rotated with u[c] at every stage (fluid_step):
     * h[c] holds H of the previous stage (the ζ term) and receives u*;
     * spare[c] receives H of this stage. */
    double *h[3];
    double *spare[3];
    double *work;          /* scratch: the pressure correction φ, the Helmholtz right-hand sides */
    double *halo_buf;      /* send and receive buffers of the combined x halo (2 × 3 planes) */
    /* metric of the local x range, index −1..nxl (stored at +1): face and
     * centre area factors (r in axisymmetric geometry, 1 otherwise) */
    double *af, *ac;
    /* coefficient of the wall ghost of a tangential component at a no-slip x
     * wall, times 2 U_wall: the inhomogeneous part of L at the first and last
     * cell (the y and z walls are handled by the ghost values themselves) */
    double xwall[3][2];
    /* [component][wall-normal direction][side]: the quadratic-ghost wall terms */
    wall_quad_t wq[3][3][2];
    int wq_any;            /* some wq[..].on */
} fluid_priv_t;

static inline fluid_priv_t *fluid_priv(const fluid_t *f) { return (fluid_priv_t *)f->priv; }

/* Number of unknowns of component c along direction d (global): a wall or
 * axis face normal to c lies on index n−1 at the high side, which is a
 * boundary value, not an unknown. */
static inline int fluid_nu(const grid_t *g, int c, int d)
{
    return g->n[d] - (c == d && !g->periodic[d] ? 1 : 0);
}
/* One past the last local x index of the unknowns of component c. */
static inline int fluid_iend(const grid_t *g, int c)
{
    int e = fluid_nu(g, c, 0) - g->ix0;
    return e < g->nxl ? e : g->nxl;
}
static inline int fluid_ncomp(const grid_t *g) { return g->dim; }
/* The unknowns of one component at local x index i as contiguous lines:
 * (j, k = 0..nk−1) for each j in 3-D, (j = 0..nj−1, k = 0) in 2-D, where the
 * j stride is 1 (nz = 1, no z ghosts).  Declares c0 (first index) and len. */
#define FLUID_FOR_LINES(g, i, nj, nk, c0, len)                                          \
    for (int jl_ = 0, nl_ = (g)->dim == 3 ? (nj) : 1; jl_ < nl_; jl_++)                \
        for (long c0 = G_IDX(g, i, (g)->dim == 3 ? jl_ : 0, 0), len = (g)->dim == 3 ? (nk) : (nj), once_ = 1; \
             once_; once_ = 0)

/* max without the NaN rules of fmax (which the compiler cannot inline) */
static inline double dmax(double a, double b) { return a > b ? a : b; }

/* advection.c: out = ca·∇·(u⊗u) + cv·L u, one fused sweep */
void fluid_rhs(const fluid_t *f, double ca, double cv, double *const out[3]);
/* the same, H = ca·N + cv·L u, with the predictor in the same sweep:
 * US[c] (H_old on entry) ← u + dg·H + dz·H_old + adt·(f − G p) + ce·L u;
 * H_old is not read when dz = 0, H not stored when H is NULL */
void fluid_rhs_predict(const fluid_t *f, double ca, double cv, double dg, double dz, double adt, double ce,
                       double *const H[3], double *const US[3]);
/* the same, also div = div_scale · D u* on the interior cells (3-D,
 * fluid_interior; the caller completes it with fluid_divergence_rest), and
 * with `ahead` (or NULL) called before each x plane i is swept: it must
 * leave planes i − 1 … i + 1 of u and p final, ghosts included (step.c's
 * deferred correction); `done` (or NULL) is called when plane i of u* is
 * written, before its divergence: it may change u* on plane i (step.c's
 * plane hook: the immersed-boundary forcing); `after_div` (or NULL) after
 * the divergence of plane i (step.c: the plane's remaining cells and its
 * forward transform for the pressure solve) */
typedef struct {
    void (*fn)(void *ctx, int i);
    void *ctx;
} fluid_ahead_t;
void fluid_rhs_predict_div(const fluid_t *f, double ca, double cv, double dg, double dz, double adt, double ce,
                           double *const H[3], double *const US[3], double div_scale, double *div,
                           const fluid_ahead_t *ahead, const fluid_ahead_t *done, const fluid_ahead_t *after_div);
/* viscous.c */
void fluid_laplacian_add(const fluid_t *f, int c, const double *u, double scale, double *out);
void fluid_wall_terms_add(const fluid_t *f, int c, double scale, double *out);
void fluid_wall_ghost_add(const fluid_t *f, int c, const double *u, double scale, double *out);
void fluid_viscous_setup(fluid_t *f);
/* The explicit viscous step limit (fourier target; INFINITY without viscosity; timestep.c). */
double fluid_viscous_limit(const fluid_t *f);
/* viscous = auto: a step of this run can be implicit (the Helmholtz solvers are needed). */
int fluid_auto_may_be_implicit(const fluid_t *f);
/* The step dt is taken with the Crank–Nicolson viscous term. */
int fluid_step_is_implicit(const fluid_t *f, double dt);
/* bc.c */
void fluid_fill_pressure_ghosts(const fluid_t *f, double *p);
/* fluid_apply_bc in parts: the edge planes' ghosts, then an inner plane's */
void fluid_apply_bc_edges(fluid_t *f);
void fluid_apply_bc_plane(fluid_t *f, int i);
/* the same ghosts of plane i for the velocity arrays u (not yet f->u) */
void fluid_apply_bc_plane_of(const fluid_t *f, double *const u[3], int i);
/* timestep.c: max over cells of Σ_d |u_d|/Δ_d (|u_d| the larger of the two faces) */
double fluid_convective_rate(const fluid_t *f);
/* diagnostics.c: ke, div_max, cfl of f->diag from the current field (stats:
 * Σ V u² and max |u| of this rank if already known, else NULL; div_cfl: max
 * |D u| and the max convective rate of this rank if already known, else
 * NULL); div = scale · D u at the cells */
void fluid_divergence_scaled(const fluid_t *f, double scale, double *div);
void fluid_update_diagnostics(fluid_t *f, const double *stats, const double *div_cfl);
/* Fused divergence and diagnostics (3-D): the cells whose stencil reads only
 * unknowns of this rank, computed by a sweep as soon as a plane is final, and
 * the rest computed after the ghosts are filled; see diagnostics.c. */
void fluid_divergence_interior_plane(const fluid_t *f, const double *const uu[3], double scale, double *div, int i);
void fluid_divergence_rest(const fluid_t *f, double scale, double *div, int edges_only);
void fluid_interior_planes(const grid_t *g, int *ilo, int *ihi);
void fluid_divergence_rest_plane(const fluid_t *f, const double *const uu[3], double scale, double *div, int i);
void fluid_div_cfl_interior_plane(const fluid_t *f, int i, double *m);
void fluid_div_cfl_rest(const fluid_t *f, double *m);
/* step.c */
void fluid_project_stage(fluid_t *f, double dt_stage, int update_pressure, double *stats);

/* prm.hold_flow: set the superficial velocity along prm.hold_dir to
 * prm.hold_velocity by a uniform correction and add the corresponding
 * acceleration to prm.body_force (called by fluid_step after its last stage). */
void fluid_hold_flow_rate(fluid_t *f, double dt);

#endif
