/* dem_private.h — the DEM data structure and the contact-law interface.
 *
 * Shared by the files of src/dem only.  A new contact law is a new file
 * src/dem/contact_<name>.c defining a dem_contact_law_t (see
 * contact_linear.c) and one line in contact_registry.c.
 */
#ifndef IBMDEM_DEM_PRIVATE_H
#define IBMDEM_DEM_PRIVATE_H

#include <math.h>
#include <stdint.h>

#include "dem.h"

#define DEM_MAX_WALLS 16
#define DEM_MAX_USER_WALLS 6
#define DEM_MAX_THREADS 64
/* bytes of the pair loop's work space: 128 contacts × (3 ints + 38 doubles) */
#define DEM_KERNEL_BLOCK_BYTES (128 * (3 * sizeof(int) + 40 * sizeof(double)))

typedef struct {
    char name[24];
    double p[3];     /* a point of the plane */
    double n[3];     /* unit normal pointing to the particles' side */
    double vel[3];   /* velocity (translation) */
    double remove_time; /* the wall disappears at this time (INFINITY: never) */
    /* load-controlled wall (a piston): pushed along n by `push` (N) and moved
     * by Newton's law with its mass (kg) against the particles' force; mass 0:
     * the wall follows its prescribed velocity */
    double push, mass;
    int active;
    double moved;    /* distance moved since the last list build */
    /* contact list: particles within r + skin at the last build */
    int nlist, cap;
    int *idx;
    unsigned char *on; /* 1 while in contact (overlap) */
    double *hist;    /* tangential spring ξ (3 per entry) */
    double force[3]; /* force exerted by the particles on the wall, last step */
} dem_wall_t;

/* Lubrication (lubrication.c): Brenner's normal force with an effective
 * roughness (Izard eq. 2.36/3.18, decision 5) and, with model = correction,
 * the Goldman–Cox–Brenner tangential and rotational terms; between particles
 * and between a particle and a wall, active for 0 < δ_n below a cut-off; while
 * they overlap off, or with overlap = saturated at its δ_n = 0 value (eq. 3.26).
 * model = brenner: the whole force up to Δ_lub = range × R (the seed's form);
 * model = correction: only what the fluid model does not resolve — below
 * cutoff × h (h the grid spacing of the resolved fluid, set by the coupling),
 * each term less its value at the cut-off; without a resolved fluid (h = 0)
 * the whole force up to range × R. */
typedef enum { LUB_NONE = 0, LUB_BRENNER = 1, LUB_CORRECTION = 2 } dem_lub_model_t;
typedef struct {
    int on;
    int model;           /* dem_lub_model_t */
    int walls;           /* also between a particle and a wall */
    int subtract;        /* subtract the force at δ_n = Δ_lub (the part the grid resolves) */
    int overlap;         /* [lubrication] overlap = saturated: the δ_n = 0 force while overlapping */
    int tangential;      /* model = correction: the tangential and rotational terms too */
    double viscosity;    /* η_f (Pa s) */
    double roughness;    /* η_e / R */
    double range;        /* Δ_lub / R (brenner; correction without a resolved fluid) */
    double cutoff;       /* correction: normal cut-off in grid cells */
    double tcutoff;      /* correction: tangential cut-off in grid cells */
    double h;            /* grid spacing of the resolved fluid (0: none) */
    double reach;        /* largest cut-off among the particles (m): margin of the lists */
} dem_lub_t;

/* The drag closure of the reduced fluid model `drag` (drag.c). */
typedef struct {
    int on;
    int closure;         /* 0 stokes, 1 richardson_zaki */
    double n_rz;         /* Richardson–Zaki exponent */
    double mu, rho_f;    /* viscosity, fluid density (buoyancy) */
    double uf[3];        /* prescribed mean fluid velocity */
    int uf_grains;       /* fluid_velocity_from = grains: U_f of each grain is its neighbours' mean velocity */
    double *ug;          /* ... by particle id (3 per id), held with φ */
    double radius_rel;   /* sampling radius of φ in mean diameters */
    double R;            /* sampling radius (m), set at the first update */
    int every;           /* DEM steps between updates of φ */
    int rotation;        /* Stokes torque */
    double *phi;         /* local solid fraction, by particle id */
    double *fd;          /* drag force of the last step, by particle id (3 per id) */
    long nphi;           /* ids covered by phi and fd */
    long phi_step;       /* step of the last update of phi (−1: none) */
} dem_drag_t;

/* Called after every DEM step (dem_set_step_observer). */
typedef void (*dem_step_observer_t)(dem_t *d, void *ctx);

/* Contact parameters: the common part (tangential spring, friction, rolling)
 * and the fields of each law.  Laws read what they need in setup(). */
typedef struct {
    int clip;            /* normal force clipped at zero (decision 3) */
    double kt_ratio;     /* linear: k_t = kt_ratio k_n */
    double mu, mu_wall;  /* Coulomb friction: particle–particle, particle–wall */
    double mu_roll;      /* rolling resistance coefficient (constant torque), 0 = off */
    /* linear spring–dashpot: F_n = (kn_abs + m* kn_rel) δ + m* gn_rel δ̇ */
    double kn_abs, kn_rel, gn_rel;
    int kink_energy;     /* linear: onset/separation weights of the spring (theory §7.7), where
                            the force has its kink at δ = 0 (unclipped or undamped) */
    double restitution, tc_given;
    /* Hertz–Mindlin */
    double E_star, G_star, beta_damp, v_ref;
    char summary[256]; /* one line describing the law and its constants */
} dem_contact_prm_t;

typedef struct dem_contact_law {
    const char *name;
    /* Read the law's keys from [contact] into d->cp (stops on bad input). */
    void (*setup)(dem_t *d, cfg_t *cfg);
    /* Shortest contact duration among the particles present (for dt). */
    double (*contact_time)(const dem_t *d);
    /* Forces and torques of the rank's share of the particle pairs. */
    void (*pair_forces)(dem_t *d);
    /* Forces and torques of the rank's share of one wall's contacts. */
    void (*wall_forces)(dem_t *d, dem_wall_t *w);
    /* Elastic energy of one contact (normal + tangential springs). */
    double (*energy)(const dem_contact_prm_t *cp, double delta, double meff, double reff, double xi2);
} dem_contact_law_t;

const dem_contact_law_t *dem_contact_law_find(const char *name);
/* The "a|b|c" list of the registered laws (schema choices). */
extern const char dem_contact_law_choices[];

struct dem {
    MPI_Comm comm;
    int rank, nranks;
    int parallel_mode;   /* 0 auto, 1 replicated, 2 split */
    int split;           /* 1: the pairs are shared among the ranks, forces summed */
    int split_decided;

    /* particles: structure of arrays (3-vectors stored as x,y,z) */
    int n, cap;
    double *x, *v, *w;   /* position, velocity, angular velocity */
    double *f, *t;       /* force and torque (one block of 6n: f then t) */
    double *dv, *dw;     /* dt/2 × acceleration of the previous step (predictor) */
    double *fext, *text; /* external force and torque (immersed boundary) */
    double *fc;          /* contact force of the last step (diagnostics), 3n */
    double *flub;        /* lubrication force of the last step (impulse / dt), 3n */
    double *r, *invm, *invI, *rho;
    long *id;
    unsigned char *fixed;
    long next_id;
    int pending_kick;    /* 1: v, w are half-step values; the final kick is pending */

    /* domain */
    double lo[3], hi[3], L[3];
    int periodic[3];
    int any_periodic;
    int axisymmetric;    /* the fluid is axisymmetric: spheres on the y axis (x = z = 0) */

    /* walls */
    int nwall;
    dem_wall_t wall[DEM_MAX_WALLS];

    /* lubrication, drag */
    dem_lub_t lub;
    dem_drag_t drag;
    dem_step_observer_t observer;
    void *observer_ctx;

    /* contact law */
    const dem_contact_law_t *law;
    dem_contact_prm_t cp;

    /* time integration */
    double dt, dt_user, tc;
    int n_c;
    double time;
    long step;
    double gravity[3];
    double max_overlap_allowed;
    double damping;      /* local non-viscous damping coefficient α (Cundall): F − α|F| sgn(v), 0: off */
    int ready;           /* lists built and forces of the current state computed */
    int hist_update;     /* 0 while computing the forces of the initial state */
    int use_ext;         /* the external force/torque arrays were handed out */

    /* neighbour search: linked cells + Verlet list with skin */
    double skin;         /* absolute skin (m) */
    double skin_rel;     /* skin as a fraction of the largest diameter */
    double skin_lub_added; /* part of skin added for the lubrication range (lub.reach) */
    double rmax;
    int nc[3];
    double csize[3];
    long ncell;
    int *cell_start;     /* ncell + 1 */
    int *cell_of;        /* cell of each particle at the last build */
    int *perm;           /* work: new → old index */
    double disp_bound;   /* upper bound of any particle's displacement since the build */
    int sort_every, builds_since_sort;
    long rebuilds;
    /* half neighbour list in CSR form */
    int *nb_start;       /* n + 1 */
    int *nb_j;
    unsigned char *nb_img; /* periodic image of j (index into shift), only if any_periodic */
    unsigned char *nb_on;  /* 1 while the pair overlaps */
    double *nb_hist;       /* tangential spring ξ of the pair, 3 per entry */
    long nb_n, nb_cap;
    int nb_n_rows;       /* particles (rows) covered by the list */
    double shift[27][3];
    void *kernel_block;  /* work space of the pair loop (dem_kernel.inc), one per thread: */
    void *tblock[DEM_MAX_THREADS];
    /* threads (OpenMP, [dem] threads): rows [trow[t], trow[t+1]) of the
     * rank's share; force and torque arrays of threads 1.. (6n each) */
    int nthreads;
    int trow[DEM_MAX_THREADS + 1];
    double *tforce[DEM_MAX_THREADS];
    int tforce_cap;
    /* the rank's share: rows [row_lo, row_hi) of the list */
    int row_lo, row_hi;

    /* diagnostics of the last step */
    long n_contacts, n_wall_contacts;
    long n_starts;       /* contacts started on this rank since the creation (pairs and walls) */
    double max_overlap;
    char errmsg[512];
    /* snapshots written (for the XDMF index) */
    int nsnap, snap_cap;
    double *snap_t;
    long *snap_n;
    int *snap_index;
    /* force statistics since the last dem_force_stats_take (on this rank; the
     * contacts are reduced over the ranks of a split run when taken) */
    struct {
        int on;
        long steps;
        double contact_norm, contacts; /* Σ |F| and count of the contacts (pairs and walls) */
        double lub_norm, lubricated;   /* the same for the normal lubrication (every rank computes all) */
    } fstat;
    /* work space of the lubrication sweep (lubrication.c), lub_work_cap entries */
    struct lub_work *lub_work;
    long lub_work_cap;
    /* timers */
    double t_pair, t_wall, t_build, t_integ, t_comm, t_lub;
};

/* ---- neighbour search (dem_neigh.c) ---- */
/* Rebuild the cell grid, reorder particles (if due), rebuild the pair and
 * wall lists keeping the contact histories.  Returns DEM_OK or
 * DEM_ERR_LEFT_DOMAIN / DEM_ERR_NAN (message in d->errmsg). */
dem_status_t dem_neigh_build(dem_t *d);
void dem_neigh_free(dem_t *d);
/* Split runs: every rank gets the springs of every pair and wall contact. */
void dem_neigh_gather(dem_t *d);
/* The rank's share of the rows after a build. */
void dem_neigh_partition(dem_t *d);

/* ---- internal helpers (dem.c; dem_elastic_energy: dem_diag.c) ---- */
void dem_grow(dem_t *d, int need);
dem_status_t dem_set_dt(dem_t *d);
/* Checks that need the particles (periodic lengths); sets the skin and image shifts. */
void dem_check_scene(dem_t *d);
void dem_decide_split(dem_t *d);
/* Mass of the lightest mobile particle (INFINITY if none); smallest radius in *rmin. */
double dem_lightest_mass(const dem_t *d, double *rmin);
void dem_compute_forces(dem_t *d);
/* Finish a pending half kick so that v, w are full-step values. */
void dem_sync_velocities(dem_t *d);
double dem_elastic_energy(const dem_t *d);
void dem_config_particles(dem_t *d, cfg_t *cfg);
/* The particles added from now on come from section.key (dem_check.c);
 * reset before a scene is built. */
void dem_origin_reset(void);
void dem_origin_mark(const dem_t *d, const char *section, const char *key);
/* Stop with file:line: section.key: reason on a starting geometry that cannot be (dem_check.c). */
void dem_check_geometry(dem_t *d, cfg_t *cfg);
void dem_config_bed(dem_t *d, cfg_t *cfg);
void dem_freeze_below(dem_t *d, cfg_t *cfg);
int dem_insert_random(dem_t *d, const double lo[3], const double hi[3], long count, double phi, double rmean,
                      double poly, double rho, const double v0[3], double vspread, unsigned long seed,
                      const char **why);
/* Read a LAMMPS data file; a bad file is an input error of particles.file
 * (cfg), or fatal with cfg = NULL. */
void dem_read_lammps_data(dem_t *d, cfg_t *cfg, const char *path, double box_lo[3], double box_hi[3], int read_box);
void dem_add_wall(dem_t *d, const char *name, const double p[3], const double n[3], const double vel[3],
                  double remove_time);

/* ---- lubrication (lubrication.c) ---- */
/* Read [lubrication] (viscosity default: ρν of [fluid]). */
void dem_lubrication_config(dem_t *d, cfg_t *cfg);
/* Apply the lubrication impulses of the coming drift of length dt to the
 * half-step velocities (implicit in the gap, see lubrication.c). */
void dem_lubrication_impulses(dem_t *d, double dt);
/* Frees the work space of the lubrication sweep. */
void dem_lubrication_free(dem_t *d);
/* Bytes of the work space of the lubrication sweep per entry (d->lub_work_cap entries). */
double dem_lubrication_work_bytes(void);
/* Time for a lone pair (radius R for η_e and Δ_lub, R_eff, mass m) to close
 * gap0 from approach speed u0 with approach acceleration a under the
 * lubrication (INFINITY: it stops first). */
double dem_lub_approach_time(const dem_t *d, double R, double reff, double m, double gap0, double u0, double a);
/* Largest gap at which a particle of radius rmax is lubricated (the margin the lists need). */
double dem_lub_reach(const dem_lub_t *L, double rmax);

/* ---- drag closure (drag.c) ---- */
/* Read [drag] when the fluid model is drag (off otherwise). */
void dem_drag_config(dem_t *d, cfg_t *cfg);
void dem_drag_free(dem_t *d);
/* The drag and buoyancy of the coming drift of length dt on the half-step
 * velocities (implicit), after updating the local solid fractions if due. */
void dem_drag_impulses(dem_t *d, double dt);

/* ---- pair and wall geometry for the passes outside the force kernel ---- */
/* Unit normal n from particle i to the partner of its list entry e (the
 * periodic image included); returns the distance of the centres. */
static inline double dem_pair_normal(const dem_t *d, int i, long e, double n[3])
{
    const int j = d->nb_j[e];
    const double *sh = d->any_periodic ? d->shift[d->nb_img[e]] : d->shift[13];
    double dist2 = 0;
    for (int a = 0; a < 3; a++) {
        n[a] = d->x[3 * j + a] + sh[a] - d->x[3 * i + a];
        dist2 += n[a] * n[a];
    }
    const double dist = sqrt(dist2);
    for (int a = 0; a < 3; a++) n[a] /= dist;
    return dist;
}

/* Approach speed (v_i − v_j)·n of particles i and j along the unit normal n from i to j. */
static inline double dem_pair_approach(const dem_t *d, int i, int j, const double n[3])
{
    const double *v = d->v;
    return (v[3 * i] - v[3 * j]) * n[0] + (v[3 * i + 1] - v[3 * j + 1]) * n[1] + (v[3 * i + 2] - v[3 * j + 2]) * n[2];
}

/* Gap between particle i and wall W, and (*u) its approach speed towards the wall. */
static inline double dem_wall_gap(const dem_t *d, const dem_wall_t *W, int i, double *u)
{
    double s = 0, a_ = 0;
    for (int a = 0; a < 3; a++) {
        s += (d->x[3 * i + a] - W->p[a]) * W->n[a];
        a_ -= (d->v[3 * i + a] - W->vel[a]) * W->n[a];
    }
    *u = a_;
    return s - d->r[i];
}

/* Small deterministic random generator (splitmix64 / xoshiro256**). */
typedef struct {
    uint64_t s[4];
} dem_rng_t;
void dem_rng_seed(dem_rng_t *g, uint64_t seed);
double dem_rng_uniform(dem_rng_t *g); /* [0, 1) */

static inline double dem_sphere_volume(double r) { return 4.0 / 3.0 * M_PI * r * r * r; }

#endif
