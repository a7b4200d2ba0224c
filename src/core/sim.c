/* sim.c — the run driver (see sim.h): the time loop, the stop conditions,
 * the divergence checks and the schedule of the outputs.  The physics lives
 * in the parts (sim_fluid.c, ...). */
#include "coupling.h"
#include "poisson.h"
#include "sim.h"

#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

static const cfg_key_t sim_keys[] = {
    {"time", "t_end", CFG_DOUBLE, NULL, 0, 1e300, NULL, "simulated time at which the run stops"},
    {"time", "max_steps", CFG_INT, "0", 0, 2147483647, NULL,
     "stop after this step number (counted from the start of the run, restarts included); 0: no limit"},
    {"time", "wall_limit", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "stop with a checkpoint after this many seconds of wall time; 0: no limit"},
    {"time", "steady_tol", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "stop when max|u(n+1) - u(n)| / (dt max|u|) falls below this (per unit time); 0: off"},
    {"time", "cfl_abort", CFG_DOUBLE, "1.5", 1e-3, 100, NULL,
     "hard CFL limit: a step above it (or above twice the CFL target of an adaptive step) means divergence"},
    {"time", "ke_growth_abort", CFG_DOUBLE, "100", 1.000001, 1e300, NULL,
     "kinetic energy growing by more than this factor in one step means divergence"},
    {"time", "rollback", CFG_BOOL, "true", 1, 0, NULL,
     "keep the state at the start of each step, so a diverging run checkpoints its last good state "
     "(costs one copy of the velocity and pressure)"},
    {"output", "dir", CFG_STRING, "out/NAME", 1, 0, NULL, "output folder (created); --out DIR sets it too"},
    {"output", "name", CFG_STRING, "case file name", 1, 0, NULL, "case name written in summary.json"},
    {"output", "fields_every", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "simulated time between field snapshots (fields_NNNNN.h5 + fields.xmf); 0: initial and final only"},
    {"output", "series_every", CFG_INT, "1", 1, 2147483647, NULL, "steps between rows of series.csv"},
    {"output", "checkpoint_every", CFG_INT, "0", 0, 2147483647, NULL,
     "steps between checkpoints (checkpoint_SSSSSSSS.h5); 0: at the end only"},
    {"output", "checkpoint_keep", CFG_INT, "2", 0, 1000000, NULL, "newest checkpoints kept in the folder; 0: all"},
    {"output", "progress", CFG_ENUM, "auto", 1, 0, "auto|on|off",
     "progress line redrawn in place: auto = when stdout is a terminal and the run was not started by mpirun "
     "(whose processes always see a pseudo-terminal), on, off"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void sim_register_keys(void) { cfg_schema_add(sim_keys); }

const char *const sim_run_control_keys[] = {"time.t_end",     "time.max_steps", "time.wall_limit", "time.steady_tol",
                                            "time.cfl_abort", "time.ke_growth_abort", "time.rollback",
                                            "output.*",       "poisson.fftw_wisdom", NULL};

static void read_params(sim_t *s, cfg_t *cfg)
{
    sim_params_t *p = &s->prm;
    p->t_end = cfg_double(cfg, "time", "t_end");
    p->max_steps = cfg_int(cfg, "time", "max_steps");
    p->wall_limit = cfg_double(cfg, "time", "wall_limit");
    p->steady_tol = cfg_double(cfg, "time", "steady_tol");
    p->cfl_abort = cfg_double(cfg, "time", "cfl_abort");
    p->ke_growth_abort = cfg_double(cfg, "time", "ke_growth_abort");
    p->rollback = cfg_bool(cfg, "time", "rollback");
    /* The case name defaults to the file name without its directory and .ini */
    if (cfg_has(cfg, "output", "name")) {
        snprintf(p->name, sizeof p->name, "%s", cfg_string(cfg, "output", "name"));
    } else {
        const char *base = strrchr(cfg_path(cfg), '/');
        snprintf(p->name, sizeof p->name, "%s", base ? base + 1 : cfg_path(cfg));
        char *dot = strrchr(p->name, '.');
        if (dot && dot != p->name) *dot = 0;
    }
    if (cfg_has(cfg, "output", "dir"))
        snprintf(p->dir, sizeof p->dir, "%s", cfg_string(cfg, "output", "dir"));
    else
        snprintf(p->dir, sizeof p->dir, "out/%s", p->name);
    p->fields_every = cfg_double(cfg, "output", "fields_every");
    p->series_every = cfg_int(cfg, "output", "series_every");
    p->checkpoint_every = cfg_int(cfg, "output", "checkpoint_every");
    p->checkpoint_keep = cfg_int(cfg, "output", "checkpoint_keep");
    p->progress = cfg_enum(cfg, "output", "progress");
    if (p->steady_tol > 0 && !p->rollback)
        cfg_fail(cfg, "time", "steady_tol", "needs time.rollback = true (the previous state is compared)");
}

void sim_add_part(sim_t *s, const sim_part_t *part)
{
    if (s->npart == SIM_MAX_PARTS) die("too many parts in the scene (SIM_MAX_PARTS = %d)", SIM_MAX_PARTS);
    s->part[s->npart++] = *part;
}

void sim_add_field_writer(sim_t *s, sim_field_writer_t fn, void *ctx)
{
    if (s->nfield_writers == SIM_MAX_PARTS) die("too many snapshot field writers (SIM_MAX_PARTS = %d)", SIM_MAX_PARTS);
    s->field_writer[s->nfield_writers] = fn;
    s->field_writer_ctx[s->nfield_writers++] = ctx;
}

/* ---- checkpoints --------------------------------------------------------- */

static void write_checkpoint(sim_t *s)
{
    io_checkpoint_header_t h = {s->time, s->step, s->fingerprint, mpi_size(), s->input};
    hid_t f = io_checkpoint_begin(s->out.dir, &h, s->comm);
    io_h5_attr_double(f, "next_fields_time", s->next_fields);
    for (int i = 0; i < s->npart; i++) {
        sim_part_t *p = &s->part[i];
        if (!p->checkpoint_write) continue;
        hid_t g = H5Gcreate2(f, p->name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        p->checkpoint_write(p->ctx, g);
        H5Gclose(g);
    }
    io_checkpoint_end(f, s->out.dir, s->step, s->prm.checkpoint_keep, s->last_checkpoint, sizeof s->last_checkpoint,
                      s->comm);
    s->last_checkpoint_step = s->step;
}

static void report_diff(const char *key, const char *va, const char *vb, void *ctx)
{
    (void)ctx;
    warn("  %s: %s in the checkpoint, %s now\n", key, va ? va : "(not set)", vb ? vb : "(not set)");
}

static void read_checkpoint(sim_t *s, const char *path)
{
    io_checkpoint_header_t h;
    hid_t f = io_checkpoint_open(path, &h, s->comm);
    if (h.nranks != mpi_size())
        warn("%s was written by %d ranks, this run has %d: the continuation agrees to round-off, not bit for bit\n",
             path, h.nranks, mpi_size());
    if (h.fingerprint != s->fingerprint) {
        warn("%s was written with a different input (fingerprint %016" PRIx64 ", now %016" PRIx64
             "); the keys that differ:\n",
             path, h.fingerprint, s->fingerprint);
        io_input_diff(h.input, s->input, sim_run_control_keys, report_diff, NULL);
    }
    s->time = h.time;
    s->step = h.step;
    if (io_h5_get_attr_double(f, "next_fields_time", &s->next_fields)) s->next_fields = s->time;
    for (int i = 0; i < s->npart; i++) {
        sim_part_t *p = &s->part[i];
        if (!p->checkpoint_read) continue;
        if (H5Lexists(f, p->name, H5P_DEFAULT) <= 0)
            die("%s: no /%s group: the checkpoint was written by a scene without this part", path, p->name);
        hid_t g = H5Gopen2(f, p->name, H5P_DEFAULT);
        p->checkpoint_read(p->ctx, g, path);
        H5Gclose(g);
    }
    io_checkpoint_header_free(&h);
    io_h5_close(f);
    msg("restarted from %s at step %ld, t = %.10g\n", path, s->step, s->time);
}

/* The FFTW wisdom the measuring planner made its plans from, as
 * DIR/fftw.wisdom: `--set poisson.fftw_wisdom=DIR/fftw.wisdom` makes the
 * same plans in another run (bit-identical results). */
static void write_fftw_wisdom(const sim_t *s)
{
    const char *w = poisson_fftw_wisdom_used();
    if (!w || mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 16];
    io_outdir_path(&s->out, "fftw.wisdom", path, sizeof path);
    FILE *f = fopen(path, "wb");
    size_t n = strlen(w);
    if (!f || fwrite(w, 1, n, f) != n || fclose(f) != 0) die_local("cannot write %s", path);
}

/* ---- setup ----------------------------------------------------------------- */

sim_t *sim_create(cfg_t *cfg, const char *restart, int check_only)
{
    sim_t *s = xcalloc(1, sizeof *s);
    s->cfg = cfg;
    s->comm = MPI_COMM_WORLD;
    s->check_only = check_only;
    read_params(s, cfg);
    /* known to the parts as they are built (the fluid's planner imports the
     * checkpoint's FFTW wisdom before it plans) */
    if (restart) snprintf(s->restart_path, sizeof s->restart_path, "%s", restart);

    /* Parts of the scene, in the order they advance, for its fluid model. */
    sim_build_scene(s, cfg);

    /* Everything has been read: the resolved input and its fingerprint. */
    s->input = io_resolved_input(cfg);
    s->fingerprint = io_input_fingerprint(s->input, sim_run_control_keys);
    s->next_fields = 0.0;
    s->last_fields_step = s->last_series_step = s->last_checkpoint_step = -1;
    if (check_only) return s;

    io_outdir_open(&s->out, s->prm.dir, restart != NULL, s->comm);
    io_outdir_write_input(&s->out, cfg);
    msg("ibmdem %s: case %s (%s) on %d rank%s, output in %s\n", IBMDEM_VERSION, s->prm.name, cfg_path(cfg),
        mpi_size(), mpi_size() > 1 ? "s" : "", s->prm.dir);
    write_fftw_wisdom(s);
    if (restart) read_checkpoint(s, restart);
    s->step0 = s->step;

    /* Time series: step, time, dt, the parts' columns, wall time per step. */
    const char *names[SIM_MAX_COLS];
    int nc = 0;
    names[nc++] = "step";
    names[nc++] = "time";
    names[nc++] = "dt";
    for (int i = 0; i < s->npart; i++)
        for (int c = 0; c < s->part[i].ncol && nc < SIM_MAX_COLS - 1; c++) names[nc++] = s->part[i].col_names[c];
    names[nc++] = "wall_per_step";
    char path[IO_PATH_MAX + 16];
    io_outdir_path(&s->out, "series.csv", path, sizeof path);
    s->series = io_series_open(path, nc, names, restart ? s->step : -1);
    s->summary = io_summary_create();
    return s;
}

/* ---- the steps of the loop ---------------------------------------------------- */

static double stable_dt(sim_t *s)
{
    double dt = INFINITY;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].stable_dt) dt = fmin(dt, s->part[i].stable_dt(s->part[i].ctx));
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].align_dt) dt = fmin(dt, s->part[i].align_dt(s->part[i].ctx, dt));
    /* Land on t_end: a last step shortened (or slightly stretched, by less
     * than 1e-9 dt) rather than a sliver of a step after it. */
    if (s->time + dt * (1.0 + 1e-9) >= s->prm.t_end) dt = s->prm.t_end - s->time;
    return dt;
}

static void advance(sim_t *s, double dt)
{
    if (s->prm.rollback)
        for (int i = 0; i < s->npart; i++)
            if (s->part[i].keep_previous) s->part[i].keep_previous(s->part[i].ctx);
    s->time_prev = s->time;
    s->step_prev = s->step;
    double w0 = wtime();
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].advance) s->part[i].advance(s->part[i].ctx, dt);
    s->wall_step = wtime() - w0;
    s->time += dt;
    s->step++;
    s->dt = dt;
}

/* One row of diagnostics: step, time, dt, the parts' columns, wall/step. */
static int diagnostics(sim_t *s, double *row)
{
    int nc = 0;
    row[nc++] = (double)s->step;
    row[nc++] = s->time;
    row[nc++] = s->dt;
    for (int i = 0; i < s->npart; i++) {
        if (s->part[i].diagnostics) s->part[i].diagnostics(s->part[i].ctx, row + nc);
        nc += s->part[i].ncol;
    }
    row[nc++] = s->wall_step;
    return nc;
}

/* Any part diverged?  The first reason found is kept in s->why. */
static int diverged(sim_t *s)
{
    for (int i = 0; i < s->npart; i++) {
        char why[400];
        if (s->part[i].diverged && s->part[i].diverged(s->part[i].ctx, why, sizeof why)) {
            snprintf(s->why, sizeof s->why, "%s: %s", s->part[i].name, why);
            return 1;
        }
    }
    return 0;
}

static double progress_fraction(const sim_t *s)
{
    double f = s->prm.t_end > 0 ? s->time / s->prm.t_end : 1.0;
    if (s->prm.max_steps > 0) f = fmax(f, (double)s->step / s->prm.max_steps);
    if (s->prm.wall_limit > 0) f = fmax(f, (wtime() - s->wall0) / s->prm.wall_limit);
    return f;
}

/* Why the run should stop now (SIM_RUNNING: it goes on).  The decision is
 * the same on every rank: it depends on replicated values only, except the
 * wall clock, which rank 0 decides. */
static sim_status_t stop_condition(sim_t *s)
{
    if (s->time >= s->prm.t_end) return SIM_T_END;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].done && s->part[i].done(s->part[i].ctx)) return SIM_DONE;
    if (s->prm.max_steps > 0 && s->step >= s->prm.max_steps) return SIM_MAX_STEPS;
    if (s->prm.steady_tol > 0 && s->step > s->step0) {
        double rate = 0.0;
        for (int i = 0; i < s->npart; i++)
            if (s->part[i].change_rate) rate = fmax(rate, s->part[i].change_rate(s->part[i].ctx, s->dt));
        if (rate < s->prm.steady_tol) return SIM_STEADY;
    }
    if (s->prm.wall_limit > 0) {
        int over = wtime() - s->wall0 > s->prm.wall_limit;
        MPI_Bcast(&over, 1, MPI_INT, 0, s->comm);
        if (over) return SIM_WALL_LIMIT;
    }
    return SIM_RUNNING;
}

static void write_fields(sim_t *s)
{
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].write_fields) s->part[i].write_fields(s->part[i].ctx, s->time, s->step);
    s->last_fields_step = s->step;
    /* next output time: the first multiple of fields_every after now (a
     * snapshot is written at the first step that reaches it; the step size
     * is never changed for an output, so outputs do not change the run) */
    if (s->prm.fields_every > 0)
        while (s->next_fields <= s->time * (1.0 + 1e-12)) s->next_fields += s->prm.fields_every;
    else
        s->next_fields = INFINITY;
}

static void write_series_row(sim_t *s)
{
    double row[SIM_MAX_COLS + 8];
    diagnostics(s, row);
    io_series_row(s->series, row);
    s->last_series_step = s->step;
}

/* The outputs due after this step. */
static void outputs(sim_t *s)
{
    if (s->step % s->prm.series_every == 0) write_series_row(s);
    if (s->time >= s->next_fields * (1.0 - 1e-12)) write_fields(s);
    if (s->prm.checkpoint_every > 0 && s->step % s->prm.checkpoint_every == 0) {
        io_progress_clear(&s->progress);
        write_checkpoint(s);
    }
    /* a line in the log every 10 % of the run (the terminal has the progress line) */
    double frac = progress_fraction(s);
    if (frac >= s->next_report) {
        double row[SIM_MAX_COLS + 8];
        diagnostics(s, row);
        io_progress_clear(&s->progress);
        msg("  step %8ld  t = %-11.6g dt = %-10.4g (%3.0f %%)\n", s->step, s->time, s->dt, 100 * fmin(frac, 1.0));
        while (s->next_report <= frac) s->next_report += 0.1;
    }
    io_progress_update(&s->progress, s->time, s->step, frac);
}

static void write_summary(sim_t *s)
{
    static const char *status_name[] = {"running", "t_end", "max_steps", "wall_limit", "steady", "diverged", "done"};
    io_summary_t *y = s->summary;
    double wall = wtime() - s->wall0;
    io_summary_string(y, "case", s->prm.name);
    io_summary_string(y, "input", cfg_path(s->cfg));
    io_summary_string(y, "status", status_name[s->status]);
    if (s->status == SIM_DIVERGED) io_summary_string(y, "reason", s->why);
    io_summary_string(y, "ibmdem_version", IBMDEM_VERSION);
    io_summary_long(y, "ranks", mpi_size());
    io_summary_long(y, "steps", s->step);
    io_summary_long(y, "steps_this_run", s->step - s->step0);
    io_summary_double(y, "time", s->time);
    io_summary_double(y, "last_dt", s->dt);
    io_summary_double(y, "wall_time", wall);
    io_summary_double(y, "steps_per_second", wall > 0 ? (s->step - s->step0) / wall : 0.0);
    io_summary_long(y, "peak_rss_bytes_rank0", peak_rss_bytes());
    if (s->restart_path[0]) io_summary_string(y, "restarted_from", s->restart_path);
    if (s->last_checkpoint[0]) io_summary_string(y, "checkpoint", s->last_checkpoint);
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].summary) s->part[i].summary(s->part[i].ctx, y, s->part[i].name);
    char path[IO_PATH_MAX + 16];
    io_outdir_path(&s->out, "summary.json", path, sizeof path);
    if (io_summary_write(y, path)) warn("cannot write %s\n", path);
}

/* The run diverged: bring back the state at the start of the failed step,
 * checkpoint it, and say how to go on. */
static int stop_diverged(sim_t *s)
{
    long bad_step = s->step;
    double bad_time = s->time;
    io_progress_clear(&s->progress);
    write_series_row(s); /* the failed step, as it came out */
    int restored = s->prm.rollback;
    for (int i = 0; i < s->npart && restored; i++) restored = s->part[i].restore_previous != NULL;
    if (restored) {
        for (int i = 0; i < s->npart; i++) s->part[i].restore_previous(s->part[i].ctx);
        s->time = s->time_prev;
        s->step = s->step_prev;
    }
    write_checkpoint(s);
    s->status = SIM_DIVERGED;
    write_summary(s);
    char text[4 * IO_PATH_MAX];
    snprintf(text, sizeof text,
             "the run diverged at step %ld (t = %.10g, dt = %.6g): %s\n"
             "  the state %s (step %ld, t = %.10g) is saved in %s\n"
             "  continue from it with a smaller time step: ibmdem run %s --restart %s --set ...\n",
             bad_step, bad_time, s->dt, s->why, restored ? "at the start of that step" : "after that step", s->step,
             s->time, s->last_checkpoint, cfg_path(s->cfg), s->last_checkpoint);
    if (mpi_rank() == 0) {
        fprintf(stderr, "error: %s", text);
        if (s->out.log) fprintf(s->out.log, "error: %s", text);
    }
    return 3;
}

/* ---- the time loop ------------------------------------------------------------ */

int sim_run(sim_t *s)
{
    s->wall0 = wtime();
    s->next_report = 0.1 * floor(10 * progress_fraction(s)) + 0.1;
    io_progress_start(&s->progress, progress_fraction(s), s->step, s->prm.progress);
    if (s->restart_path[0] == 0) {
        /* the initial state */
        write_series_row(s);
        write_fields(s);
    }
    for (;;) {
        s->status = stop_condition(s);
        if (s->status != SIM_RUNNING) break;
        /* 1. the time step: the most restrictive limit of every part
         *    (fluid: fluid_stable_dt, convective CFL and explicit viscous limit) */
        double dt = stable_dt(s);
        /* 2. advance every part by dt (fluid: fluid_step, three RK3 stages,
         *    each projected to a divergence-free velocity) */
        advance(s, dt);
        if (s->step == s->step0 + 1) sim_note_unused(s); /* every part has read its keys */
        /* 3. diagnostics and checks; a diverged run stops with a checkpoint */
        if (diverged(s)) return stop_diverged(s);
        /* 4. the outputs due at this step */
        outputs(s);
    }
    /* The end: last series row, snapshot and checkpoint, then the summary. */
    io_progress_clear(&s->progress);
    if (s->last_series_step != s->step) write_series_row(s);
    if (s->last_fields_step != s->step) write_fields(s);
    /* a scene whose parts have no state (a fixed packing solved once) has nothing to restart from */
    int state = 0;
    for (int i = 0; i < s->npart; i++) state |= s->part[i].checkpoint_write != NULL;
    if (s->last_checkpoint_step != s->step && state) write_checkpoint(s);
    write_summary(s);
    static const char *why[] = {"", "reached t_end", "reached max_steps", "reached the wall-time limit",
                                "reached a steady state", "", "has what it was run for (a part is done)"};
    double wall = wtime() - s->wall0;
    msg("%s: %s at step %ld, t = %.10g (%ld steps in %.3g s, %.4g steps/s); checkpoint %s\n", s->prm.name,
        why[s->status], s->step, s->time, s->step - s->step0, wall, wall > 0 ? (s->step - s->step0) / wall : 0.0,
        s->last_checkpoint[0] ? s->last_checkpoint : "none (no part has a state to restart from)");
    return 0;
}

void sim_free(sim_t *s)
{
    if (!s) return;
    /* in reverse order of creation: a part may use an earlier one (the
     * immersed boundary holds the fluid) */
    for (int i = s->npart - 1; i >= 0; i--)
        if (s->part[i].destroy) s->part[i].destroy(s->part[i].ctx);
    io_series_close(s->series);
    io_summary_free(s->summary);
    if (!s->check_only) io_outdir_close(&s->out);
    free(s->input);
    free(s);
}
