/* sim_checkpoint.c — the run's checkpoints: written from every part's
 * state with the series.csv position they match, read back on a restart
 * (the input compared with the run's), and the FFTW wisdom file (sim.c). */
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "coupling.h"
#include "poisson.h"
#include "sim.h"
#include "sim_internal.h"
#include "util.h"

/* The step of the last series row at or before `step` (the row a checkpoint
 * of that step follows: a diverged run checkpoints the step before its last
 * row). */
static long series_row_before(const sim_t *s, long step)
{
    return s->last_series_step <= step ? s->last_series_step : s->prev_series_step;
}

/* What to say if the run must stop at once (a failed collective write). */
static void note_checkpoint(const sim_t *s, const char *path)
{
    char text[IO_PATH_MAX + 64];
    snprintf(text, sizeof text, "the newest checkpoint is %s", path);
    io_recovery_note(text);
}

/* Write a checkpoint of the current state.  The time series and the log are
 * made durable (fsync) first, and the checkpoint is renamed to its final name
 * only when complete: whenever a checkpoint exists, the outputs it refers to
 * do too.  Returns 0, or -1 on every rank after an I/O error (the previous
 * checkpoint is then still the newest). */
int sim_write_checkpoint(sim_t *s)
{
    if (mpi_rank() == 0) {
        io_series_sync_all();
        msg_sync_log();
    }
    io_checkpoint_header_t h = {s->time, s->step, s->fingerprint, mpi_size(), s->input};
    hid_t f = io_checkpoint_begin(s->out.dir, &h, s->comm);
    io_h5_attr_double(f, "next_fields_time", s->next_fields);
    io_h5_attr_long(f, "series_last_step", series_row_before(s, s->step));
    io_h5_attr_hash(f, "series_hash", io_series_hash(s->series, s->step), s->comm);
    io_h5_attr_long(f, "fields_last_step", s->last_fields_step);
    io_h5_attr_double(f, "last_dt", s->dt);
    io_h5_attr_long(f, "rejected_steps", s->rejected_steps);
    for (int i = 0; i < s->npart; i++) {
        sim_part_t *p = &s->part[i];
        if (!p->checkpoint_write) continue;
        hid_t g = H5Gcreate2(f, p->name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        p->checkpoint_write(p->ctx, g);
        H5Gclose(g);
    }
    if (io_checkpoint_end(f, s->out.dir, s->step, s->prm.checkpoint_keep, s->last_checkpoint,
                          sizeof s->last_checkpoint, s->comm))
        return -1;
    s->last_checkpoint_step = s->step;
    note_checkpoint(s, s->last_checkpoint);
    return 0;
}

/* Rank 0 decides: do two paths name the same file? */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    int same = stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    MPI_Bcast(&same, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return same;
}

static void report_diff(const char *key, const char *va, const char *vb, void *ctx)
{
    (void)ctx;
    warn("  %s: %s in the checkpoint, %s now\n", key, va ? va : "(not set)", vb ? vb : "(not set)");
}

void sim_read_checkpoint(sim_t *s, const char *path)
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
    s->series_resume.step = s->step;
    if (io_h5_get_attr_long(f, "series_last_step", &s->series_resume.last_row)) s->series_resume.last_row = -1;
    s->series_resume.has_hash = io_h5_get_attr_hash(f, "series_hash", &s->series_resume.hash) == 0;
    if (io_h5_get_attr_long(f, "fields_last_step", &s->last_fields_step)) s->last_fields_step = -1;
    if (io_h5_get_attr_double(f, "last_dt", &s->dt)) s->dt = 0;
    if (io_h5_get_attr_long(f, "rejected_steps", &s->rejected_steps)) s->rejected_steps = 0;
    /* the folder's own checkpoint of this step: not written again at the end */
    char own[IO_PATH_MAX + 64];
    snprintf(own, sizeof own, "%s/checkpoint_%08ld.h5", s->out.dir, s->step);
    if (same_file(own, path)) {
        snprintf(s->last_checkpoint, sizeof s->last_checkpoint, "%s", own);
        s->last_checkpoint_step = s->step;
    }
    /* what the lost continuation of this checkpoint wrote in the folder: its
     * checkpoints (else they would be kept as the newest and ours pruned; the
     * unfinished ones went when the folder was opened); the parts delete
     * their own snapshots after theirs */
    io_outdir_remove_numbered(&s->out, "checkpoint_", ".h5", s->step + 1);
    io_checkpoint_prune(s->out.dir, s->prm.checkpoint_keep); /* a run killed before it pruned */
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
    note_checkpoint(s, path);
    msg("restarted from %s at step %ld, t = %.10g\n", path, s->step, s->time);
}

/* The FFTW wisdom the measuring planner made its plans from, as
 * DIR/fftw.wisdom: `--set poisson.fftw_wisdom=DIR/fftw.wisdom` makes the
 * same plans in another run (bit-identical results). */
void sim_write_fftw_wisdom(const sim_t *s)
{
    const char *w = poisson_fftw_wisdom_used();
    if (!w || mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 16], tmp[IO_PATH_MAX + 32];
    io_outdir_path(&s->out, "fftw.wisdom", path, sizeof path);
    FILE *f = atomic_open(path, tmp, sizeof tmp);
    if (!f) return;
    fputs(w, f);
    atomic_commit(f, tmp, path);
}
