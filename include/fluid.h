/* fluid.h — incompressible Navier–Stokes on the MAC grid: low-storage RK3,
 * incremental pressure-correction projection, explicit or Crank–Nicolson
 * viscous term.  The pressure is kinematic (p/ρ) and relative to hydrostatic
 * (decision 7 of the reference notes): gravity does not enter the fluid
 * equations of a constant-density fluid; particles get their immersed weight.
 */
#ifndef IBMDEM_FLUID_H
#define IBMDEM_FLUID_H

#include "config.h"
#include "grid.h"
#include "poisson.h"

typedef struct fluid fluid_t;

/* Called at every Runge–Kutta stage after the predictor and before the
 * projection (the immersed-boundary forcing lives here): may modify the
 * predicted velocity u*.  dt_stage = (γ_k + ζ_k) Δt.  The same type serves
 * the stage-end hook, called after the projection of every stage (u^k
 * divergence-free, ghosts filled): the immersed boundary measures the fluid
 * momentum inside the particles there and moves them. */
typedef void (*fluid_stage_hook_t)(fluid_t *f, int stage, double dt_stage, void *ctx);
/* Called for every local x plane i (0 .. nxl − 1, in order) of the predicted
 * velocity u* (the arrays ustar[c], which are not yet f->u inside the sweep)
 * once all its components are written, before the projection: may modify
 * u* at the unknowns of plane i (not its ghosts, not other planes).  Inside the predictor sweep when the fluid can (3-D, explicit
 * viscous term or FLUID_HOOK_PREDICTOR, no quadratic wall ghost:
 * docs/theory.md §1, step 1.1b), so that the plane is still in cache;
 * otherwise plane by plane after the sweep (and the Crank–Nicolson solves,
 * unless FLUID_HOOK_PREDICTOR).  Either way before the stage hook and with
 * the same result. */
typedef void (*fluid_plane_hook_t)(fluid_t *f, double *const ustar[3], int stage, double dt_stage, int i, void *ctx);

/* Promises a hook owner makes in f->hook_flags (what the fluid may then fuse),
 * and one request:
 *  FLUID_HOOK_KEEPS_USTAR  the stage hook reads u* but does not change it (the
 *                          divergence of u* may be formed inside the sweep);
 *  FLUID_HOOK_IDLE_UK      in this step, the stage-end hooks of stages 0 and 1
 *                          and the stage-begin hooks of stages 1 and 2 read
 *                          neither u nor p (the corrections of stages 0 and 1
 *                          may be deferred into the next sweep);
 *  FLUID_HOOK_PREDICTOR    (Crank–Nicolson only) the plane hook is called
 *                          before the Helmholtz solve, on its right-hand side
 *                          u* = u^{k−1} + Δt(γH + ζH_old) + αΔt(f − G p) + αΔtν/2 L u^{k−1},
 *                          with f->pred_u and f->pred_a set, from which the
 *                          explicit predictor with the whole viscous term,
 *                          ũ = u* + αΔtν/2 L u^{k−1}, is formed at the nodes
 *                          the hook forces; what it adds to u* becomes a
 *                          source term of the solve (the forcing inside the
 *                          implicit step, docs/theory.md §4.6).  Without it
 *                          the hook gets the solved u*.
 * The fluid reads them after the stage-begin hook of stage 0, for the step. */
enum { FLUID_HOOK_KEEPS_USTAR = 1, FLUID_HOOK_IDLE_UK = 2, FLUID_HOOK_PREDICTOR = 4 };

/* Coefficients of the low-storage RK3 (step.c): stage k advances by
 * (γ_k + ζ_k) Δt, i.e. to t + (8/15, 2/3, 1) Δt. */
extern const double fluid_rk_gamma[3], fluid_rk_zeta[3];

/* Ghost value of a wall-tangential velocity at a no-slip wall, as the
 * viscous operator sees it (docs/theory.md §4.3): the linear extrapolation
 * 2U − u_0 (its Laplacian is exact for linear profiles), or the quadratic one
 * through U, u_0, u_1 (exact for quadratic profiles: plane Poiseuille and
 * Hagen–Poiseuille on a uniform grid). */
typedef enum { WALL_GHOST_LINEAR = 0, WALL_GHOST_QUADRATIC = 1 } wall_ghost_t;

/* The viscous term (fluid_params_t implicit_viscous): explicit in the RK3
 * stages, Crank–Nicolson, or chosen per step (auto): explicit when its
 * stability limit allows the step the other limits set (or more than
 * 1/viscous_auto_ratio of it: an implicit step costs more), implicit
 * otherwise (docs/theory.md §1). */
enum { FLUID_VISCOUS_EXPLICIT = 0, FLUID_VISCOUS_IMPLICIT = 1, FLUID_VISCOUS_AUTO = 2 };

typedef struct {
    double nu;            /* kinematic viscosity */
    double rho;           /* density (for forces and output in physical units) */
    double body_force[3]; /* acceleration driving the flow (e.g. a pressure gradient) */
    int implicit_viscous; /* FLUID_VISCOUS_*: 0 explicit, 1 Crank–Nicolson, 2 auto (per step, fluid_stable_dt) */
    double viscous_auto_ratio; /* auto: implicit when the other limits allow more than this × the explicit limit */
    wall_ghost_t wall_ghost; /* no-slip wall closure of the viscous term */
    double cfl;           /* convective CFL target of the adaptive step */
    double fourier;       /* viscous stability target (explicit only) */
    double dt_fixed;      /* > 0: constant time step */
    double dt_max;
    poisson_opts_t poisson;
    int hold_flow;        /* the flow rate along the periodic direction hold_dir is held (fluid_step) */
    int hold_dir;
    double hold_velocity; /* ... at this superficial velocity; body_force[hold_dir] is then the drive it takes */
    int unfused;          /* verification switch, not a case-file key: every pass of the step on
                           * its own (no plane hook, divergence or correction inside the sweeps);
                           * bit-identical results (tests/test_ibm_fused.c, test_fluid_ops.c) */
} fluid_params_t;

typedef struct {
    double cfl;           /* convective CFL of the last step */
    double ke;            /* kinetic energy ½∫|u|² dV (per unit density) */
    double div_max;       /* max |div u| after projection, relative to max|u|/min Δ */
    double dt;            /* the last time step */
    double res_poisson;   /* relative residual of the last pressure solve */
    int it_poisson;       /* iterations of the last pressure solve */
} fluid_diag_t;

struct fluid {
    grid_t *g;
    fluid_params_t prm;
    double *u[3];         /* velocity components on their faces (u[2] NULL in 2-D); fluid_step
                           * swaps these arrays with its Runge–Kutta storage at every stage:
                           * read f->u[c] afresh, never keep the pointer across a step */
    double *p;            /* kinematic pressure relative to hydrostatic, cell centres */
    double time;
    long step;
    fluid_diag_t diag;
    fluid_stage_hook_t stage_begin_hook; /* before each predictor sweep (may be NULL) */
    fluid_plane_hook_t plane_hook;       /* on each plane of u* (may be NULL) */
    fluid_stage_hook_t stage_hook;       /* before each projection (may be NULL) */
    fluid_stage_hook_t stage_end_hook;   /* after each projection (may be NULL) */
    void *hook_ctx;                      /* passed to all hooks */
    int hook_flags;                      /* FLUID_HOOK_* */
    /* FLUID_HOOK_PREDICTOR, for the plane hook: u^{k−1} of the stage and
     * a = α_kΔtν/2, so that the explicit predictor at a node m of component
     * c and local x plane i is ũ = u*[m] + a fluid_laplacian_at(f, c, pred_u[c], i, m) */
    const double *pred_u[3];
    double pred_a;
    int implicit_step;    /* the viscous term of the current (or last) step is Crank–Nicolson */
    long implicit_steps;  /* steps taken with it (viscous = auto: the others were explicit) */
    double dt_viscous;    /* the explicit viscous limit (fourier target; INFINITY without viscosity) */
    void *priv;           /* work arrays and solvers of the implementation */
};

void fluid_register_keys(void);
/* Read [fluid] and [poisson] and check them against the grid; stops with
 * file:line: key: reason.  ([time] and [output] belong to the run driver.) */
void fluid_params_from_config(cfg_t *cfg, const grid_t *g, fluid_params_t *prm);
/* The kinematic viscosity of [fluid]: nu, or mu/rho. */
double fluid_nu_from_config(cfg_t *cfg);
fluid_t *fluid_create(grid_t *g, const fluid_params_t *prm);
/* Set the initial condition named in [fluid] init (stops on a bad value):
 * rest, taylor_green, abc or laminar (see docs/user-guide.md).  The field is
 * projected (fluid_project) so that it is discretely divergence-free. */
void fluid_init_from_config(fluid_t *f, cfg_t *cfg);
/* Remove the gradient part of u (projection without a pressure update), e.g.
 * after setting an initial field; fills the ghosts. */
void fluid_project(fluid_t *f);
/* From a stage hook: project the current u* as the end of the stage does
 * (the pressure gets the correction too), e.g. between forcing iterations;
 * the stage's own projection still follows the hook.  Fills the ghosts of
 * u* first (boundary conditions, halos) and after. */
void fluid_stage_project(fluid_t *f, double dt_stage);
void fluid_free(fluid_t *f);

/* Fill the ghost values of the velocity (walls, axis, periodic, halos). */
void fluid_apply_bc(fluid_t *f);
/* The time step allowed by the CFL (and Fourier, if explicit) limits. */
double fluid_stable_dt(const fluid_t *f);
/* Advance by dt (three RK3 stages, each projected); updates time, step, diag. */
void fluid_step(fluid_t *f, double dt);

/* ½ Σ |u|² V over the velocity unknowns (per unit density; axisymmetric:
 * the whole volume, 2π r dr dz). */
double fluid_kinetic_energy(const fluid_t *f);
/* max |D u| over the cells (1/s; D is the divergence of the projection). */
double fluid_max_divergence(const fluid_t *f);
/* Volume-weighted mean of velocity component c over the box (all ranks): along
 * a periodic direction, the flux per unit cross-section (superficial velocity). */
double fluid_mean_velocity(const fluid_t *f, int c);

/* The discrete operators, for the tests and for other modules.  u must have
 * valid ghosts (fluid_apply_bc); each writes the unknowns of out[c] only.
 *  fluid_advection: ∇·(u⊗u), energy-conserving divergence form;
 *  fluid_viscous:   ν∇²u including the wall velocities;
 *  fluid_divergence: D u at the cell centres. */
void fluid_advection(const fluid_t *f, double *const out[3]);
void fluid_viscous(const fluid_t *f, double *const out[3]);
/* (L u)_m of component c at the unknown m of local x plane i, the operator of
 * fluid_viscous at one node (moving walls and quadratic wall ghosts included;
 * without the factor ν); u with valid ghosts. */
double fluid_laplacian_at(const fluid_t *f, int c, const double *u, int i, long m);
void fluid_divergence(const fluid_t *f, double *div);
/* Volume of the control cell of the unknown (i,j,k) of component c (local i;
 * axisymmetric: per radian); the weight of the discrete energy Σ V u². */
double fluid_cell_volume(const fluid_t *f, int c, int i);

#endif
