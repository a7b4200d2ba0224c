/* test_dem_bed.c — static beds: force balance, packing preparation and
 * the save/load round trip.
 * RANKS: 1
 *
 *  - A bed of 400 grains (d = 2 mm ± 15 %) settled to rest in a walled box: the total force of the grains on
 *    the walls equals their weight to 0.1 % (the bound).  At rest the
 *    momentum balance of the grains is Σ F_walls→grains + Σ m g = d/dt Σ m v,
 *    and the residual kinetic energy bounds the right-hand side.  With
 *    friction the side walls carry part of the load (Janssen); only the sum
 *    over all walls must equal the weight.  Linear and Hertz–Mindlin laws.
 *  - The settled packing is written (HDF5, with the contact springs) and
 *    read into a new scene: it stays at rest (the springs were restored,
 *    else the friction forces would be lost and the bed would move).
 *  - Dense (frictionless settling) packings are denser than loose ones
 *    (high friction while settling).
 *  - Rough beds of fixed half-grains (random insertion, dense relaxed,
 *    hexagonal): every grain fixed with its centre on the plane, no two
 *    discs overlapping (periodic images included), the coverage asked reached
 *    within the last disc, the same seed giving the same bed; the dense bed
 *    reaches a coverage of 0.80 that random insertion cannot (it jams at 0.547).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/dem/dem_private.h"
#include "dem.h"
#include "modules.h"
#include "testutil.h"
#include "util.h"

static char outdir[256];

static const char *bed_ini(const char *law, const char *variant, char *buf, size_t n)
{
    snprintf(buf, n,
             "[domain]\nlength = 0.016 0.016 0.03\n[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\n"
             "y_hi = noslip\nz_lo = noslip\nz_hi = noslip\n"
             "[particles]\nsource = insert\ncount = 250\nradius = 1e-3\npolydispersity = 0.15\nseed = 5\n"
             "region_lo = 0 0 0\nregion_hi = 0.016 0.016 0.03\n"
             "[contact]\nlaw = %s\nrestitution = 0.5\ncontact_time = 2e-4\nfriction = 0.5\n"
             "youngs_modulus = 2e7\npoisson_ratio = 0.3\nreference_velocity = 0.5\n"
             "[packing]\nprepare = true\nvariant = %s\nrest_energy = 1e-6\nmax_time = 2\noutput = bed_%s_%s.h5\n"
             "[dem]\ngravity = 0 0 -9.81\nsteps_per_contact = 20\nmax_overlap = 0.1\n",
             law, variant, law, variant);
    return buf;
}

/* Weight of the mobile grains, and the total force of the grains on the walls
 * along −z averaged over `steps` steps (the residual vibrations average out:
 * the mean force differs from the weight by ΔP/T). */
static void balance(dem_t *d, int steps, double *weight, double *fz)
{
    *weight = 0;
    for (int i = 0; i < dem_count(d); i++)
        if (!dem_fixed(d)[i]) *weight += dem_mass(d, i) * 9.81;
    *fz = 0;
    for (int s = 0; s < steps; s++) {
        assert_int_equal(dem_step(d), DEM_OK);
        for (int w = 0; w < dem_wall_count(d); w++) {
            double f[3];
            dem_wall_force(d, w, f);
            *fz -= f[2] / steps;
        }
    }
}

static double settle(const char *law, const char *variant, double *phi)
{
    char buf[2048];
    cfg_t *cfg = cfg_load_string("bed.ini", bed_ini(law, variant, buf, sizeof buf), 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    const double w0 = wtime();
    assert_int_equal(dem_prepare_packing(d, cfg, outdir), 0);
    double W, fz;
    balance(d, 1000, &W, &fz);
    dem_diag_t g;
    dem_diag(d, &g);
    /* packing fraction below the top: volume of grains / (area × 2 z_com) */
    double vol = 0;
    for (int i = 0; i < dem_count(d); i++) vol += dem_sphere_volume(dem_radii(d)[i]);
    *phi = vol / (0.016 * 0.016 * 2 * g.com[2]);
    const double err = fz / W - 1;
    printf("  %s, %s settling: weight %.6e N, total wall force %.6e N (mean of 1000 steps), error %+.4f %%, "
           "phi %.4f, %.1f s\n",
           law, variant, W, fz, 100 * err, *phi, wtime() - w0);
    dem_free(d);
    cfg_free(cfg);
    return err;
}

static void test_static_bed_linear(void **state)
{
    double phi;
    const double err = settle("linear", "as_is", &phi);
    assert_true(fabs(err) < 1e-3);
}

static void test_static_bed_hertz(void **state)
{
    double phi;
    const double err = settle("hertz_mindlin", "as_is", &phi);
    assert_true(fabs(err) < 1e-3);
}

/* Read the packing back and continue: the run follows the one that wrote the
 * file bit for bit (the file holds the particles in their order, the lists,
 * the springs and the forces), and the wall force still balances the weight. */
static void test_packing_roundtrip(void **state)
{
    char buf[2048], text[1024];
    cfg_t *ca = cfg_load_string("bed.ini", bed_ini("linear", "as_is", buf, sizeof buf), 0, NULL);
    dem_t *a = dem_create_from_config(ca, MPI_COMM_WORLD);
    assert_int_equal(dem_prepare_packing(a, ca, outdir), 0);
    snprintf(text, sizeof text,
             "[domain]\nlength = 0.016 0.016 0.03\n[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\n"
             "y_hi = noslip\nz_lo = noslip\nz_hi = noslip\n"
             "[particles]\nsource = file\nfile = %s/bed_linear_as_is.h5\n"
             "[contact]\nrestitution = 0.5\ncontact_time = 2e-4\nfriction = 0.5\n[dem]\ngravity = 0 0 -9.81\n"
             "steps_per_contact = 20\nmax_overlap = 0.1\n",
             outdir);
    cfg_t *cb = cfg_load_string("reload.ini", text, 0, NULL);
    assert_non_null(cb);
    dem_t *b = dem_create_from_config(cb, MPI_COMM_WORLD);
    for (int s = 0; s < 500; s++) {
        assert_int_equal(dem_step(a), DEM_OK);
        assert_int_equal(dem_step(b), DEM_OK);
    }
    const int n = dem_count(a);
    double maxd = 0, maxv = 0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < n; k++)
            if (dem_ids(b)[k] == dem_ids(a)[i])
                for (int c = 0; c < 3; c++) {
                    maxd = fmax(maxd, fabs(dem_positions(b)[3 * k + c] - dem_positions(a)[3 * i + c]));
                    maxv = fmax(maxv, fabs(dem_velocities(b)[3 * k + c] - dem_velocities(a)[3 * i + c]));
                }
    double W, fz;
    balance(b, 1000, &W, &fz);
    printf("  reloaded packing vs the original run after 500 steps: max |dx| = %.2e m, max |dv| = %.2e m/s; "
           "wall force error %+.4f %%\n",
           maxd, maxv, 100 * (fz / W - 1));
    assert_true(maxd == 0 && maxv == 0);
    assert_true(fabs(fz / W - 1) < 1e-3);
    dem_free(a);
    dem_free(b);
    cfg_free(ca);
    cfg_free(cb);
}

static void test_dense_vs_loose(void **state)
{
    double phi_dense, phi_loose;
    settle("linear", "dense", &phi_dense);
    settle("linear", "loose", &phi_loose);
    printf("  packing fraction below the centre of mass x2: dense %.4f, loose %.4f\n", phi_dense, phi_loose);
    assert_true(phi_dense > phi_loose + 0.01);
}

/* Build the bed of a 20 D x 20 D periodic plane (D = 2 mm, ± 10 %) and check it. */
static dem_t *rough_bed(const char *type, double coverage, int seed, double *cov)
{
    char text[1024];
    snprintf(text, sizeof text,
             "[domain]\nlength = 0.04 0.04 0.02\n[boundary]\nz_lo = noslip\nz_hi = noslip\n"
             "[particles]\nsource = insert\ncount = 1\nradius = 1e-3\nregion_lo = 0 0 0.01\nregion_hi = 0.04 0.04 0.02\n"
             "[bed]\ntype = %s\nradius = 1e-3\npolydispersity = 0.1\ncoverage = %g\nseed = %d\n"
             "[contact]\nrestitution = 0.5\ncontact_time = 2e-4\nfriction = 0.5\n[walls]\nfaces = z_lo z_hi\n"
             "[dem]\ngravity = 0 0 -9.81\n",
             type, coverage, seed);
    cfg_t *cfg = cfg_load_string("rough.ini", text, 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    const double *x = dem_positions(d), *r = dem_radii(d);
    const unsigned char *fix = dem_fixed(d);
    double area = 0, rmin = 1, worst = 0;
    int nb = 0;
    for (int i = 0; i < dem_count(d); i++) {
        if (!fix[i]) continue;
        nb++;
        assert_true(x[3 * i + 2] == 0.0);
        area += M_PI * r[i] * r[i];
        rmin = fmin(rmin, r[i]);
        for (int j = i + 1; j < dem_count(d); j++) {
            if (!fix[j]) continue;
            double e[2];
            for (int c = 0; c < 2; c++) e[c] = x[3 * i + c] - x[3 * j + c] - 0.04 * round((x[3 * i + c] - x[3 * j + c]) / 0.04);
            worst = fmax(worst, r[i] + r[j] - sqrt(e[0] * e[0] + e[1] * e[1]));
        }
    }
    *cov = area / (0.04 * 0.04);
    printf("  %s bed, coverage asked %.3f: %d grains, coverage %.4f, largest overlap %.2e R\n", type, coverage, nb,
           *cov, worst / 1e-3);
    /* hexagonal rows touch exactly (spacing 2R): the overlap there is round-off */
    assert_true(worst <= (strcmp(type, "hexagonal") ? 1e-9 : 1e-12) * 1e-3 * 1.1 || worst <= 0);
    if (strcmp(type, "hexagonal")) {
        /* the last disc drawn takes the coverage past the target by at most its own area */
        assert_true(*cov >= coverage && *cov < coverage + M_PI * 1.1e-3 * 1.1e-3 / (0.04 * 0.04));
    }
    cfg_free(cfg);
    return d;
}

static void test_rough_beds(void **state)
{
    double c1, c2, c3, c4;
    dem_t *a = rough_bed("random", 0.5, 4, &c1);
    dem_t *b = rough_bed("dense", 0.8, 4, &c2);
    dem_t *b2 = rough_bed("dense", 0.8, 4, &c3);
    dem_t *h = rough_bed("hexagonal", 0.5, 4, &c4);
    assert_int_equal(dem_count(b), dem_count(b2));
    for (int i = 0; i < 3 * dem_count(b); i++) assert_true(dem_positions(b)[i] == dem_positions(b2)[i]);
    /* 20 discs of R = 1 mm in each of 22 rows (23 fit, an even count goes round the periodic plane) */
    assert_true(fabs(c4 - 440 * M_PI * 1e-6 / (0.04 * 0.04)) < 1e-12);
    dem_free(a);
    dem_free(b);
    dem_free(b2);
    dem_free(h);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    int pid = (int)getpid();
    MPI_Bcast(&pid, 1, MPI_INT, 0, MPI_COMM_WORLD);
    snprintf(outdir, sizeof outdir, "/tmp/ibmdem_test_dem_bed_%d", pid);
    if (mpi_rank() == 0) mkdir_p(outdir);
    MPI_Barrier(MPI_COMM_WORLD);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_static_bed_linear),
        cmocka_unit_test(test_static_bed_hertz),
        cmocka_unit_test(test_packing_roundtrip),
        cmocka_unit_test(test_dense_vs_loose),
        cmocka_unit_test(test_rough_beds),
    };
    TEST_MPI_RUN("dem_bed", tests);
}
