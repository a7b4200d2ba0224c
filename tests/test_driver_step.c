/* test_driver_step.c — the run driver never takes a step it cannot take: a
 * part whose time-step limit is zero, not a number, or too small to change
 * the time stops the run as diverged (status 3) with a checkpoint of the
 * state it is in, and the fluid is never advanced by such a step.
 * RANKS: 1 2
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "config.h"
#include "modules.h"
#include "sim.h"
#include "testutil.h"
#include "util.h"

static double limit;  /* what the test part gives as its largest stable step */
static int first_free; /* ... after the first step only (the first one is the fluid's) */
static double part_dt(void *ctx)
{
    const sim_t *s = ctx;
    return first_free && s->step == 0 ? INFINITY : limit;
}

/* A small cavity with one more part (no state, only a time-step limit);
 * returns the run's exit status (negative if the checkpoint it names is
 * missing), the step it stopped at and the status in summary.json. */
static int run_with_limit(double lim, const char *name, long *step, char *status, size_t nstatus)
{
    char dir[256], set[300];
    snprintf(dir, sizeof dir, "/tmp/ibmdem_driver_step_%s_%d", name, mpi_size());
    snprintf(set, sizeof set, "output.dir=%s", dir);
    char *sets[] = {set, "output.progress=off", "output.overwrite=true"}; /* the folder of the last make test */
    cfg_t *cfg = cfg_load_string("step.ini",
                                 "[domain]\ngeometry = 2d\nnx = 8\nny = 8\nlength = 1 1 1\n[boundary]\n"
                                 "x_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\ny_hi_velocity = 1 0 0\n"
                                 "[fluid]\nnu = 0.01\n[time]\nt_end = 0.1\n",
                                 3, sets);
    assert_non_null(cfg);
    sim_t *s = sim_create(cfg, NULL, 0);
    limit = lim;
    sim_part_t p = {.name = "limiter", .ctx = s, .stable_dt = part_dt};
    sim_add_part(s, &p);
    const int rc = sim_run(s);
    *step = s->step;
    char path[300];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    MPI_Barrier(MPI_COMM_WORLD);
    FILE *f = mpi_rank() == 0 ? fopen(path, "r") : NULL;
    memset(status, 0, 64);
    if (f) {
        char buf[4096];
        size_t n = fread(buf, 1, sizeof buf - 1, f);
        buf[n] = 0;
        fclose(f);
        const char *k = strstr(buf, "\"status\": \"");
        if (k) sscanf(k + 11, "%63[^\"]", status);
    }
    (void)nstatus;
    int have_checkpoint = access(s->last_checkpoint, R_OK) == 0;
    sim_free(s);
    cfg_free(cfg);
    /* rank 0 wrote and read the files: every rank takes its answer (testutil.h) */
    MPI_Bcast(&have_checkpoint, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Bcast(status, 64, MPI_CHAR, 0, MPI_COMM_WORLD);
    return have_checkpoint ? rc : -rc - 100;
}

static void test_no_step(void **state)
{
    (void)state;
    /* from the start: zero, negative, not a number; after the first step
     * (the fluid's, t = 0.0625): 1e-30, which does not change t */
    static const struct {
        double lim;
        int after_first;
        const char *name;
    } c[] = {{0.0, 0, "zero"}, {-1.0, 0, "negative"}, {NAN, 0, "nan"}, {1e-30, 1, "no_change"}};
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
        long step = -1;
        char status[64];
        first_free = c[k].after_first;
        const int rc = run_with_limit(c[k].lim, c[k].name, &step, status, sizeof status);
        print_message("  limit %g: status %d, stopped at step %ld, summary status %s\n", c[k].lim, rc, step, status);
        assert_int_equal(rc, 3);
        assert_string_equal(status, "diverged");
        assert_int_equal(step, c[k].after_first);
    }
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_no_step)};
    TEST_MPI_RUN("driver_step", tests);
}
