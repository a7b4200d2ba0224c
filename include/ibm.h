/* ibm.h — immersed boundary for resolved spheres: the seed's volume-fraction
 * direct forcing (Izard 2014 §1.7 of the reference notes; Yuki et al. 2007,
 * Bigot et al. 2014), with the hydrodynamic force and torque from the
 * forcing integrals plus the rate of change of the fluid momentum inside the
 * particle (Uhlmann 2005; Kempe & Fröhlich 2012; Breugem 2012), and
 * rigid-body motion of free spheres integrated inside the fluid step.
 * docs/theory.md §6b gives the equations.
 *
 * The module owns a small set of spheres (ibm_sphere_t): free (moved by the
 * hydrodynamic force, the immersed weight (ρ_p − ρ)V_p g and nothing else),
 * fixed, prescribed (a constant velocity or a velocity history) and external
 * (moved by another module: the coupling with the DEM sets x, u, ω between
 * fluid steps, calls ibm_update_geometry(), and reads the hydrodynamic force
 * and torque of the step after fluid_step(); within the step an external
 * sphere's solid fraction stays where it was put, forced with U + ω × r).
 *
 * It works through the fluid's hooks (fluid.h): at every RK3 stage, before
 * the predictor sweep, the targets are set (and at the first stage the moves
 * made between steps applied); on each plane of the predicted velocity, as
 * the sweep writes it, that velocity is forced towards the rigid-body
 * velocity U + ω × r of each sphere,
 *     u ← u + β (U − u)      (f = β (U − u*)/Δt_k),
 * with α the smoothed solid fraction of decision 1 at each staggered node
 * and β = α (the seed's forcing) or its time-step independent form
 * β = α Δt_k/((1 − α)τ + α Δt_k) (forcing.c); with the Crank–Nicolson
 * viscous term either after the implicit solve (cn_forcing = after_solve) or,
 * from the explicit predictor, as a source term of it (predictor);
 * after the projection the momentum integrals are taken and the spheres are
 * moved.  Geometries: 3-D (spheres), 2-D (discs, per unit depth) and
 * axisymmetric (spheres on the axis, moving along it, integrals with 2πr).
 *
 * Parallel: every rank holds every sphere (replicated), forces the nodes of
 * its own slab, and the per-sphere integrals are summed over the ranks
 * (MPI_Allreduce in a fixed order: same rank count = bit-identical).
 *
 * Cost: each sphere touches only the nodes of its bounding box (radius plus
 * the band where 0 < α < 1): O(N_p (D/Δx)³) per stage, independent of the
 * grid size.  The node lists of all spheres are kept in storage order and
 * merged so that a node in several spheres' bands is forced once.  When
 * every sphere is fixed or external (nothing moves within the step), α is
 * built only when a sphere moved (ibm_update_geometry), the targets of the
 * forcing once per step, and the impulse of each sphere once per step
 * (docs/theory.md §6b).
 */
#ifndef IBMDEM_IBM_H
#define IBMDEM_IBM_H

#include "config.h"
#include "fluid.h"
#include "grid.h"

typedef enum { IBM_FREE = 0, IBM_FIXED = 1, IBM_PRESCRIBED = 2, IBM_EXTERNAL = 3 } ibm_kind_t;
typedef enum { IBM_FORCE_MOMENTUM = 0, IBM_FORCE_RIGID = 1 } ibm_force_model_t;

/* α is cut continuously to exactly 0 and 1 where the smoothed profile is
 * within this of them: α = clamp((α_tanh − ε)/(1 − 2ε), 0, 1), so each
 * sphere has a finite band |d| ≤ 2.26 Δx (ε = 1e-3) and no jump anywhere. */
#define IBM_ALPHA_CUT 1e-3

typedef struct {
    ibm_kind_t kind;
    double radius;
    double density;        /* ρ_p (free spheres; others: informative) */
    double x[3];           /* centre */
    double xa[3];          /* centre of the solid fraction α: x predicted explicitly at the end of the last
                            * stage (x + Δt_k u), which differs from x by O(Δt_k² du/dt); see forcing.c */
    double u[3];           /* translational velocity */
    double omega[3];       /* angular velocity */
    int history;           /* prescribed: index of a velocity history (ibm_add_history), −1: constant u, ω */
    /* Results of the last fluid step (averages over its three stages): the
     * hydrodynamic force and torque of the pressure relative to hydrostatic
     * and of the viscous stress.  The buoyancy −ρ V_p g is NOT included
     * (decision 7): a free sphere's total force is force + (ρ_p − ρ) V_p g. */
    double force[3], torque[3];
    /* State carried between stages (checkpointed): the velocity and
     * angular-velocity increments of the last stage (virtual-mass term). */
    double du_prev[3], dw_prev[3];
    /* Fixed and external spheres: where the velocity of the last fluid step
     * would have taken the centre (xa + Δt u; checkpointed): the part of
     * their next move that it predicts is counted in the force, the rest
     * is not (docs/theory.md §6b). */
    double xpred[3];
} ibm_sphere_t;

typedef struct {
    ibm_force_model_t force_model; /* momentum (default) or rigid (the seed's eq. 2.32) */
    double virtual_mass;  /* C_v of the added-mass stabilisation (momentum model) */
    int forcing_iterations; /* extra force + project passes per stage (0: one forcing) */
    double gravity[3];    /* acts on the particles only (pressure relative to hydrostatic) */
    double retraction;    /* α is taken for the radius R − retraction × h (h the cell size) */
    int radius_calibrated; /* IBM_RADIUS_*: 1 (calibrated): less the calibrated thickening of the band,
                            * ibm_calibrated_retraction(); 2 (gaps): the same fit with the local gap term,
                            * ibm_gap_retraction() and ibm_gap_thickening() */
    double forcing_time;  /* κ: partially covered nodes relax towards U with the time scale
                           * τ = κ h²/ν (0: the seed's u ← u + α (U − u) at every stage) */
    double band_width;    /* s ∈ (0, 1]: the smoothing length of α is s times the seed's
                           * (ibm_alpha()); 1: the seed's profile */
    int free_alpha_per_step; /* 1: a free sphere's α is held over the fluid step and moved
                              * between steps (docs/theory.md §6b); 0: moved after every stage */
    int forcing_predictor; /* Crank–Nicolson: 1: forcing of the explicit predictor, a source term of
                            * the implicit solve (FLUID_HOOK_PREDICTOR, docs/theory.md §4.6);
                            * 0: forcing of the solved velocity (after the solve) */
} ibm_params_t;

typedef struct ibm ibm_t;

struct ibm {
    fluid_t *f;
    const grid_t *g;
    ibm_params_t prm;
    int n;                 /* spheres */
    ibm_sphere_t *s;
    /* wall-clock seconds spent in the immersed boundary (α, forcing,
     * integrals, particle update) since creation */
    double wall_alpha, wall_forcing, wall_integrals;
    long nodes_forced;     /* node entries (sphere, node) of the last stage, this rank */
    long nodes_distinct;   /* ... the distinct nodes they cover (each forced once) */
    long nodes_shared;     /* ... of them at nodes that another sphere's band reaches too */
    void *priv;
};

/* ---- case file ------------------------------------------------------------- */

void ibm_register_keys(void);
/* Read [ibm] (options, sphere1..sphereN keys, spheres_file), build the
 * spheres and attach to the fluid (its stage hooks).  Stops with
 * file:line: ibm.key: reason on bad input. */
ibm_t *ibm_create_from_config(cfg_t *cfg, fluid_t *f);
/* The same with extra spheres appended after those of [ibm] (the DEM
 * particles of a coupled scene, kind external); [ibm] may then define none. */
ibm_t *ibm_create_from_config_with(cfg_t *cfg, fluid_t *f, const ibm_sphere_t *extra, int nextra);

/* ---- programmatic use (tests, coupling) -------------------------------------- */

/* Default parameters (momentum model, C_v = 0.1, the seed's forcing, no
 * iterations, no retraction, no gravity). */
ibm_params_t ibm_default_params(void);
/* Build for the fluid f with n spheres (copied) and install the fluid's
 * hooks (stage begin, plane, stage, stage end).  Dies on spheres that do not fit the
 * grid (e.g. off the axis of an axisymmetric grid). */
ibm_t *ibm_create(fluid_t *f, const ibm_params_t *prm, const ibm_sphere_t *s, int n);
/* Remove the hooks and free. */
void ibm_free(ibm_t *ibm);
/* A prescribed velocity history: n samples (t, u, v, w, ωx, ωy, ωz) per row,
 * linear between samples, constant outside.  Returns its index. */
int ibm_add_history(ibm_t *ibm, int n, const double *rows);
/* Velocity and angular velocity of a prescribed sphere at time t. */
void ibm_prescribed_velocity(const ibm_t *ibm, const ibm_sphere_t *s, double t, double u[3], double w[3]);

/* After changing spheres from outside (coupling): the solid fraction at
 * the current positions (xa = x).  When every sphere is fixed or external,
 * the move is applied at the start of the next fluid step (nothing is
 * rebuilt if no sphere moved), and each moved sphere carries the momentum
 * inside it over its jump as docs/theory.md §6b says (the part of the jump
 * that its last velocity predicts is counted in the next force).
 * Otherwise at once; free and prescribed spheres then take the momentum
 * inside them from the current fluid velocity.  Collective. */
void ibm_update_geometry(ibm_t *ibm);
/* The same from the stored xa (restart, rollback: the state as it was). */
void ibm_rebuild_geometry(ibm_t *ibm);

/* Volume, mass and moment of inertia of sphere p (2-D: a disc per unit
 * depth, πR², m R²/2). */
double ibm_volume(const ibm_t *ibm, int p);
double ibm_mass(const ibm_t *ibm, int p);
double ibm_inertia(const ibm_t *ibm, int p);

/* Largest time step for the spheres: a sphere surface point moves at most
 * cfl cells per step, and a sphere starting from rest under its immersed
 * weight moves at most one cell in the first steps. */
double ibm_stable_dt(const ibm_t *ibm, double cfl);

/* ---- solid fraction ----------------------------------------------------------- */

/* The smoothed solid fraction of decision 1 at signed distance d from the
 * surface (d < 0 inside), for outward normal n (unit) and cell size h:
 * α = ½[1 − tanh(d/(σλΔ))], λ = |n_x|+|n_y|+|n_z|, σ = 0.065(1 − λ²) + 0.39,
 * Δ = √2 h, then the continuous cut of IBM_ALPHA_CUT. */
double ibm_alpha(double d, const double n[3], double h);

/* The calibrated retraction (cells) of `radius_correction = calibrated`:
 * r(κ) − 0.282 h/R, r(κ) the first-order thickening of the band measured
 * for forcing_time κ ∈ [0.1, 0.3] (docs/theory.md §6b). */
double ibm_calibrated_retraction(double kappa, double h_over_R);

/* `radius_correction = gaps`: the uniform part of the retraction (cells),
 * r(κ) − 0.084 h/R, and the local thickening (length) of a sphere's forced
 * radius at a node whose distance to the nearest other sphere's surface is G
 * (clamped to [0, IBM_GAP_CUTOFF_D diameters]):
 *     min(0.45 h²/(G + h), IBM_GAP_MAX h)
 * (docs/theory.md §6b). */
#define IBM_GAP_MAX 0.4
#define IBM_GAP_CUTOFF_D 2.0
enum { IBM_RADIUS_NONE = 0, IBM_RADIUS_CALIBRATED = 1, IBM_RADIUS_GAPS = 2 };
double ibm_gap_retraction(double kappa, double h_over_R);
double ibm_gap_thickening(double G, double h);

/* The radius whose smoothed indicator is forced for a sphere of radius R at
 * cell size h: R − retraction h, less the calibrated retraction if chosen
 * (with `gaps`, the uniform part; the local thickening is added node by
 * node, alpha.c). */
double ibm_forced_radius(const ibm_t *ibm, double R, double h);
/* Half-width of the band where 0 < α < 1, in units of h. */
double ibm_band_halfwidth(void);

/* Total solid fraction min(1, Σ_p α_p) at the unknowns of velocity
 * component c (out is a grid field; only the unknowns are written, the
 * rest is zeroed), from the current node lists. */
void ibm_solid_fraction_face(const ibm_t *ibm, int c, double *out);
/* The same at the cell centres (pressure points), computed for output. */
void ibm_solid_fraction_cell(const ibm_t *ibm, double *out);

#endif
