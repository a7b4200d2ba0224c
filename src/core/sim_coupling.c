/* sim_coupling.c — the resolved fluid–particle coupling as a part of a run
 * (sim.h, coupling.h), and the restitution measurement of bouncing cases.
 *
 * Built when the scene has a fluid and particles (without a pore network):
 * every particle becomes an immersed sphere of kind external; after the
 * fluid step (which forced the spheres where they were) this part hands the
 * hydrodynamic forces to the DEM, advances the DEM over the fluid step with
 * its own sub-steps (the DEM part is then driven from here), and moves the
 * spheres.  The fluid model is [coupling] fluid (fluid_model.h); without the
 * resolved fluid the part only measures bounces: [coupling] restitution = wall|pair adds the bounce
 * measurements (restitution.c) to the time series and summary.json, in
 * coupled and dry runs alike.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "coupling.h"
#include "fluid_model.h"
#include "sim.h"
#include "util.h"

static const cfg_key_t coupling_keys[] = {
    {"coupling", "restitution", CFG_ENUM, "off", 1, 0, "off|wall|pair",
     "measure a bounce: particle 0 against a wall (V_T, V_C, V_R, epsilon, St, Re_p) or particles 0 and 1 (epsilon_B, St_B)"},
    {"coupling", "stop_after_rebound", CFG_BOOL, "false", 1, 0, NULL,
     "restitution: stop the run once the bounce is measured (the particle moves towards the wall again, touches "
     "it a second time, rests on it, or stopped before touching it)"},
    {"coupling", "fit_window", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "restitution: the window (time) of the trajectory fits before the contact and after the release (the impact "
     "and rebound speeds as an experiment measures them, epsilon_fit); 0: 0.2 D/V_T"},
    {"coupling", "align_contacts", CFG_BOOL, "true", 1, 0, NULL,
     "end a fluid step t_c/8 before a contact is predicted to start (along the lubricated approach; steps not "
     "shorter than t_c/8, no sliver of a step before a contact), so that collisions start at the beginning of a "
     "fluid step"},
    {"coupling", "align_release", CFG_BOOL, "true", 1, 0, NULL,
     "with align_contacts: the fluid step that holds a collision ends t_c/8 after its predicted end (when that is "
     "shorter than the step the fluid allows), so that the hydrodynamic force held over the collision acts for "
     "t_c + t_c/4 whatever the fluid step, and the fluid reacts to the rebound from the next step on"},
    {"coupling", "freeze_collisions", CFG_DOUBLE, "2", 0, 1e6, NULL,
     "hold a particle's hydrodynamic force at its value before a contact for up to this many contact times "
     "of contact, the fluid's force meanwhile applied after it (the seed's fluid frozen during collisions; "
     "matters when the fluid step is shorter than t_c); 0: off"},
    {"coupling", "added_mass", CFG_ENUM, "consistent", 1, 0, "none|consistent",
     "none: contact and lubrication forces act on m_p, the fluid's reaction to a collision comes through the next "
     "fluid step; consistent: they act on m_p + C_M rho V_p (Izard eqs. 3.24, 3.26) and the fluid's reaction "
     "C_M rho V_p dU/dt_f to the velocity change they made is removed from the next held force (docs/theory.md §9.1)"},
    {"coupling", "added_mass_coefficient", CFG_DOUBLE, "0.5", 0, 10, NULL,
     "added_mass = consistent: C_M (1/2, a sphere in unbounded fluid, the seed's value for walls and pairs; "
     "0.803, a sphere touching a wall or the symmetry plane of two equal spheres, docs/theory.md §9.1)"},
    {"coupling", "implicit_drag", CFG_DOUBLE, "0", 0, 1e6, NULL,
     "K > 0: inside the DEM sub-steps the held hydrodynamic force and torque respond to the particle's velocity "
     "change since the fluid step, -K 3 pi eta D (U - U_n) and -K pi eta D^3 (omega - omega_n), so that a particle "
     "whose relaxation time is shorter than the fluid step is not driven by a stale force (docs/theory.md §9.1); "
     "0: the held force alone (the seed's)"},
    {"coupling", "implicit_drag_hindrance", CFG_ENUM, "none", 1, 0, "none|richardson_zaki|relative",
     "implicit_drag > 0: the force coefficient K 3 pi eta D of every particle (none); or c_h = 3 pi eta D max(K, "
     "(1 - phi)^-4.65), phi the particle's local solid fraction (a ball of 1.5 mean diameters; at most 0.64) at the start of "
     "the fluid step, on the whole velocity change (richardson_zaki), or on its part relative to the "
     "neighbourhood's mean change, K on the rest, along the periodic directions (relative: a grain that moves "
     "against its neighbours meets the hindered drag, a neighbourhood that moves together carries its pore fluid "
     "along; along a direction bounded by walls it pushes the fluid through its pores: c_h on the whole change; "
     "docs/theory.md §9.1b)"},
    {"coupling", "restitution_axis", CFG_VEC3, NULL, -1e300, 1e300, NULL,
     "wall: direction from the particle towards the wall (default: along gravity)", CFG_OPTIONAL},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL},
};

void sim_coupling_register_keys(void) { cfg_schema_add(coupling_keys); }

int sim_fluid_enabled(cfg_t *cfg) { return fluid_model_of(cfg) == FLUID_MODEL_RESOLVED; }

typedef struct {
    sim_t *sim;
    cfg_t *cfg;
    dem_t *d;
    ibm_t *ibm;          /* NULL in a dry run */
    double rho_f, gravity[3];
    int synced;
    restitution_t rest;
    dem_status_t status;
    int stop_after;      /* [coupling] stop_after_rebound */
    int align;           /* [coupling] align_contacts */
    int align_release;   /* [coupling] align_release */
    double freeze;       /* [coupling] freeze_collisions (contact times) */
    coupling_numbers_t num; /* of particle 0 (a bounce) or of the mean particle; num.D = 0: none */
    coupling_freeze_t fz;
    coupling_added_mass_t am; /* [coupling] added_mass = consistent (am.n > 0) */
    coupling_drag_t drag;     /* [coupling] implicit_drag > 0 (drag.n > 0) */
    double wall_dem;     /* wall time in the DEM */
    long substeps;       /* DEM sub-steps done */
    /* the state at the start of the step (rollback) */
    restitution_t prev_rest;   /* its trajectory samples are in prev_traj */
    double *prev_fz, *prev_dU; /* F0, J, held (13n); dU (3n) */
    double *prev_traj;         /* the tracker's trajectory samples (2 prev_rest.ntraj) */
    long prev_captraj;
    long prev_substeps;
} coupling_part_t;

static const char *const rest_cols[] = {"approach_speed", "lubrication_force"};

static void observe(dem_t *d, void *ctx)
{
    coupling_part_t *cp = ctx;
    restitution_substep(&cp->rest, d);
    cp->substeps++;
}

/* Density, diameter and ε_max of the tracked particle (id 0). */
static void tracked_particle(coupling_part_t *cp)
{
    const long *id = dem_ids(cp->d);
    for (int i = 0; i < dem_count(cp->d); i++)
        if (id[i] == 0) {
            const double r = dem_radii(cp->d)[i];
            cp->rest.rho_p = dem_density(cp->d, i);
            cp->rest.D = 2 * r;
        }
    cp->rest.e_dry = dem_dry_restitution(cp->d);
}

/* The dimensionless numbers of the scene (numbers.c): of particle 0 when a bounce is measured,
 * otherwise of the mean particle; printed once. */
static void scene_numbers(coupling_part_t *cp)
{
    const int n = dem_count(cp->d);
    if (!cp->ibm || n == 0 || !(cp->rest.mu > 0)) return;
    double D = 0, rho_p = 0;
    if (cp->rest.D > 0) {
        D = cp->rest.D;
        rho_p = cp->rest.rho_p;
    } else {
        for (int i = 0; i < n; i++) {
            D += 2 * dem_radii(cp->d)[i] / n;
            rho_p += dem_density(cp->d, i) / n;
        }
    }
    const double g = sqrt(cp->gravity[0] * cp->gravity[0] + cp->gravity[1] * cp->gravity[1] +
                          cp->gravity[2] * cp->gravity[2]);
    coupling_numbers(D, rho_p, cp->rho_f, cp->rest.mu, g, grid_min_spacing(cp->sim->fluid->g), dem_contact_time(cp->d),
                     &cp->num);
    const coupling_numbers_t *q = &cp->num;
    msg("coupling: %s D = %.4g, rho_p/rho = %.4g, Ga = %.4g; Schiller-Naumann V_T = %.4g, Re_T = %.4g, "
        "St_T = (rho_p + rho/2) V_T D/(9 mu) = %.4g; D/dx = %.3g, t_c sqrt(g/D) = %.3g, t_c V_T/D = %.3g\n",
        cp->rest.D > 0 ? "particle 0:" : "mean particle:", q->D, q->ratio, q->Ga, q->V_T, q->Re_T, q->St_T, q->D_over_h,
        q->tc_g, q->tc_VT);
}

/* The DEM engine (prepared), the tracked particle, gravity, the freeze's
 * hold time and the sub-step observer: at the first use, or after a restart. */
static void attach(coupling_part_t *cp)
{
    cp->d = sim_dem_engine(cp->sim);
    tracked_particle(cp);
    dem_get_gravity(cp->d, cp->gravity);
    if (cp->fz.n) cp->fz.hold_time = cp->freeze * dem_contact_time(cp->d);
    if (cp->am.n) coupling_added_mass_apply(&cp->am, cp->d, cp->rho_f);
    if (cp->rest.mode != RESTITUTION_OFF) dem_set_step_observer(cp->d, observe, cp);
    if (cp->ibm) memcpy(cp->ibm->prm.gravity, cp->gravity, sizeof cp->gravity);
    scene_numbers(cp);
}

/* Once, before the first step of a new run: attach, and the spheres at the
 * particles (they may have moved in the packing preparation). */
static void setup(coupling_part_t *cp)
{
    if (cp->synced) return;
    cp->synced = 1;
    attach(cp);
    if (cp->ibm) {
        if (dem_count(cp->d) != cp->ibm->n) die("coupling: %d particles but %d immersed spheres", dem_count(cp->d), cp->ibm->n);
        if (cp->sim->step == 0) coupling_motion_to_ibm(cp->d, cp->ibm);
    }
}

/* align_contacts: given the step T that the fluid and the spheres allow, the
 * step ends t_c/8 before the next contact is predicted to start, unless that
 * is less than t_c/4 away (it starts early in the next step anyway).  The
 * prediction follows the lubricated approach (dem_time_to_contact), which
 * the constant-velocity estimate gap/u misses.  A contact predicted just
 * beyond T, between T and 1.5 T, would leave a sliver of a step before it,
 * whose hydrodynamic force (a change of the fluid momentum over a tiny Δt) is
 * noise: the distance is split into two equal steps instead.  The aim is
 * t_c/8 early because the prediction holds the last hydrodynamic force, which
 * grows as the gap closes (the film the grid resolves): it is late by a few
 * sub-steps.  With align_release, the step that holds the collision (its
 * start within t_c/4) ends t_c/8 after the predicted end of the collision,
 * t_c after its start (a collision of the linear law lasts t_c): the force
 * held over the collision — that of the approach, pushing the particle away
 * from the wall — then acts over t_c + t_c/4 however long the fluid step, and
 * the fluid's reaction to the rebound starts at a fixed time after the
 * release.  Only the step's own state enters (no previous step): a restart
 * takes the same steps. */
static double part_align_dt(void *ctx, double T)
{
    coupling_part_t *cp = ctx;
    setup(cp);
    if (!cp->ibm || !cp->align) return T;
    const double tc = dem_contact_time(cp->d), margin = 0.125 * tc; /* t_c/8 */
    /* contacts beyond 1.5 T + t_c/8 cannot change the step: not integrated */
    const double t = dem_time_to_contact(cp->d, 1.5 * T + margin);
    if (!(t > 0)) return T; /* in contact: the fluid stays frozen over a whole step */
    if (!(t > 2.0 * margin)) {
        /* within t_c/4: the step holds the collision */
        const double through = t + tc + margin;
        return cp->align_release && through < T ? through : T;
    }
    const double aim = t - margin;
    if (aim >= 1.5 * T) return T;
    return aim > T ? 0.5 * aim : aim;
}

/* The step limit of the particles' acceleration from rest (the immersed
 * boundary limits the step by their velocities, ibm_stable_dt): a particle
 * at rest, whose held force vanished, accelerates at most by its immersed
 * weight, a = |g| (m_p − ρV_p)/m (m with any added mass), and moves a cell
 * in √(2h/a): the step is at most the CFL target over √(a/h), as the
 * immersed boundary does for a free sphere.  (With implicit_drag a single
 * particle's speed within the step stays below a m/c, c = K 3πηD, but the
 * fluid a settling crowd sets in motion does not: that bound let a scene of
 * 150 grains at rest take a first step that put the fluid at CFL 2.) */
static double part_stable_dt(void *ctx)
{
    coupling_part_t *cp = ctx;
    setup(cp);
    if (!cp->ibm || cp->sim->fluid->prm.dt_fixed > 0) return INFINITY;
    const grid_t *g = cp->ibm->g;
    const double h = grid_min_spacing(g);
    const double gg = sqrt(cp->gravity[0] * cp->gravity[0] + cp->gravity[1] * cp->gravity[1] +
                           cp->gravity[2] * cp->gravity[2]);
    const double *r = dem_radii(cp->d);
    const unsigned char *fx = dem_fixed(cp->d);
    double rate = 0.0;
    for (int i = 0; i < dem_count(cp->d); i++) {
        if (fx[i]) continue;
        const double V = 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i], m = dem_mass(cp->d, i);
        const double a = gg * fabs(dem_density(cp->d, i) - cp->rho_f) * V / m;
        rate = fmax(rate, sqrt(a / h));
    }
    return rate > 0 ? cp->sim->fluid->prm.cfl / rate : INFINITY;
}

static void part_advance(void *ctx, double dt)
{
    coupling_part_t *cp = ctx;
    setup(cp);
    if (cp->ibm) {
        const double w0 = wtime();
        coupling_added_mass_t *am = cp->am.n ? &cp->am : NULL;
        coupling_forces_to_dem(cp->ibm, cp->d, cp->rho_f, cp->gravity, cp->fz.n ? &cp->fz : NULL, am, dt);
        cp->status = cp->drag.n ? coupling_drag_advance(&cp->drag, cp->ibm, cp->d, am, dt)
                                : dem_advance(cp->d, dem_time(cp->d) + dt);
        if (am) coupling_added_mass_after_step(am, cp->d);
        cp->wall_dem += wtime() - w0;
        if (cp->status == DEM_OK) coupling_motion_to_ibm(cp->d, cp->ibm);
    }
    restitution_sample(&cp->rest, cp->d);
}

static void part_diagnostics(void *ctx, double *c)
{
    coupling_part_t *cp = ctx;
    setup(cp);
    c[0] = restitution_approach_speed(&cp->rest, cp->d, 0);
    /* the impulse the observer summed over the sub-steps of the step (in a dry run the DEM
     * part advances before this part), reported once and reset */
    c[1] = cp->sim->dt > 0 ? cp->rest.lub_impulse / cp->sim->dt : 0.0;
    cp->rest.lub_impulse = 0;
}

static int part_diverged(void *ctx, char *why, size_t n)
{
    coupling_part_t *cp = ctx;
    if (cp->status == DEM_OK) return 0;
    snprintf(why, n, "dem (coupled): %s", dem_error(cp->d));
    return 1;
}

/* The state at the start of the step, and back (the DEM and the spheres
 * are brought back by their own parts). */
static void part_keep_previous(void *ctx)
{
    coupling_part_t *cp = ctx;
    const size_t n = (size_t)cp->fz.n, na = (size_t)cp->am.n;
    cp->prev_rest = cp->rest;
    const long nt = cp->rest.ntraj;
    if (nt > cp->prev_captraj) {
        cp->prev_captraj = cp->rest.captraj;
        free(cp->prev_traj);
        cp->prev_traj = xcalloc(2 * (size_t)cp->prev_captraj, sizeof(double));
    }
    if (nt) memcpy(cp->prev_traj, cp->rest.traj, 2 * (size_t)nt * sizeof(double));
    cp->prev_substeps = cp->substeps;
    if (n) {
        if (!cp->prev_fz) cp->prev_fz = xcalloc(13 * n, sizeof(double));
        memcpy(cp->prev_fz, cp->fz.F0, 6 * n * sizeof(double));
        memcpy(cp->prev_fz + 6 * n, cp->fz.J, 6 * n * sizeof(double));
        memcpy(cp->prev_fz + 12 * n, cp->fz.held, n * sizeof(double));
    }
    if (na) {
        if (!cp->prev_dU) cp->prev_dU = xcalloc(3 * na, sizeof(double));
        memcpy(cp->prev_dU, cp->am.dU, 3 * na * sizeof(double));
    }
}

static void part_restore_previous(void *ctx)
{
    coupling_part_t *cp = ctx;
    const size_t n = (size_t)cp->fz.n, na = (size_t)cp->am.n;
    /* the samples go back into the tracker's own array (the step may have grown or cleared it) */
    double *traj = cp->rest.traj;
    long cap = cp->rest.captraj;
    const long nt = cp->prev_rest.ntraj;
    if (nt > cap) {
        free(traj);
        cap = cp->prev_captraj;
        traj = xcalloc(2 * (size_t)cap, sizeof(double));
    }
    cp->rest = cp->prev_rest;
    cp->rest.traj = traj;
    cp->rest.captraj = cap;
    if (nt) memcpy(traj, cp->prev_traj, 2 * (size_t)nt * sizeof(double));
    cp->substeps = cp->prev_substeps;
    cp->status = DEM_OK;
    if (n && cp->prev_fz) {
        memcpy(cp->fz.F0, cp->prev_fz, 6 * n * sizeof(double));
        memcpy(cp->fz.J, cp->prev_fz + 6 * n, 6 * n * sizeof(double));
        memcpy(cp->fz.held, cp->prev_fz + 12 * n, n * sizeof(double));
    }
    if (na && cp->prev_dU) memcpy(cp->am.dU, cp->prev_dU, 3 * na * sizeof(double));
}

/* The tracker's state (exact restarts of the measurements). */
#define REST_NSCALAR 16
#define REST_NSTATE (REST_NSCALAR + 13)
static void pack(const restitution_t *r, double *v)
{
    const double s[REST_NSCALAR] = {r->phase,     r->u_last, r->VT,     r->VC,   r->VR,    r->VR_release,
                                    r->t_contact, r->t_release, r->lub_impulse, r->VC_onset, r->window, r->V_in,
                                    r->V_out,     r->apex,   r->t_apex, (double)r->ntraj};
    memcpy(v, s, sizeof s);
    double *o = v + REST_NSCALAR;
    memcpy(o, r->cp_last, 3 * sizeof(double));
    memcpy(o + 3, r->cp_in, 3 * sizeof(double));
    memcpy(o + 6, r->cp_out, 3 * sizeof(double));
    memcpy(o + 9, r->vt_out, 3 * sizeof(double));
    o[12] = r->vn_out;
}

static void part_checkpoint_write(void *ctx, hid_t grp)
{
    coupling_part_t *cp = ctx;
    double v[REST_NSTATE];
    pack(&cp->rest, v);
    io_h5_write_array(grp, "restitution", REST_NSTATE, v);
    if (cp->rest.ntraj > 0) io_h5_write_array(grp, "restitution_trajectory", 2 * cp->rest.ntraj, cp->rest.traj);
    io_h5_attr_long(grp, "dem_substeps", cp->substeps);
    if (cp->fz.n) {
        io_h5_write_array(grp, "freeze_force", 6L * cp->fz.n, cp->fz.F0);
        io_h5_write_array(grp, "freeze_impulse", 6L * cp->fz.n, cp->fz.J);
        io_h5_write_array(grp, "freeze_held", cp->fz.n, cp->fz.held);
    }
    if (cp->am.n) io_h5_write_array(grp, "added_mass_dU", 3L * cp->am.n, cp->am.dU);
}

static void part_checkpoint_read(void *ctx, hid_t grp, const char *path)
{
    coupling_part_t *cp = ctx;
    double v[REST_NSTATE];
    if (io_h5_read_array(grp, "restitution", REST_NSTATE, v) != REST_NSTATE)
        die("%s: /coupling/restitution is missing or has the wrong size", path);
    restitution_t *r = &cp->rest;
    r->phase = (int)v[0];
    r->u_last = v[1], r->VT = v[2], r->VC = v[3], r->VR = v[4], r->VR_release = v[5];
    r->t_contact = v[6], r->t_release = v[7], r->lub_impulse = v[8], r->VC_onset = v[9];
    r->window = v[10], r->V_in = v[11], r->V_out = v[12], r->apex = v[13], r->t_apex = v[14];
    const double *o = v + REST_NSCALAR;
    memcpy(r->cp_last, o, 3 * sizeof(double));
    memcpy(r->cp_in, o + 3, 3 * sizeof(double));
    memcpy(r->cp_out, o + 6, 3 * sizeof(double));
    memcpy(r->vt_out, o + 9, 3 * sizeof(double));
    r->vn_out = o[12];
    const long nt = (long)v[15];
    restitution_free(r);
    if (nt > 0) {
        r->captraj = nt;
        r->traj = xcalloc(2 * (size_t)nt, sizeof(double));
        if (io_h5_read_array(grp, "restitution_trajectory", 2 * nt, r->traj) != 2 * nt)
            die("%s: /coupling/restitution_trajectory is missing or has the wrong size", path);
        r->ntraj = nt;
    }
    if (io_h5_get_attr_long(grp, "dem_substeps", &cp->substeps)) cp->substeps = 0;
    if (cp->fz.n) {
        const long n = cp->fz.n;
        if (io_h5_read_array(grp, "freeze_force", 6 * n, cp->fz.F0) != 6 * n ||
            io_h5_read_array(grp, "freeze_impulse", 6 * n, cp->fz.J) != 6 * n ||
            io_h5_read_array(grp, "freeze_held", n, cp->fz.held) != n)
            die("%s: /coupling/freeze_* is missing or has the wrong size", path);
    }
    if (cp->am.n && io_h5_read_array(grp, "added_mass_dU", 3L * cp->am.n, cp->am.dU) != 3L * cp->am.n)
        die("%s: /coupling/added_mass_dU is missing or has the wrong size", path);
    cp->synced = 1; /* the spheres and particles come from the checkpoint */
    attach(cp);
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    coupling_part_t *cp = ctx;
    setup(cp);
    char key[128];
#define KEY(name) (snprintf(key, sizeof key, "%s.%s", prefix, name), key)
    io_summary_string(y, KEY("fluid"), cp->ibm ? "resolved" : "off");
    io_summary_long(y, KEY("dem_substeps"), cp->substeps);
    if (cp->num.D > 0) {
        const coupling_numbers_t *q = &cp->num;
        io_summary_double(y, KEY("numbers.D"), q->D);
        io_summary_double(y, KEY("numbers.density_ratio"), q->ratio);
        io_summary_double(y, KEY("numbers.Ga"), q->Ga);
        io_summary_double(y, KEY("numbers.V_T_schiller_naumann"), q->V_T);
        io_summary_double(y, KEY("numbers.Re_T"), q->Re_T);
        io_summary_double(y, KEY("numbers.St_T"), q->St_T);
        io_summary_double(y, KEY("numbers.D_over_dx"), q->D_over_h);
        io_summary_double(y, KEY("numbers.tc_sqrt_g_over_D"), q->tc_g);
        io_summary_double(y, KEY("numbers.tc_V_T_over_D"), q->tc_VT);
    }
    io_summary_double(y, KEY("dem_wall_seconds"), cp->wall_dem);
    if (cp->drag.n && cp->drag.hindered) {
        /* the last step's local solid fraction (mean over the mobile grains) and largest coefficient */
        io_summary_double(y, KEY("implicit_drag_phi_mean"), cp->drag.phi_mean);
        io_summary_double(y, KEY("implicit_drag_factor_max"), cp->drag.factor_max);
    }
    const restitution_t *r = &cp->rest;
    if (r->mode != RESTITUTION_OFF) {
        const int wall = r->mode == RESTITUTION_WALL;
        io_summary_string(y, KEY("restitution_mode"), wall ? "wall" : "pair");
        io_summary_bool(y, KEY("contact"), r->phase > 0);
        io_summary_bool(y, KEY("rebound"), r->VR > 0);
        io_summary_double(y, KEY(wall ? "V_T" : "U_i"), r->VT);
        io_summary_double(y, KEY(wall ? "V_C" : "U_c"), r->VC);
        io_summary_double(y, KEY(wall ? "V_R" : "U_r"), r->VR);
        io_summary_double(y, KEY(wall ? "V_C_onset" : "U_c_onset"), r->VC_onset);
        io_summary_double(y, KEY("V_release"), r->VR_release);
        io_summary_double(y, KEY("V_C_over_V_T"), r->VT > 0 ? r->VC / r->VT : 0.0);
        io_summary_double(y, KEY(wall ? "epsilon" : "epsilon_B"), restitution_epsilon(r));
        io_summary_double(y, KEY("epsilon_max"), r->e_dry);
        io_summary_double(y, KEY("epsilon_over_max"), r->e_dry > 0 ? restitution_epsilon(r) / r->e_dry : 0.0);
        io_summary_double(y, KEY(wall ? "St" : "St_B"), restitution_stokes(r));
        io_summary_double(y, KEY(wall ? "Re_p" : "Re_rel"), restitution_reynolds(r));
        /* the rebound as an experiment measures it: fits of the trajectory (docs/theory.md §9.3) */
        io_summary_double(y, KEY("fit_window"), r->window);
        io_summary_double(y, KEY("V_in"), r->V_in);
        io_summary_double(y, KEY("V_out"), r->V_out);
        io_summary_double(y, KEY("epsilon_fit"), restitution_epsilon_fit(r));
        if (wall) {
            io_summary_double(y, KEY("apex_over_D"), r->D > 0 ? r->apex / r->D : 0.0);
            io_summary_double(y, KEY("t_apex_after_release"), r->phase >= 2 ? r->t_apex - r->t_release : 0.0);
            double psi_in, psi_out, beta, mu_f, angle;
            restitution_oblique(r, &psi_in, &psi_out, &beta, &mu_f, &angle);
            io_summary_double(y, KEY("psi_in"), psi_in);
            io_summary_double(y, KEY("psi_out"), psi_out);
            io_summary_double(y, KEY("beta"), beta);
            io_summary_double(y, KEY("mu_f"), mu_f);
            io_summary_double(y, KEY("rebound_angle_deg"), angle);
        }
        io_summary_double(y, KEY("t_contact"), r->t_contact);
        io_summary_double(y, KEY("t_release"), r->t_release);
        io_summary_bool(y, KEY("second_contact"), r->phase == 3);
    }
#undef KEY
}

/* The bounce is measured: after the rebound, moving towards the wall again
 * (wall) or separating at less than 0.9 of the largest rebound speed (pair:
 * the maximum is behind), a second contact, resting in contact for 40 t_c,
 * or stopped before touching (the lubrication held it: approach speed below
 * 1 % of V_T). */
static int part_done(void *ctx)
{
    coupling_part_t *cp = ctx;
    if (!cp->stop_after || !cp->synced) return 0;
    const restitution_t *r = &cp->rest;
    const double u = restitution_approach_speed(r, cp->d, 0), t = dem_time(cp->d);
    switch (r->phase) {
    case 0: return r->VT > 0 && fabs(u) < 1e-2 * r->VT && cp->sim->step > 10;
    case 1: return t - r->t_contact > 40 * dem_contact_time(cp->d);
    case 2:
        if (!restitution_measured(r)) return 0;
        if (r->mode == RESTITUTION_PAIR) return r->VR > 0 && -u < 0.9 * r->VR;
        return u > 0 && r->VR > 0;
    default: return 1;
    }
}

/* A mobile particle crossing a face of the fluid's domain that has no DEM
 * wall: the fluid alone would let it sink through (no contact law there).
 * Returns its id + 1 (0: none) and the face. */
static long unwalled_touch(const dem_t *d, const grid_t *g, const char **face_name)
{
    static const char *face[3][2] = {{"x_lo", "x_hi"}, {"y_lo", "y_hi"}, {"z_lo", "z_hi"}};
    const double *x = dem_positions(d), *r = dem_radii(d);
    const unsigned char *fixed = dem_fixed(d);
    for (int a = 0; a < g->dim; a++)
        for (int side = 0; side < 2; side++) {
            if (g->bc.type[a][side] == BC_PERIODIC || g->bc.type[a][side] == BC_AXIS) continue;
            const int w = dem_wall_find(d, face[a][side]);
            if (w >= 0 && dem_wall_active(d, w)) continue;
            const double plane = side ? g->x0[a] + g->L[a] : g->x0[a];
            for (int i = 0; i < dem_count(d); i++)
                if (!fixed[i] && (side ? plane - (x[3 * i + a] + r[i]) : x[3 * i + a] - r[i] - plane) < 0) {
                    *face_name = face[a][side];
                    return dem_ids(d)[i] + 1;
                }
        }
    return 0;
}

/* Such a contact stops the run (sim.h, halt). */
static int part_halt(void *ctx, char *why, size_t n)
{
    coupling_part_t *cp = ctx;
    if (!cp->ibm) return 0;
    setup(cp);
    const char *face;
    const long id = unwalled_touch(cp->d, cp->ibm->g, &face);
    if (id)
        snprintf(why, n, "particle %ld touched the %s face of the fluid's domain, which has no DEM wall (give it one "
                 "with walls.faces)", id, face);
    return id != 0;
}

static void part_destroy(void *ctx)
{
    coupling_part_t *cp = ctx;
    coupling_freeze_free(&cp->fz);
    coupling_added_mass_free(&cp->am);
    coupling_drag_free(&cp->drag);
    restitution_free(&cp->rest);
    free(cp->prev_fz);
    free(cp->prev_dU);
    free(cp->prev_traj);
    free(cp);
}

void sim_add_coupling(sim_t *s, cfg_t *cfg, struct ibm *ibm)
{
    coupling_part_t *cp = xcalloc(1, sizeof *cp);
    cp->sim = s;
    cp->cfg = cfg;
    cp->ibm = ibm;
    cp->rho_f = s->fluid ? s->fluid->prm.rho : (cfg_has_section(cfg, "fluid") ? cfg_double(cfg, "fluid", "rho") : 0.0);
    const int mode = cfg_enum(cfg, "coupling", "restitution");
    double g[3], axis[3];
    cfg_vec3(cfg, "dem", "gravity", g);
    if (cfg_has(cfg, "coupling", "restitution_axis"))
        cfg_vec3(cfg, "coupling", "restitution_axis", axis);
    else
        memcpy(axis, g, sizeof axis);
    if (mode == RESTITUTION_WALL && axis[0] == 0 && axis[1] == 0 && axis[2] == 0)
        cfg_fail(cfg, "coupling", "restitution_axis", "needed: there is no gravity to take the direction from");
    double mu = 0;
    if (cfg_has_section(cfg, "fluid")) mu = cfg_double(cfg, "fluid", "rho") * fluid_nu_from_config(cfg);
    if (fluid_model_lubrication(cfg) && cfg_enum(cfg, "lubrication", "model") != 0 &&
        cfg_double(cfg, "lubrication", "viscosity") > 0)
        mu = cfg_double(cfg, "lubrication", "viscosity");
    /* density, diameter and ε_max of the tracked particle: at setup */
    restitution_init(&cp->rest, (restitution_mode_t)mode, axis, cp->rho_f, mu, 0.0, 0.0, 0.0);
    cp->rest.fit_window = cfg_double(cfg, "coupling", "fit_window");
    cp->align = cfg_bool(cfg, "coupling", "align_contacts");
    cp->align_release = cfg_bool(cfg, "coupling", "align_release");
    cp->freeze = cfg_double(cfg, "coupling", "freeze_collisions");
    if (ibm && cp->freeze > 0 && ibm->n > 0) coupling_freeze_init(&cp->fz, ibm->n, 0.0); /* hold time at setup */
    if (ibm && ibm->n > 0 && cfg_enum(cfg, "coupling", "added_mass") == 1)
        coupling_added_mass_init(&cp->am, ibm->n, cfg_double(cfg, "coupling", "added_mass_coefficient"));
    cp->stop_after = mode != RESTITUTION_OFF && cfg_bool(cfg, "coupling", "stop_after_rebound");
    if (ibm && ibm->n > 0 && cfg_double(cfg, "coupling", "implicit_drag") > 0)
        coupling_drag_init(&cp->drag, ibm->n, cfg_double(cfg, "coupling", "implicit_drag"),
                           s->fluid->prm.rho * s->fluid->prm.nu, cfg_enum(cfg, "coupling", "implicit_drag_hindrance"));
    if (cp->drag.n) coupling_drag_set_bounded(&cp->drag, s->fluid->g->periodic);
    /* the lubrication correction adds what the grid does not resolve: it needs the grid spacing
     * (before the packing preparation, whose lists must hold every lubricated pair) */
    if (ibm) dem_lubrication_set_grid(sim_dem_engine_unprepared(s), grid_min_spacing(s->fluid->g));
    const char *face;
    const long id = ibm ? unwalled_touch(sim_dem_engine_unprepared(s), ibm->g, &face) : 0;
    if (id)
        cfg_fail(cfg, "walls", "faces", "particle %ld crosses the %s face of the fluid's domain, which has no DEM wall: "
                 "it would halt the run at once", id, face);
    sim_part_t part = {
        .name = "coupling",
        .ctx = cp,
        .stable_dt = part_stable_dt,
        .align_dt = part_align_dt,
        .advance = part_advance,
        .ncol = mode ? 2 : 0,
        .col_names = rest_cols,
        .diagnostics = part_diagnostics,
        .diverged = part_diverged,
        .keep_previous = part_keep_previous,
        .restore_previous = part_restore_previous,
        .checkpoint_write = part_checkpoint_write,
        .checkpoint_read = part_checkpoint_read,
        .summary = part_summary,
        .done = part_done,
        .halt = part_halt,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}
