/* coupling.h — the resolved fluid–particle coupling (immersed boundary ↔
 * DEM, Izard 2014 §1.8 of the reference notes) and the restitution
 * measurements of the bouncing cases (§2.6, §2.9; decision 8).
 *
 * One fluid step (docs/theory.md §9):
 *   1. the fluid advances Δt_f with every particle as an immersed sphere held
 *      at its position and forced to its rigid-body velocity (ibm.h, kind
 *      external), which gives the hydrodynamic force F_h and torque T_h
 *      (averages over the three RK stages);
 *   2. the DEM advances the same Δt_f in M = ⌈Δt_f/Δt_s⌉ equal sub-steps
 *      (Δt_s = t_c/n_c, set by the contact time, not by the fluid step), with
 *      F_h − ρV_p g and T_h held constant and the contact and lubrication
 *      forces evaluated at every sub-step;
 *   3. the new positions and velocities go back to the immersed boundary,
 *      which rebuilds its solid fraction for the next step.
 *
 * The restitution tracker follows one particle against a wall (or a pair of
 * particles) through its first collision, from the fluid-step samples and
 * the DEM sub-steps (restitution.c).
 */
#ifndef IBMDEM_COUPLING_H
#define IBMDEM_COUPLING_H

#include "dem.h"
#include "ibm.h"

/* ---- exchange (ibm_dem.c) ---------------------------------------------------- */

/* The immersed spheres of the DEM particles: kind external, in the order of
 * the particles' ids (sphere p is the particle of id p).  *n gets the count;
 * the array is malloc'd. */
ibm_sphere_t *coupling_spheres_of_particles(const dem_t *d, int *n);
/* The fluid frozen during collisions (docs/theory.md §9.1): while a
 * particle is in contact at the start of a fluid step (for at most
 * hold_time of contact), the DEM keeps the hydrodynamic force and torque of
 * the last step before the contact, and the difference is applied, as an
 * impulse spread over one step, once the contact is over.  Matters only
 * when the fluid step is shorter than the contact. */
typedef struct {
    int n;
    double hold_time;
    double *F0;     /* 6n: force and torque of the last step before the contact (by sphere) */
    double *J;      /* 6n: impulse deferred while frozen */
    double *held;   /* n: contact time spent frozen */
} coupling_freeze_t;
void coupling_freeze_init(coupling_freeze_t *fz, int n, double hold_time);
void coupling_freeze_free(coupling_freeze_t *fz);
/* The added-mass-consistent collision ([coupling] added_mass = consistent,
 * docs/theory.md §9.1): inside the DEM sub-steps the contact and lubrication
 * forces act on m* = m_p + C_M ρ V_p (Izard eqs. 3.24, 3.26) while the held
 * hydrodynamic force, the buoyancy and the weight keep their acceleration
 * (F/m_p); the velocity change the contact and lubrication forces produced
 * in a step, ΔU_c, makes the fluid react in the next step by ≈ −C_M ρ V_p
 * ΔU_c (its added mass, already moved by the DEM), so C_M ρ V_p ΔU_c/Δt_f is
 * added back to the next held force: over the two steps the particle gets
 * the same momentum as without the option, the fluid's reaction is not
 * counted twice. */
typedef struct {
    int n;
    double cm;      /* C_M */
    double *dU;     /* 3n: ΔU_c of the last step (by sphere), added back to the next held force */
    double *U0;     /* 3n: velocity at the start of the step */
    double *slow;   /* 3n: velocity change the held force, buoyancy and weight give over the step */
} coupling_added_mass_t;
void coupling_added_mass_init(coupling_added_mass_t *am, int n, double cm);
void coupling_added_mass_free(coupling_added_mass_t *am);
/* The particles' inertia m_p + C_M ρ V_p in the DEM (idempotent: at setup and after a restart). */
void coupling_added_mass_apply(const coupling_added_mass_t *am, dem_t *d, double rho_fluid);
/* After the DEM advanced a fluid step: ΔU_c of every particle. */
void coupling_added_mass_after_step(coupling_added_mass_t *am, const dem_t *d);
/* Step 1 → 2: hand the hydrodynamic force and torque of the last fluid step
 * (of length dt), with the buoyancy −ρ V_p g, to the DEM as its external
 * force and torque, through the freeze fz (NULL: none) and with the
 * added-mass correction am (NULL: none). */
void coupling_forces_to_dem(const ibm_t *ibm, dem_t *d, double rho_fluid, const double gravity[3],
                            coupling_freeze_t *fz, coupling_added_mass_t *am, double dt);
/* The hydrodynamic force linearised in the particle's velocity inside the
 * DEM sub-steps ([coupling] implicit_drag = K, docs/theory.md §9.1): the held
 * force and torque F_h, T_h were measured with the particle moving at U_n,
 * ω_n (its velocity at the start of the fluid step); over the sub-steps the
 * DEM adds −c (U − U_n) and −c_r (ω − ω_n), c = K 3πηD, c_r = K πηD³, so the
 * drag responds to the velocity the particle gains within the step instead of
 * one step later.  The terms vanish when the velocity does not change (steady
 * states unchanged).  They are updated in chunks of DEM steps short against
 * the relaxation times m/c and I/c_r (at most 5 % of them).
 * Hindered ([coupling] implicit_drag_hindrance = richardson_zaki): the force
 * coefficient of each particle is c = 3πηD max(K, (1 − φ)^−4.65), φ its local
 * solid fraction (dem_local_fraction, a ball of 1.5 mean diameters; at most 0.64) at the
 * start of the fluid step: in a dense bed the resistance of a grain that
 * moves against its neighbours is the hindered drag, tens of times the
 * isolated sphere's.  Relative (= relative): the hindered coefficient c_h acts
 * on the particle's velocity change less the lens-volume-weighted mean change
 * ΔŪ of the other spheres in the ball (fixed ones at rest), K on the rest:
 *     F = −c_K ΔU − (c_h − c_K)(ΔU − ΔŪ),   ΔU = U − U_n,
 * along the periodic directions, where a neighbourhood that accelerates
 * together carries its pore fluid along (the bed's triggering); along a
 * direction bounded by walls the volume flux of the mixture through a
 * cross-section vanishes, a neighbourhood that moves together pushes the
 * fluid through its pores, and the whole change meets c_h as with
 * richardson_zaki (bounded[], coupling_drag_set_bounded). */
typedef enum { DRAG_HINDRANCE_NONE, DRAG_HINDRANCE_RICHARDSON_ZAKI, DRAG_HINDRANCE_RELATIVE } drag_hindrance_t;
typedef struct {
    int n;          /* spheres (0: off) */
    double k;       /* K */
    double mu;      /* dynamic viscosity η of the fluid */
    double *held;   /* 6n: the held force and torque of this step (by sphere) */
    long chunks;    /* DEM chunks done (statistics) */
    int hindered;   /* implicit_drag_hindrance (drag_hindrance_t, the order of the key's choices) */
    dem_nbhood_t nbh; /* relative: the neighbourhoods of this step */
    double *du;     /* relative: by id, 3 per particle, U − U_n at the start of a chunk (scratch) */
    unsigned char bounded[3]; /* relative: the directions bounded by walls (not periodic); all by default */
    double *factor; /* by id: the force coefficient over 3πηD of this step */
    double *phi;    /* by id: the local solid fraction (scratch) */
    long nid;       /* length of factor and phi */
    double phi_mean, factor_max; /* of the mobile particles, last step (diagnostics) */
} coupling_drag_t;
/* The hindered force coefficient over 3πηD: max(K, (1 − φ)^−n), n = 4.65, φ at most 0.64. */
double coupling_drag_hindrance(double k, double phi);
void coupling_drag_init(coupling_drag_t *dr, int n, double k, double mu, int hindered);
void coupling_drag_free(coupling_drag_t *dr);
/* relative: which directions are bounded (the fluid's non-periodic ones). */
void coupling_drag_set_bounded(coupling_drag_t *dr, const int periodic[3]);
/* Advance the DEM by dt after coupling_forces_to_dem (its external force and
 * torque are the held ones), the linear terms about the spheres' velocities
 * u, ω (the fluid step's) updated between chunks; am (or NULL): the
 * velocity change the terms give is added to am->slow (not a collision's). */
dem_status_t coupling_drag_advance(coupling_drag_t *dr, const ibm_t *ibm, dem_t *d, coupling_added_mass_t *am,
                                   double dt);
/* Step 2 → 3: positions and velocities of the particles to the spheres, and
 * the solid fraction rebuilt (collective). */
void coupling_motion_to_ibm(const dem_t *d, ibm_t *ibm);

/* ---- dimensionless numbers (numbers.c) ----------------------------------------- */

typedef struct {
    double D, ratio;     /* diameter, ρ_p/ρ */
    double Ga;           /* Galileo number √((ρ_p/ρ − 1) g D³)/ν (0 when the particle does not sink) */
    double V_T, Re_T;    /* Schiller–Naumann terminal velocity and its Reynolds number */
    double St_T;         /* (ρ_p + ρ/2) V_T D/(9μ), the Stokes number of a bounce at V_T (Izard eq. 3.19) */
    double D_over_h;     /* resolution (0: no grid) */
    double tc_g, tc_VT;  /* contact time t_c √(g/D) and t_c V_T/D */
} coupling_numbers_t;

/* The numbers of a particle of diameter D and density rho_p in a fluid (rho_f, mu) under gravity
 * |g|, grid spacing h (0: none) and contact time tc. */
void coupling_numbers(double D, double rho_p, double rho_f, double mu, double g, double h, double tc,
                      coupling_numbers_t *n);

/* ---- restitution (restitution.c) ---------------------------------------------- */

typedef enum { RESTITUTION_OFF = 0, RESTITUTION_WALL = 1, RESTITUTION_PAIR = 2 } restitution_mode_t;

typedef struct {
    restitution_mode_t mode;
    double axis[3];      /* wall: unit vector towards the wall (along gravity) */
    double rho_f, mu;    /* fluid density and viscosity (St, Re); mu = 0: dry */
    double rho_p, D;     /* particle density and diameter (the particle of id 0) */
    double e_dry;        /* ε_max of the contact law */
    /* state */
    int phase;           /* 0 approach, 1 first contact, 2 after it, 3 a second contact seen */
    double u_last;       /* approach speed at the last sub-step */
    double VT, VC, VR;   /* approach speed before the contact (max over the fluid steps), at the
                          * last fluid step before the contact, largest rebound speed after it (fluid steps) */
    double VC_onset;     /* approach speed at the last sub-step before the contact starts */
    double VR_release;   /* rebound speed when the contact ends (sub-step) */
    double t_contact, t_release;
    double lub_impulse;  /* lubrication impulse on particle 0 against its approach direction, last fluid step */
    /* the rebound as an experiment records it (the trajectory of the gap, sampled at every sub-step) */
    double fit_window;   /* [coupling] fit_window; 0: 0.2 D/V_T */
    double window;       /* the window used (set at the contact) */
    long ntraj, captraj; /* samples (t, gap) of the approach (gap < 0.3 D) and of the rebound window */
    double *traj;
    double V_in, V_out;  /* speeds fitted over the window before the contact and after the release */
    double apex, t_apex; /* largest gap after the release (wall), and when */
    /* oblique impacts (wall): the velocity of the contact point, v + ω × R n (n towards the wall), in the
     * plane of the wall, at the sub-step before the contact and when it ends, and the centre's */
    double cp_last[3], cp_in[3], cp_out[3], vt_out[3], vn_out;
} restitution_t;

/* axis: wall mode: unit vector from the particle towards the wall. */
void restitution_init(restitution_t *r, restitution_mode_t mode, const double axis[3], double rho_f, double mu,
                      double rho_p, double D, double e_dry);
/* After every DEM sub-step (an observer, dem_set_step_observer). */
void restitution_substep(restitution_t *r, dem_t *d);
/* After every fluid step (or driver step of a dry run). */
void restitution_sample(restitution_t *r, dem_t *d);
/* Approach speed of the tracked motion now (wall: v·axis; pair: (v₀ − v₁)·n₀₁). */
double restitution_approach_speed(const restitution_t *r, dem_t *d, int full_step);
/* Results: ε = V_R/V_T, St = (ρ_p + ρ/2) V_T D/(9μ) and Re_p = ρ V_T D/μ
 * (wall, eq. 3.19), or ε_B and St_B = ρ_p U D/(9μ), Re = ρ U D/μ (pair,
 * eq. 3.34–3.35, no added mass). */
double restitution_epsilon(const restitution_t *r);
/* Oblique impacts against a wall (Joseph & Hunt 2004, at the contact point): Ψ_in = |u_t,in|/u_n,in,
 * Ψ_out = u_t,out·t̂_in/u_n,in (t̂_in the direction of u_t,in), β = −Ψ_out/Ψ_in, the effective friction
 * μ_f = 2(1 + β)Ψ_in/(7(1 + e)), and the rebound angle of the centre's velocity from the wall normal
 * (degrees); u_t,in and u_t,out are the contact point's tangential velocities at the sub-steps before
 * and after the contact, u_n,in = V_in and e = V_out/V_in the trajectory fits (without them: the
 * sub-step speeds V_C_onset and V_release/V_C_onset); 0 when the impact is normal or not measured. */
void restitution_oblique(const restitution_t *r, double *psi_in, double *psi_out, double *beta, double *mu_f,
                         double *angle_out);
/* The experiment-like ε = V_out/V_in of the trajectory fits (0 before they are made). */
double restitution_epsilon_fit(const restitution_t *r);
void restitution_free(restitution_t *r);
/* The rebound's fits are made (the window after the release has passed, or a second contact came first). */
int restitution_measured(const restitution_t *r);
double restitution_stokes(const restitution_t *r);
double restitution_reynolds(const restitution_t *r);

#endif
