/* sim.c — the run driver (see sim.h): the time loop, the stop conditions,
 * the divergence checks and the schedule of the outputs.  The physics lives
 * in the parts (sim_fluid.c, ...); the driver's keys are read in
 * sim_params.c, its checkpoints written and read in sim_checkpoint.c. */
#include "coupling.h"
#include "poisson.h"
#include "sim.h"

#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sim_internal.h"
#include "util.h"

void sim_add_part(sim_t *s, const sim_part_t *part)
{
    if (s->npart == SIM_MAX_PARTS) die("too many parts in the scene (SIM_MAX_PARTS = %d)", SIM_MAX_PARTS);
    s->part[s->npart++] = *part;
}

void sim_add_output_name(sim_t *s, const char *name)
{
    if (s->noutput_names == SIM_MAX_PARTS) die("too many output names (SIM_MAX_PARTS = %d)", SIM_MAX_PARTS);
    s->output_names[s->noutput_names++] = name;
}

void sim_add_field_writer(sim_t *s, sim_field_writer_t fn, void *ctx)
{
    if (s->nfield_writers == SIM_MAX_PARTS) die("too many snapshot field writers (SIM_MAX_PARTS = %d)", SIM_MAX_PARTS);
    s->field_writer[s->nfield_writers] = fn;
    s->field_writer_ctx[s->nfield_writers++] = ctx;
}

/* ---- setup ----------------------------------------------------------------- */

sim_t *sim_create(cfg_t *cfg, const char *restart, int check_only)
{
    sim_t *s = xcalloc(1, sizeof *s);
    s->cfg = cfg;
    s->comm = MPI_COMM_WORLD;
    s->check_only = check_only;
    sim_read_params(s, cfg);
    /* known to the parts as they are built (the fluid's planner imports the
     * checkpoint's FFTW wisdom before it plans) */
    if (restart) snprintf(s->restart_path, sizeof s->restart_path, "%s", restart);

    /* Parts of the scene, in the order they advance, for its fluid model. */
    sim_build_scene(s, cfg);

    /* Everything has been read: the resolved input and its fingerprint. */
    s->input = io_resolved_input(cfg);
    s->fingerprint = io_input_fingerprint(s->input, sim_run_control_keys);
    s->next_fields = 0.0;
    s->last_fields_step = s->last_series_step = s->prev_series_step = s->last_checkpoint_step = -1;
    if (check_only) return s;

    char why[IO_PATH_MAX + 1024];
    s->output_names[s->noutput_names] = NULL;
    const int rc = io_outdir_open(&s->out, s->prm.dir, restart != NULL, s->prm.overwrite, s->output_names, why,
                                  sizeof why, s->comm);
    if (rc == 2) cfg_fail(cfg, "output", "dir", "%s: %s", s->prm.dir, why);
    if (rc) die("output folder %s: %s", s->prm.dir, why);
    io_outdir_write_input(&s->out, cfg);
    msg("ibmdem %s: case %s (%s) on %d rank%s, output in %s\n", IBMDEM_VERSION, s->prm.name, cfg_path(cfg),
        mpi_size(), mpi_size() > 1 ? "s" : "", s->prm.dir);
    sim_write_fftw_wisdom(s);
    if (restart) sim_read_checkpoint(s, restart);
    s->step0 = s->step;

    /* Time series: step, time, dt, the parts' columns, wall time per step. */
    const char *names[SIM_MAX_COLS];
    int nc = 0;
    names[nc++] = "step";
    names[nc++] = "time";
    names[nc++] = "dt";
    int ncol = 4;
    for (int i = 0; i < s->npart; i++) ncol += s->part[i].ncol;
    if (ncol > SIM_MAX_COLS) die("series.csv would have %d columns, more than SIM_MAX_COLS = %d", ncol, SIM_MAX_COLS);
    for (int i = 0; i < s->npart; i++)
        for (int c = 0; c < s->part[i].ncol; c++) names[nc++] = s->part[i].col_names[c];
    names[nc++] = "wall_per_step";
    char path[IO_PATH_MAX + 16];
    io_outdir_path(&s->out, "series.csv", path, sizeof path);
    s->series = io_series_open(path, nc, names, restart ? &s->series_resume : NULL);
    long last_row = io_series_last_step(s->series); /* rank 0's file */
    MPI_Bcast(&last_row, 1, MPI_LONG, 0, s->comm);
    s->last_series_step = s->prev_series_step = last_row;
    s->summary = io_summary_create();
    return s;
}

/* ---- the steps of the loop ---------------------------------------------------- */

static double stable_dt(sim_t *s)
{
    double dt = INFINITY;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].stable_dt) {
            const double l = s->part[i].stable_dt(s->part[i].ctx);
            if (!(l > 0)) return l; /* zero, negative or not a number: no step (sim_run stops) */
            dt = fmin(dt, l);
        }
    if (s->dt_cap > 0) dt = fmin(dt, s->dt_cap); /* a step taken again after it diverged */
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
    const double w0 = wtime();
    double wp = w0;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].advance) {
            s->part[i].advance(s->part[i].ctx, dt);
            const double w = wtime();
            s->part_wall[i] += w - wp;
            wp = w;
        }
    s->wall_step = wtime() - w0;
    s->time += dt;
    s->step++;
    s->dt_prev = s->dt;
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
    s->retry_ok = 0;
    if (fault_armed("diverge", s->step)) { /* a test: a divergence at a chosen step */
        snprintf(s->why, sizeof s->why, "%s: divergence injected by IBMDEM_FAULT", s->part[s->npart - 1].name);
        return 1;
    }
    if (fault_armed("diverge_retry", s->step)) { /* a test: one that a smaller step cures */
        snprintf(s->why, sizeof s->why, "%s: divergence injected by IBMDEM_FAULT (a smaller step cures it)",
                 s->part[s->npart - 1].name);
        s->retry_ok = 1;
        return 1;
    }
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
    for (int i = 0; i < s->npart; i++) {
        char why[400];
        if (s->part[i].halt && s->part[i].halt(s->part[i].ctx, why, sizeof why)) {
            snprintf(s->why, sizeof s->why, "%s: %s", s->part[i].name, why);
            return SIM_HALTED;
        }
    }
    if (s->time >= s->prm.t_end) return SIM_T_END;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].done && s->part[i].done(s->part[i].ctx)) return SIM_DONE;
    if (s->prm.max_steps > 0 && s->step >= s->prm.max_steps) return SIM_MAX_STEPS;
    /* (not after a retried step: the state is the one restored at the start of the failed
     * step, which the change rate would compare with its own copy) */
    if (s->prm.steady_tol > 0 && s->step > s->step0 && s->retries == 0) {
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
    s->prev_series_step = s->last_series_step;
    s->last_series_step = s->step;
}

/* The outputs due after this step.  Returns -1 (every rank) after an I/O
 * error: a write failed somewhere (io_check_errors). */
static int outputs_due(sim_t *s)
{
    if (s->step % s->prm.series_every == 0) write_series_row(s);
    if (s->time >= s->next_fields * (1.0 - 1e-12)) write_fields(s);
    if (s->prm.checkpoint_every > 0 && s->step % s->prm.checkpoint_every == 0) {
        io_progress_clear(&s->progress);
        if (sim_write_checkpoint(s)) return -1;
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
    return io_check_errors(s->comm, s->io_why, sizeof s->io_why) ? -1 : 0;
}

/* The outputs, timed (summary.json "cost"). */
static int outputs(sim_t *s)
{
    const double w0 = wtime();
    const int rc = outputs_due(s);
    s->output_wall += wtime() - w0;
    return rc;
}

static void write_summary(sim_t *s)
{
    static const char *status_name[] = {"running", "t_end",    "max_steps", "wall_limit",
                                        "steady",  "diverged", "done",      "halted", "io_error"};
    io_summary_t *y = s->summary;
    double wall = wtime() - s->wall0;
    io_summary_string(y, "case", s->prm.name);
    io_summary_string(y, "input", cfg_path(s->cfg));
    io_summary_string(y, "status", status_name[s->status]);
    if (s->status == SIM_DIVERGED || s->status == SIM_HALTED) io_summary_string(y, "reason", s->why);
    if (s->status == SIM_IO_ERROR) io_summary_string(y, "reason", s->io_why);
    io_summary_string(y, "ibmdem_version", IBMDEM_VERSION);
    io_summary_long(y, "ranks", mpi_size());
    io_summary_long(y, "steps", s->step);
    io_summary_long(y, "steps_this_run", s->step - s->step0);
    io_summary_long(y, "rejected_steps", s->rejected_steps);
    io_summary_double(y, "time", s->time);
    io_summary_double(y, "last_dt", s->dt);
    io_summary_double(y, "wall_time", wall);
    io_summary_double(y, "steps_per_second", wall > 0 ? (s->step - s->step0) / wall : 0.0);
    io_summary_long(y, "peak_rss_bytes_rank0", peak_rss_bytes());
    if (s->restart_path[0]) io_summary_string(y, "restarted_from", s->restart_path);
    /* the wall time of this run in each part's advance and in the outputs (rank 0) */
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].advance) {
            char key[96];
            snprintf(key, sizeof key, "cost.%s_seconds", s->part[i].name);
            io_summary_double(y, key, s->part_wall[i]);
        }
    io_summary_double(y, "cost.output_seconds", s->output_wall);
    if (s->last_checkpoint[0]) io_summary_string(y, "checkpoint", s->last_checkpoint);
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].summary) s->part[i].summary(s->part[i].ctx, y, s->part[i].name);
    char path[IO_PATH_MAX + 16];
    io_outdir_path(&s->out, "summary.json", path, sizeof path);
    io_summary_write(y, path);
}

/* Rank 0: an error message on stderr and in the log. */
static void report_error(const sim_t *s, const char *text)
{
    if (mpi_rank() != 0) return;
    fprintf(stderr, "error: %s", text);
    if (s->out.log) {
        fprintf(s->out.log, "error: %s", text);
        msg_sync_log();
    }
}

/* A write failed (s->io_why): checkpoint the state if it can be, and say how
 * to go on.  Returns the exit status 1. */
static int stop_io_error(sim_t *s)
{
    io_progress_clear(&s->progress);
    s->status = SIM_IO_ERROR;
    int saved = s->last_checkpoint_step == s->step;
    if (!saved) {
        /* the error is known: see whether a checkpoint can still be written (another file system, room freed) */
        io_error_clear();
        saved = sim_write_checkpoint(s) == 0;
    }
    io_error_clear();
    write_summary(s);
    char text[6 * IO_PATH_MAX], cmd[3 * IO_PATH_MAX];
    int len = snprintf(text, sizeof text, "%s\n", s->io_why);
    if (s->last_checkpoint[0] || s->restart_path[0]) {
        const char *ckpt = s->last_checkpoint[0] ? s->last_checkpoint : s->restart_path;
        sim_restart_command(s, ckpt, cmd, sizeof cmd);
        snprintf(text + len, sizeof text - len,
                 "  %s %s\n  once the disk has room, continue with:\n    %s\n",
                 saved ? "the state at this step is saved in" : "no checkpoint could be written; the newest is", ckpt,
                 cmd);
    } else {
        snprintf(text + len, sizeof text - len, "  no checkpoint could be written\n");
    }
    report_error(s, text);
    return 1;
}

/* The step just taken diverged: can it be taken again with half its time
 * step?  Only when the part that diverged says a smaller step may cure it (the
 * fluid with an adaptive step: a CFL number or a kinetic-energy jump beyond
 * the limits when the grains' velocities changed faster than the step
 * followed).  Every part brings back its state at the start of the step, the
 * next time step is capped at half the failed one, and the retry is logged.
 * A run without rollback, a part that cannot restore its state, a fixed time
 * step, an injected fault or the last allowed retry stop the run
 * (stop_diverged). */
static int retry_step(sim_t *s)
{
    if (!s->prm.rollback || !s->retry_ok || s->retries >= s->prm.step_retries) return 0;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].restore_previous == NULL && s->part[i].checkpoint_write != NULL) return 0;
    const double bad_dt = s->dt;
    for (int i = 0; i < s->npart; i++)
        if (s->part[i].restore_previous) s->part[i].restore_previous(s->part[i].ctx);
    s->time = s->time_prev;
    s->step = s->step_prev;
    s->dt = s->dt_prev;
    s->dt_cap = 0.5 * bad_dt;
    s->retries++;
    s->rejected_steps++;
    io_progress_clear(&s->progress);
    msg("step %ld (t = %.10g, dt = %.6g) diverged: %s; taken again with dt <= %.6g (retry %d of %d)\n",
        s->step + 1, s->time, bad_dt, s->why, s->dt_cap, s->retries, s->prm.step_retries);
    return 1;
}

/* The run diverged: bring back the state at the start of the failed step,
 * checkpoint it, and say how to go on. */
static int stop_diverged(sim_t *s)
{
    long bad_step = s->step;
    double bad_time = s->time, bad_dt = s->dt;
    io_progress_clear(&s->progress);
    write_series_row(s); /* the failed step, as it came out */
    /* every part with a state must be able to bring it back */
    int restored = s->prm.rollback;
    for (int i = 0; i < s->npart && restored; i++)
        restored = s->part[i].restore_previous != NULL || s->part[i].checkpoint_write == NULL;
    if (restored) {
        for (int i = 0; i < s->npart; i++)
            if (s->part[i].restore_previous) s->part[i].restore_previous(s->part[i].ctx);
        s->time = s->time_prev;
        s->step = s->step_prev;
        s->dt = s->dt_prev;
    }
    if (sim_write_checkpoint(s) != 0) {
        io_check_errors(s->comm, s->io_why, sizeof s->io_why);
        char text[2 * IO_PATH_MAX];
        snprintf(text, sizeof text, "the run diverged at step %ld (t = %.10g): %s\n", bad_step, bad_time, s->why);
        report_error(s, text);
        return stop_io_error(s);
    }
    s->status = SIM_DIVERGED;
    write_summary(s);
    char text[6 * IO_PATH_MAX], cmd[3 * IO_PATH_MAX], hint[128];
    sim_restart_command(s, s->last_checkpoint, cmd, sizeof cmd);
    sim_smaller_step_hint(s, hint, sizeof hint);
    snprintf(text, sizeof text,
             "the run diverged at step %ld (t = %.10g, dt = %.6g): %s\n"
             "  the state %s (step %ld, t = %.10g) is saved in %s\n"
             "  continue from it with a smaller time step, e.g.:\n    %s %s\n",
             bad_step, bad_time, bad_dt, s->why, restored ? "at the start of that step" : "after that step", s->step,
             s->time, s->last_checkpoint, cmd, hint);
    report_error(s, text);
    return 3;
}

/* No step can be taken: the time step the parts allow is zero, not a number,
 * or too small to change the time.  The run stops as diverged, with a
 * checkpoint of the state it is in (nothing was advanced). */
static int stop_no_step(sim_t *s, double dt)
{
    const char *who = "the run driver";
    double least = INFINITY;
    for (int i = 0; i < s->npart; i++) {
        const double l = s->part[i].stable_dt ? s->part[i].stable_dt(s->part[i].ctx) : INFINITY;
        if (!(l >= least)) { /* the smallest limit, or the first that is not a number */
            least = l;
            who = s->part[i].name;
            if (isnan(l)) break;
        }
    }
    snprintf(s->why, sizeof s->why, "the time step is %g (limit of %s): the state cannot advance from t = %.10g", dt,
             who, s->time);
    io_progress_clear(&s->progress);
    if (s->last_series_step != s->step) write_series_row(s);
    char text[2 * IO_PATH_MAX];
    snprintf(text, sizeof text, "the run cannot go on at step %ld: %s\n", s->step, s->why);
    if (s->last_checkpoint_step != s->step && sim_write_checkpoint(s) != 0) {
        io_check_errors(s->comm, s->io_why, sizeof s->io_why);
        report_error(s, text);
        return stop_io_error(s);
    }
    s->status = SIM_DIVERGED;
    write_summary(s);
    const size_t len = strlen(text);
    snprintf(text + len, sizeof text - len, "  the state (step %ld, t = %.10g) is saved in %s\n", s->step, s->time,
             s->last_checkpoint);
    report_error(s, text);
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
        if (!(dt > 0) || !isfinite(dt) || s->time + dt == s->time) return stop_no_step(s, dt);
        /* 2. advance every part by dt (fluid: fluid_step, three RK3 stages,
         *    each projected to a divergence-free velocity) */
        advance(s, dt);
        if (s->step == s->step0 + 1) sim_note_unused(s); /* every part has read its keys */
        /* 3. diagnostics and checks; a diverged step is taken again with half
         *    its time step (time.step_retries), else the run stops with a checkpoint */
        if (diverged(s)) {
            if (retry_step(s)) continue;
            return stop_diverged(s);
        }
        s->dt_cap = 0;
        s->retries = 0;
        /* 4. the outputs due at this step; a failed write stops the run */
        if (outputs(s)) return stop_io_error(s);
    }
    /* The end: last series row, snapshot and checkpoint, then the summary. */
    io_progress_clear(&s->progress);
    if (s->last_series_step != s->step) write_series_row(s);
    if (s->last_fields_step != s->step) write_fields(s);
    /* a scene whose parts have no state (a fixed packing solved once) has nothing to restart from */
    int state = 0;
    for (int i = 0; i < s->npart; i++) state |= s->part[i].checkpoint_write != NULL;
    if (s->last_checkpoint_step != s->step && state && sim_write_checkpoint(s) != 0) {
        io_check_errors(s->comm, s->io_why, sizeof s->io_why);
        return stop_io_error(s);
    }
    write_summary(s);
    if (s->status == SIM_HALTED) {
        if (mpi_rank() == 0) io_series_sync_all();
        char text[2 * IO_PATH_MAX];
        snprintf(text, sizeof text, "the run stopped at step %ld (t = %.10g): %s\n  its state is saved in %s\n",
                 s->step, s->time, s->why, s->last_checkpoint);
        report_error(s, text);
        if (io_check_errors(s->comm, s->io_why, sizeof s->io_why)) return stop_io_error(s);
        return 1;
    }
    static const char *why[] = {"", "reached t_end", "reached max_steps", "reached the wall-time limit",
                                "reached a steady state", "", "has what it was run for (a part is done)"};
    double wall = wtime() - s->wall0;
    msg("%s: %s at step %ld, t = %.10g (%ld steps in %.3g s, %.4g steps/s); checkpoint %s\n", s->prm.name,
        why[s->status], s->step, s->time, s->step - s->step0, wall, wall > 0 ? (s->step - s->step0) / wall : 0.0,
        s->last_checkpoint[0] ? s->last_checkpoint : "none (no part has a state to restart from)");
    /* everything written is on the disk, or the run says it is not */
    if (mpi_rank() == 0) {
        io_series_sync_all();
        msg_sync_log();
    }
    if (io_check_errors(s->comm, s->io_why, sizeof s->io_why)) {
        char text[3 * IO_PATH_MAX];
        snprintf(text, sizeof text, "%s\n  the state at the end is saved in %s\n", s->io_why, s->last_checkpoint);
        report_error(s, text);
        return 1;
    }
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
    free(s->command);
    free(s);
}
