/* dem.h — soft-sphere discrete element method (DEM): spheres with individual
 * radius and density, contact laws chosen in the case file, planar walls,
 * fixed particles, periodic directions, linked cells + Verlet lists, velocity
 * Verlet integration, packing preparation, output and diagnostics.
 *
 * Usable alone (a scene with [particles] and no [fluid] runs DEM only, see
 * dem_run_case) or sub-cycled inside a fluid step (dem_advance), with the
 * hydrodynamic force and torque of each particle given through
 * dem_ext_force()/dem_ext_torque() (held constant while sub-cycling).
 *
 * Particle order: particles are reordered by cell from time to time (at
 * neighbour-list rebuilds) to keep neighbours close in memory.  Any index
 * into the arrays below is valid only until the next dem_step/dem_advance;
 * dem_id() gives each particle's permanent identity (0..N-1 in the order of
 * creation).  The external force/torque arrays travel with the particles.
 *
 * Parallelism: replicated data.  Every rank holds every particle and
 * integrates all of them identically; the pair and wall forces are split
 * among the ranks by particle ranges and summed (MPI_Allreduce).  Same input
 * and same rank count give bit-identical results.
 */
#ifndef IBMDEM_DEM_H
#define IBMDEM_DEM_H

#include <hdf5.h>
#include <mpi.h>

#include "config.h"

typedef struct dem dem_t;

/* Status returned by dem_step/dem_advance.  On an error the state is that of
 * the end of the failing step; dem_error() gives the message. */
typedef enum {
    DEM_OK = 0,
    DEM_ERR_OVERLAP,    /* an overlap exceeded dem.max_overlap × the smaller diameter */
    DEM_ERR_LEFT_DOMAIN,/* a particle centre left the domain through a non-periodic face */
    DEM_ERR_NAN,        /* a non-finite position or velocity */
    DEM_ERR_TIMESTEP    /* dem.dt above t_c/20 for the contact time of the particles present */
} dem_status_t;

typedef struct {
    double time;
    long step;
    long n_particles, n_mobile;
    double ke_trans, ke_rot;   /* Σ ½ m v², Σ ½ I ω² of the mobile particles (J) */
    double ke_axis[3];         /* Σ ½ m v_a² of the mobile particles, per axis a (J) */
    double e_elastic;          /* energy stored in the contact springs (J) */
    long n_contacts;           /* particle–particle contacts (overlapping pairs) */
    long n_wall_contacts;
    double max_overlap;        /* max δ / (2 min(R_i, R_j)) over contacts of the last step */
    double momentum[3];        /* Σ m v of the mobile particles */
    double com[3];             /* centre of mass of the mobile particles */
    long rebuilds;             /* neighbour-list rebuilds so far */
    long contacts_started;     /* contacts (pairs and walls) started since the creation */
} dem_diag_t;

/* Case-file schema of [particles], [contact], [walls], [bed], [packing], [dem]. */
void dem_register_keys(void);

/* Build the DEM of a case file: domain ([domain] length/origin, periodic faces
 * from [boundary]), contact law, walls, particles (inserted, read from a
 * packing/checkpoint file or a LAMMPS data file), rough bed.  Does not run the
 * packing preparation (dem_prepare_packing does).  Stops with file:line:
 * section.key: reason on bad input. */
dem_t *dem_create_from_config(cfg_t *cfg, MPI_Comm comm);
void dem_free(dem_t *d);

/* Add a particle (before the first step, or between steps: the neighbour
 * lists are rebuilt).  fixed != 0: infinite mass, never moves (rough beds). */
int dem_add_particle(dem_t *d, const double x[3], const double v[3], double radius, double density, int fixed);
/* Set the angular velocity of the particle with the given id. */
void dem_set_omega(dem_t *d, long id, const double w[3]);

/* One time step of size dem_dt(). */
dem_status_t dem_step(dem_t *d);
/* A copy of the whole state (particles, forces, contact springs, pair and
 * wall lists, walls, time and step): dem_state_save fills `st` (NULL: a new
 * one, which dem_state_free releases), dem_state_restore brings it back
 * bit for bit (a diverged step undone: time.rollback). */
typedef struct dem_state dem_state_t;
dem_state_t *dem_state_save(const dem_t *d, dem_state_t *st);
void dem_state_restore(dem_t *d, const dem_state_t *st);
void dem_state_free(dem_state_t *st);
/* Advance to t_target with equal steps no longer than dem_dt() (sub-cycling
 * inside a fluid step).  External forces are held constant. */
dem_status_t dem_advance(dem_t *d, double t_target);
/* nsteps steps of size dem_dt(). */
dem_status_t dem_run_steps(dem_t *d, long nsteps);
const char *dem_error(const dem_t *d);

double dem_dt(const dem_t *d);
double dem_time(const dem_t *d);
double dem_contact_time(const dem_t *d);
void dem_set_time(dem_t *d, double t);
void dem_set_gravity(dem_t *d, const double g[3]);
void dem_get_gravity(const dem_t *d, double g[3]);
/* Local non-viscous damping coefficient α (dem.damping). */
void dem_set_damping(dem_t *d, double alpha);
/* The dry restitution coefficient e_dry (ε_max) of the contact law (0 if given by stiffness). */
double dem_dry_restitution(const dem_t *d);

/* Particle arrays (3-vectors are stored x,y,z per particle). */
int dem_count(const dem_t *d);
const double *dem_positions(const dem_t *d);
const double *dem_velocities(const dem_t *d);
const double *dem_omegas(const dem_t *d);
const double *dem_radii(const dem_t *d);
const long *dem_ids(const dem_t *d);
const unsigned char *dem_fixed(const dem_t *d);
/* The particle indices sorted by id (a new array of dem_count + 1 ints; free it): the order the
 * snapshots are written in, and the order in which sums over particles stay bit-identical when
 * the DEM reorders its storage (a restart). */
int *dem_id_order(const dem_t *d);
double dem_mass(const dem_t *d, int i); /* inertial mass (with any added mass); +inf for a fixed particle */
/* The particle's material density (its mass is density × volume without added mass). */
double dem_density(const dem_t *d, int i);
/* Added mass m_a of particle i (the resolved coupling's [coupling] added_mass, docs/theory.md §9.1):
 * from now on the particle's translational inertia is ρ_p V_p + m_a for every force (contacts,
 * lubrication, the external force and gravity; the caller scales the external force so that the
 * forces it does not want on m_a keep their acceleration); the rotational inertia is unchanged.
 * Sets the mass from the density, so calling it again with the same m_a changes nothing; call it
 * before the first step (contact forces already computed keep the mass they were computed with). */
void dem_set_added_mass(dem_t *d, int i, double added_mass);
/* Writable per-particle inputs, added to the contact forces and gravity at
 * every step (zeroed at creation). */
double *dem_ext_force(dem_t *d);
double *dem_ext_torque(dem_t *d);
/* Total contact force of each particle (pairs and walls) at the last step. */
const double *dem_contact_forces(const dem_t *d);
/* Particle i is in contact: it carries a nonzero contact force (pairs or
 * walls) at the last step; used by the coupling's freeze and measurements. */
static inline int dem_in_contact(const dem_t *d, int i)
{
    const double *f = dem_contact_forces(d) + 3 * i;
    return f[0] != 0 || f[1] != 0 || f[2] != 0;
}

/* Brenner lubrication (lubrication.c), set by [lubrication] in a case file. */
void dem_lubrication_register_keys(void);
/* Lubrication force on each particle in the last step (impulse / dt), 3n. */
const double *dem_lubrication_forces(const dem_t *d);
/* The drag closure of the fluid model drag (drag.c, [drag]). */
void dem_drag_register_keys(void);
/* The neighbourhoods dem_local_fraction read (its last argument, or NULL):
 * the other spheres in the ball about the particle of id p are id[k], with
 * weight w[k] (the lens volume of each inside the ball), for beg[p] <= k <
 * end[p].  Arrays grown as needed; dem_nbhood_free releases them. */
typedef struct dem_nbhood {
    long *beg, *end; /* by id */
    long *id;        /* the neighbours' ids */
    double *w;       /* their lens volumes */
    long nid, cap;   /* length of beg/end, of id/w */
} dem_nbhood_t;
void dem_nbhood_free(dem_nbhood_t *h);
/* The local solid fraction of every particle, by id (phi_by_id[id]): the
 * volume of the other spheres inside the ball of radius R about its centre
 * (exact lens volumes; fixed ones included) over the ball's volume inside the
 * box (caps beyond non-periodic faces removed) less its own; at most 0.95.
 * ug_by_id (or NULL): 3 per id, the volume-weighted mean velocity of the
 * other spheres in the ball (fixed ones at rest), fallback where it holds
 * none.  nbh (or NULL): the neighbourhoods read.  A cell list: O(N).
 * (drag.c) */
void dem_local_fraction(const dem_t *d, double R, double *phi_by_id, double *ug_by_id, const double fallback[3],
                        dem_nbhood_t *nbh);

/* rel times the mean diameter of the mobile particles, reduced where the
 * ball would not fit in half a periodic length (bit a of *clipped set). */
double dem_fraction_radius(const dem_t *d, double rel, int *clipped);
/* One more than the largest particle id (the size of arrays by id). */
long dem_id_bound(const dem_t *d);
/* Local solid fraction φ of each particle and its drag force in the last
 * step (3 per particle), indexed by particle id (dem_ids); NULL without the
 * drag. */
const double *dem_drag_fraction(const dem_t *d);
const double *dem_drag_forces(const dem_t *d);
/* The grid spacing of the resolved fluid (model = correction adds only what it
 * does not resolve, below a cut-off in grid cells); 0: no resolved fluid. */
void dem_lubrication_set_grid(dem_t *d, double h);
/* Largest damping rate (1/s) of the explicit tangential lubrication on a particle of radius R and mass m
 * (0 without it): the DEM step must stay well below its inverse. */
double dem_lubrication_tangential_rate(const dem_t *d, double R, double m);
/* Time until the first particle–particle or particle–wall contact (0: a
 * contact exists; INFINITY: nothing approaches).  Without lubrication at the
 * current velocities; lubricated pairs along their lubricated approach with
 * gravity and the held external forces (dem_lub_approach_time in
 * lubrication.c), except where a lower bound (the time without lubrication)
 * is beyond `horizon`: that bound is returned for them. */
double dem_time_to_contact(const dem_t *d, double horizon);
/* A function called after every DEM step (NULL: none), e.g. to record the
 * motion at the resolution of the sub-steps. */
void dem_set_step_observer(dem_t *d, void (*fn)(dem_t *d, void *ctx), void *ctx);
/* Velocity of particle i at the end of the current step (inside an observer
 * the stored velocities are half-step values). */
void dem_full_velocity(const dem_t *d, int i, double vel[3]);

/* Force statistics of a flow (the force balance of Izard 2014 eq. 4.16):
 * over the sub-steps since the last take, the sums of Σ |F_pair| and of the
 * number of contacts (particle pairs and walls), and of Σ |F_lub| and of
 * the number of pairs (and particle–wall gaps) under the normal
 * lubrication.  Collected once enabled; take is collective and resets. */
typedef struct {
    long steps;
    double contact_norm, contacts;
    double lub_norm, lubricated;
} dem_force_stats_t;
void dem_force_stats_enable(dem_t *d, int on);
void dem_force_stats_take(dem_t *d, dem_force_stats_t *out);
/* Wall time spent in the normal and tangential lubrication (s, this rank). */
double dem_lubrication_seconds(const dem_t *d);

/* Bytes allocated by the DEM per particle (particles, lists, cells, walls). */
double dem_memory_per_particle(const dem_t *d);

/* Time spent in the parts of a step (rank 0 prints). */
void dem_print_timers(const dem_t *d);

/* Walls */
int dem_wall_count(const dem_t *d);
/* Force exerted BY the particles ON wall w at the last step (N). */
void dem_wall_force(const dem_t *d, int w, double f[3]);
int dem_wall_active(const dem_t *d, int w);
const char *dem_wall_name(const dem_t *d, int w);
/* Index of the wall with this name (x_lo ... z_hi, wall1 ...), -1: none. */
int dem_wall_find(const dem_t *d, const char *name);
/* Smallest gap between particle i and the active walls (INFINITY: none). */
double dem_wall_gap_min(const dem_t *d, int i);
/* A point of wall w (it moves with the wall). */
void dem_wall_position(const dem_t *d, int w, double p[3]);
/* Move wall w (between steps) so that its plane passes through p. */
void dem_wall_set_point(dem_t *d, int w, const double p[3]);
/* Make wall w a piston: pushed along its normal (towards the particles) by
 * the force `push` (N) and moved by Newton's law with its mass (kg) and the
 * particles' force ([walls] wall<N>_force / wall<N>_mass); mass 0: back to
 * its prescribed velocity. */
void dem_wall_set_load(dem_t *d, int w, double push, double mass);

/* Diagnostics (collective).  dem_diag_light skips the elastic energy (a pass
 * over the contacts). */
void dem_diag(dem_t *d, dem_diag_t *out);
void dem_diag_light(dem_t *d, dem_diag_t *out);

/* Packing preparation as configured in [packing]: settle under gravity until
 * the kinetic energy per particle drops below the rest criterion (dense:
 * frictionless settling; loose: high friction), then restore the contact
 * parameters and reset time to 0.  Returns 0 at rest, 1 if the time limit was
 * reached (a warning is printed), or a dem_status_t error + 10. */
int dem_prepare_packing(dem_t *d, cfg_t *cfg, const char *outdir);

/* Output */
/* HDF5 snapshot <dir>/particles_<index>.h5 and its entry in
 * <dir>/particles.xdmf (the XDMF file is rewritten, so it is always valid). */
void dem_write_snapshot(dem_t *d, const char *dir, int index);
/* Full state (particles, contact and wall histories, time) to HDF5; a packing
 * file is a checkpoint.  dem_read_checkpoint replaces the particles. */
void dem_write_checkpoint(dem_t *d, const char *path);
void dem_read_checkpoint(dem_t *d, const char *path);
/* The particles of a packing, snapshot or checkpoint as the start of a new run ([particles]
 * source = file): as dem_read_checkpoint, but the walls stay where the case put them (point,
 * activity, velocity, load); where the file has them elsewhere, the lists are built for the
 * case's walls and the file's wall springs are dropped. */
void dem_read_particles_file(dem_t *d, const char *path);
/* The same into / from an open HDF5 file or group (a part of a run checkpoint). */
void dem_checkpoint_write_loc(dem_t *d, hid_t loc);
void dem_checkpoint_read_loc(dem_t *d, hid_t loc, const char *path);
/* After a restart: list the snapshots 0..first-1 already in dir in the XDMF index. */
void dem_snapshots_resume(dem_t *d, const char *dir, int first);
/* Number of snapshots written (or listed) so far. */
int dem_snapshot_count(const dem_t *d);
/* LAMMPS/LIGGGHTS data file (atom_style sphere: id type diameter density x y z). */
void dem_write_lammps_data(dem_t *d, const char *path);

/* Rate of change of the grains for time.steady_tol: rms velocity / mean
 * diameter of the mobile particles (1/s), INFINITY before time `after`. */
double dem_rest_rate(dem_t *d, double after);

/* Run a DEM-only case without the run driver (ibmdem run does the same
 * through src/core/sim_dem.c): preparation (if [packing] prepare), then the
 * run to time.t_end (or until the grains' rate of change dem_rest_rate falls
 * below time.steady_tol) with snapshots every output.fields_every, the time
 * series dem_series.csv and the checks; writes its outputs in outdir.  Returns 0 on success, non-zero after a diagnostic stopped the run
 * (a checkpoint was written). */
int dem_run_case(cfg_t *cfg, const char *outdir);

#endif
