/* test_dem_diagnostics.c — a bad scene stops with a clear message (and, in a
 * run, a checkpoint): overlap above dem.max_overlap, a particle leaving the
 * domain, a time step too large for the contact time, bad case-file keys.
 * RANKS: 1 2
 */
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dem.h"
#include "modules.h"
#include "testutil.h"
#include "util.h"

static jmp_buf jb;
static char last_msg[1024];

static void hook(const char *m)
{
    snprintf(last_msg, sizeof last_msg, "%s", m);
    longjmp(jb, 1);
}

static const char *BOX = "[domain]\nlength = 0.02 0.02 0.02\n[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\n"
                         "y_hi = noslip\nz_lo = noslip\nz_hi = noslip\n";

static dem_t *make(const char *extra)
{
    char text[2048];
    snprintf(text, sizeof text, "%s%s", BOX, extra);
    cfg_t *cfg = cfg_load_string("diag.ini", text, 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    cfg_free(cfg);
    return d;
}

static void test_overlap(void **state)
{
    /* soft contacts (t_c = 1 ms) and a fast impact: δ ≈ v t_c/π ≫ 1 % of d */
    dem_t *d = make("[walls]\nfaces = none\n[contact]\nrestitution = 0.5\ncontact_time = 1e-3\nfriction = 0.5\n"
                    "[dem]\ngravity = 0 0 0\n");
    const double xa[3] = {0.008, 0.01, 0.01}, xb[3] = {0.012, 0.01, 0.01}, va[3] = {1, 0, 0}, vb[3] = {-1, 0, 0};
    dem_add_particle(d, xa, va, 1e-3, 2500, 0);
    dem_add_particle(d, xb, vb, 1e-3, 2500, 0);
    dem_status_t st = DEM_OK;
    for (int s = 0; s < 2000 && st == DEM_OK; s++) st = dem_step(d);
    printf("  %s\n", dem_error(d));
    assert_int_equal(st, DEM_ERR_OVERLAP);
    assert_non_null(strstr(dem_error(d), "overlap"));
    dem_free(d);
}

static void test_left_domain(void **state)
{
    dem_t *d = make("[walls]\nfaces = none\n[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\n"
                    "[dem]\ngravity = 0 0 -9.81\n");
    const double x[3] = {0.01, 0.01, 0.002}, v[3] = {0, 0, -1};
    dem_add_particle(d, x, v, 1e-3, 2500, 0);
    dem_status_t st = DEM_OK;
    for (int s = 0; s < 5000 && st == DEM_OK; s++) st = dem_step(d);
    printf("  %s\n", dem_error(d));
    assert_int_equal(st, DEM_ERR_LEFT_DOMAIN);
    assert_non_null(strstr(dem_error(d), "z low face"));
    dem_free(d);
}

static void test_timestep(void **state)
{
    /* known at input time (linear law, restitution and t_c): file:line message */
    char text[2048];
    snprintf(text, sizeof text, "%s[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\n[dem]\ndt = 1e-5\n",
             BOX);
    cfg_t *cfg = cfg_load_string("diag.ini", text, 0, NULL);
    assert_non_null(cfg);
    cfg_set_error_hook(hook);
    if (setjmp(jb) == 0) {
        dem_create_from_config(cfg, MPI_COMM_WORLD);
        fail_msg("a time step of t_c/10 was accepted");
    }
    cfg_set_error_hook(NULL);
    printf("  %s\n", last_msg);
    assert_non_null(strstr(last_msg, "diag.ini:15: dem.dt:"));
    cfg_free(cfg);
    /* known only with the particles (given stiffness: t_c depends on the mass) */
    dem_t *d = make("[contact]\nparameters = stiffness\nkn = 1e4\nfriction = 0.5\n[dem]\ndt = 1e-5\n");
    const double x[3] = {0.01, 0.01, 0.01}, v[3] = {0, 0, 0};
    dem_add_particle(d, x, v, 5e-4, 2500, 0);
    const dem_status_t st = dem_step(d);
    printf("  %s\n", dem_error(d));
    assert_int_equal(st, DEM_ERR_TIMESTEP);
    dem_free(d);
}

/* Load and build a scene from `text`; returns the error message (empty if none). */
static const char *bad_input(const char *text)
{
    last_msg[0] = 0;
    cfg_set_error_hook(hook);
    if (setjmp(jb) == 0) {
        cfg_t *cfg = cfg_load_string("bad.ini", text, 0, NULL);
        if (cfg) {
            dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
            dem_free(d);
            cfg_free(cfg);
        }
    }
    cfg_set_error_hook(NULL);
    return last_msg;
}

static void test_bad_keys(void **state)
{
    static const struct {
        const char *text, *expect;
    } cases[] = {
        {"[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\nlaw = hooke\n", "is not one of"},
        {"[contact]\nrestitution = 1.5\ncontact_time = 1e-4\nfriction = 0.5\n", "out of range"},
        {"[contact]\nrestitution = 0.5\ncontact_time = 1e-4\n", "contact.friction: missing key"},
        {"[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\nnormal_clip = false\n",
         "contact.calibration"},
        {"[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\n[walls]\nfaces = x_lo top\n",
         "'top' is not auto"},
        {"[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\n[particles]\nsource = insert\n"
         "radius = 1e-3\ncount = 10\nvolume_fraction = 0.1\n",
         "give either count or volume_fraction"},
        {"[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.5\n[walls]\nwall1_point = 0 0 0.01\n"
         "wall1_normal = 0 0 -1\nwall1_force = 1\n",
         "walls.wall1_force: a load-controlled wall needs a mass"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[2048];
        snprintf(text, sizeof text, "%s%s", BOX, cases[k].text);
        bad_input(text);
        printf("  %-60.60s -> %s\n", cases[k].expect, last_msg);
        assert_non_null(strstr(last_msg, cases[k].expect));
        assert_non_null(strstr(last_msg, "bad.ini"));
    }
}

/* dem_run_case: the run stops on the error and leaves a checkpoint. */
static void test_run_checkpoint(void **state)
{
    char dir[256], path[512];
    int pid = (int)getpid();
    MPI_Bcast(&pid, 1, MPI_INT, 0, MPI_COMM_WORLD);
    snprintf(dir, sizeof dir, "/tmp/ibmdem_test_dem_diag_%d", pid);
    char text[2048];
    snprintf(text, sizeof text,
             "%s[particles]\nsource = insert\ncount = 20\nradius = 1e-3\nvelocity = 0 0 -3\n"
             "[contact]\nrestitution = 0.5\ncontact_time = 1e-3\nfriction = 0.5\n[time]\nt_end = 0.05\n",
             BOX);
    cfg_t *cfg = cfg_load_string("run.ini", text, 0, NULL);
    assert_non_null(cfg);
    const int rc = dem_run_case(cfg, dir);
    snprintf(path, sizeof path, "%s/checkpoint_error.h5", dir);
    struct stat sb;
    const int ok = stat(path, &sb) == 0 && sb.st_size > 0;
    printf("  run stopped with status %d, checkpoint %s\n", rc, ok ? "written" : "missing");
    assert_int_equal(rc, 1);
    assert_true(ok);
    cfg_free(cfg);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_overlap),       cmocka_unit_test(test_left_domain),
        cmocka_unit_test(test_timestep),      cmocka_unit_test(test_bad_keys),
        cmocka_unit_test(test_run_checkpoint),
    };
    TEST_MPI_RUN("dem_diagnostics", tests);
}
