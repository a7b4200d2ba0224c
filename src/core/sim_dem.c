/* sim_dem.c — the DEM (particles) as a part of a run (sim.h).
 *
 * Built when the case has particles ([particles] source other than none).
 * In a scene without a fluid, one step of the run driver is dem.substeps
 * DEM steps (the driver's diagnostics, checks and output decisions then cost
 * nothing); with a fluid, the DEM sets no limit on the step and is advanced
 * to the end of each fluid step with its own steps (sub-cycling; the
 * coupling forces come with the immersed boundary).  The packing preparation
 * ([packing] prepare) runs before the first step of a new run, when the
 * output folder exists; a restarted run takes the particles from the
 * checkpoint.  Snapshots: DIR/particles_NNNNNN.h5 indexed by DIR/particles.xdmf.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem.h"
#include "fluid_model.h"
#include "sim.h"
#include "util.h"

typedef struct {
    sim_t *sim;
    cfg_t *cfg;
    dem_t *d;
    int substeps;        /* DEM steps per driver step (DEM-only scene) */
    double rest_after;   /* the rate of change counts after this time */
    int with_fluid;
    int driven;          /* advanced by the coupling part */
    int prepared;        /* packing prepared, or state read from a checkpoint */
    int snap_first;      /* index of the first snapshot of this run */
    int snap_resumed;
    dem_status_t status; /* of the last advance */
    dem_state_t *prev;   /* the state at the start of the step (rollback) */
    double wall, psteps; /* wall time in dem_advance and particle-steps done */
} dem_part_t;

static const char *const dem_cols[] = {"dem_kinetic_energy", "dem_rotational_energy", "dem_contacts",
                                       "dem_wall_contacts", "dem_max_overlap", "dem_kinetic_energy_x",
                                       "dem_kinetic_energy_y", "dem_kinetic_energy_z"};

static void ensure_prepared(dem_part_t *dp)
{
    if (dp->prepared) return;
    dp->prepared = 1;
    const int rc = dem_prepare_packing(dp->d, dp->cfg, dp->sim->out.dir);
    if (rc >= 10) die("dem: error while preparing the packing: %s", dem_error(dp->d));
    /* lists, forces and time step of the initial state */
    const dem_status_t st = dem_advance(dp->d, dem_time(dp->d));
    if (st != DEM_OK) die("dem: %s", dem_error(dp->d));
    msg("dem: %d particles, contact time %.4g s, DEM step %.4g s%s\n", dem_count(dp->d), dem_contact_time(dp->d),
        dem_dt(dp->d), dp->with_fluid ? " (sub-cycled in the fluid step)" : "");
}

static double part_stable_dt(void *ctx)
{
    dem_part_t *dp = ctx;
    ensure_prepared(dp);
    return dp->with_fluid ? INFINITY : dp->substeps * dem_dt(dp->d);
}

static void part_advance(void *ctx, double dt)
{
    dem_part_t *dp = ctx;
    ensure_prepared(dp);
    if (dp->driven) return;
    const double w0 = wtime();
    const double t_target = dem_time(dp->d) + dt;
    const double steps = ceil(dt / dem_dt(dp->d) * (1 - 1e-12));
    dp->status = dem_advance(dp->d, t_target);
    dp->wall += wtime() - w0;
    dp->psteps += steps * dem_count(dp->d);
}

static void part_diagnostics(void *ctx, double *c)
{
    dem_part_t *dp = ctx;
    ensure_prepared(dp);
    dem_diag_t g;
    dem_diag_light(dp->d, &g);
    c[0] = g.ke_trans;
    c[1] = g.ke_rot;
    c[2] = (double)g.n_contacts;
    c[3] = (double)g.n_wall_contacts;
    c[4] = g.max_overlap;
    for (int a = 0; a < 3; a++) c[5 + a] = g.ke_axis[a];
}

static int part_diverged(void *ctx, char *why, size_t n)
{
    dem_part_t *dp = ctx;
    if (dp->status == DEM_OK) return 0;
    snprintf(why, n, "%s", dem_error(dp->d));
    return 1;
}

static void part_keep_previous(void *ctx)
{
    dem_part_t *dp = ctx;
    dp->prev = dem_state_save(dp->d, dp->prev);
}

static void part_restore_previous(void *ctx)
{
    dem_part_t *dp = ctx;
    if (!dp->prev) return;
    dem_state_restore(dp->d, dp->prev);
    dp->status = DEM_OK;
}

static double part_change_rate(void *ctx, double dt)
{
    dem_part_t *dp = ctx;
    (void)dt;
    return dem_rest_rate(dp->d, dp->rest_after);
}

static void part_write_fields(void *ctx, double time, long step)
{
    dem_part_t *dp = ctx;
    (void)time;
    (void)step;
    ensure_prepared(dp);
    if (!dp->snap_resumed) {
        if (dp->snap_first > 0) dem_snapshots_resume(dp->d, dp->sim->out.dir, dp->snap_first);
        dp->snap_resumed = 1;
    }
    const int index = dem_snapshot_count(dp->d) > dp->snap_first ? dem_snapshot_count(dp->d) : dp->snap_first;
    dem_write_snapshot(dp->d, dp->sim->out.dir, index);
}

static void part_checkpoint_write(void *ctx, hid_t grp)
{
    dem_part_t *dp = ctx;
    ensure_prepared(dp);
    const int nsnap = dem_snapshot_count(dp->d) > dp->snap_first ? dem_snapshot_count(dp->d) : dp->snap_first;
    io_h5_attr_long(grp, "snapshots", nsnap);
    dem_checkpoint_write_loc(dp->d, grp);
}

static void part_checkpoint_read(void *ctx, hid_t grp, const char *path)
{
    dem_part_t *dp = ctx;
    dem_checkpoint_read_loc(dp->d, grp, path);
    long snaps = 0;
    if (io_h5_get_attr_long(grp, "snapshots", &snaps) == 0) dp->snap_first = (int)snaps;
    /* the snapshots the lost continuation wrote, and the index of ours */
    io_outdir_remove_numbered(&dp->sim->out, "particles_", ".h5", dp->snap_first);
    dem_snapshots_resume(dp->d, dp->sim->out.dir, dp->snap_first);
    dp->snap_resumed = 1;
    dp->prepared = 1;
    const dem_status_t st = dem_advance(dp->d, dem_time(dp->d));
    if (st != DEM_OK) die("dem: %s", dem_error(dp->d));
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    dem_part_t *dp = ctx;
    char key[128];
    dem_diag_t g;
    dem_diag(dp->d, &g);
#define KEY(name) (snprintf(key, sizeof key, "%s.%s", prefix, name), key)
    io_summary_long(y, KEY("particles"), g.n_particles);
    io_summary_long(y, KEY("mobile_particles"), g.n_mobile);
    io_summary_long(y, KEY("dem_steps"), g.step);
    io_summary_double(y, KEY("dt"), dem_dt(dp->d));
    io_summary_double(y, KEY("contact_time"), dem_contact_time(dp->d));
    io_summary_double(y, KEY("kinetic_energy"), g.ke_trans);
    io_summary_double(y, KEY("rotational_energy"), g.ke_rot);
    io_summary_double(y, KEY("elastic_energy"), g.e_elastic);
    io_summary_long(y, KEY("contacts"), g.n_contacts);
    io_summary_double(y, KEY("max_overlap"), g.max_overlap);
    io_summary_double(y, KEY("centre_of_mass_z"), g.com[2]);
    io_summary_double(y, KEY("particle_steps_per_second"), dp->wall > 0 ? dp->psteps / dp->wall : 0.0);
    io_summary_double(y, KEY("bytes_per_particle"), dem_memory_per_particle(dp->d));
#undef KEY
}

static void part_destroy(void *ctx)
{
    dem_part_t *dp = ctx;
    dem_state_free(dp->prev);
    dem_free(dp->d);
    free(dp);
}

dem_t *sim_dem_engine(sim_t *s)
{
    for (int p = 0; p < s->npart; p++)
        if (!strcmp(s->part[p].name, "dem")) {
            dem_part_t *dp = s->part[p].ctx;
            ensure_prepared(dp);
            return dp->d;
        }
    return NULL;
}

static dem_part_t *find_part(sim_t *s)
{
    for (int p = 0; p < s->npart; p++)
        if (!strcmp(s->part[p].name, "dem")) return s->part[p].ctx;
    return NULL;
}

void sim_dem_set_driven(sim_t *s)
{
    dem_part_t *dp = find_part(s);
    if (dp) dp->driven = 1;
}

dem_t *sim_dem_engine_unprepared(sim_t *s)
{
    dem_part_t *dp = find_part(s);
    return dp ? dp->d : NULL;
}

void sim_add_dem(sim_t *s, cfg_t *cfg)
{
    dem_part_t *dp = xcalloc(1, sizeof *dp);
    dp->sim = s;
    dp->cfg = cfg;
    dp->d = dem_create_from_config(cfg, s->comm);
    dp->substeps = cfg_int(cfg, "dem", "substeps");
    dp->rest_after = cfg_double(cfg, "dem", "rest_after");
    /* a fluid (resolved or pore network) sets the step; the DEM sub-cycles in it */
    const fluid_model_t model = fluid_model_of(cfg);
    dp->with_fluid = model == FLUID_MODEL_RESOLVED || model == FLUID_MODEL_PORENET;
    if (dem_count(dp->d) == 0) cfg_fail(cfg, "particles", "source", "the scene has no particles");
    if (cfg_bool(cfg, "packing", "prepare")) sim_add_output_name(s, cfg_string(cfg, "packing", "output"));
    sim_part_t part = {
        .name = "dem",
        .ctx = dp,
        .stable_dt = part_stable_dt,
        .advance = part_advance,
        .ncol = 8,
        .col_names = dem_cols,
        .diagnostics = part_diagnostics,
        .diverged = part_diverged,
        .keep_previous = part_keep_previous,
        .restore_previous = part_restore_previous,
        .change_rate = part_change_rate,
        .write_fields = part_write_fields,
        .checkpoint_write = part_checkpoint_write,
        .checkpoint_read = part_checkpoint_read,
        .summary = part_summary,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}
