/* test_dem_lists.c — neighbour search, contact histories across rebuilds,
 * reproducibility and the parallel split.
 * RANKS: 1 2
 *
 *  - The half Verlet list holds every pair (and every periodic image of a
 *    pair) closer than R_i + R_j + skin exactly once, and nothing else,
 *    compared with an O(N²) search over all 27 images, for periodic boxes
 *    1, 2 and 3+ cells wide and for walls.
 *  - After many steps with rebuilds and reordering, the contacts the force
 *    loop finds are exactly the overlapping pairs of the brute-force search.
 *  - A rebuild with reordering keeps every contact's tangential spring.
 *  - Same input, same ranks: bit-identical; pairs split over 2 ranks (or
 *    2 OpenMP threads) agree with the serial computation to round-off.
 */
#include <stdlib.h>
#include <string.h>

#include "../src/dem/dem_private.h"
#include "dem.h"
#include "modules.h"
#include "testutil.h"

static dem_t *scene(const char *box, const char *bnd, int n, double phi_v, const char *extra, MPI_Comm comm,
                    double gz)
{
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nlength = %s\n[boundary]\n%s\n"
             "[particles]\nsource = insert\ncount = %d\nradius = 1e-3\npolydispersity = 0.3\nseed = 3\n"
             "velocity_spread = %g\n"
             "[contact]\nrestitution = 0.7\ncontact_time = 1e-4\nfriction = 0.4\n"
             "[dem]\ngravity = 0 0 %g\nmax_overlap = 0.2\n%s\n",
             box, bnd, n, phi_v, gz, extra);
    cfg_t *cfg = cfg_load_string("lists.ini", text, 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, comm);
    cfg_free(cfg);
    return d;
}

/* Number of list entries for (i, j, image) in either orientation. */
static int count_entries(const dem_t *d, int i, int j, const int img[3])
{
    int c = 0;
    const int code = (img[0] + 1) + 3 * (img[1] + 1) + 9 * (img[2] + 1);
    const int rcode = (-img[0] + 1) + 3 * (-img[1] + 1) + 9 * (-img[2] + 1);
    for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++)
        if (d->nb_j[k] == j && (d->any_periodic ? d->nb_img[k] == code : 1)) c++;
    for (int k = d->nb_start[j]; k < d->nb_start[j + 1]; k++)
        if (d->nb_j[k] == i && (d->any_periodic ? d->nb_img[k] == rcode : 1)) c++;
    return c;
}

/* Brute force over all images: every pair within the cutoff listed once; the
 * list has no other entries; returns the number of overlapping pairs. */
static long check_list(const dem_t *d, double cut_extra, long *n_overlap)
{
    long expected = 0, bad = 0, over = 0;
    for (int i = 0; i < d->n; i++)
        for (int j = i + 1; j < d->n; j++) {
            if (d->fixed[i] && d->fixed[j]) continue;
            for (int ix = -1; ix <= 1; ix++)
                for (int iy = -1; iy <= 1; iy++)
                    for (int iz = -1; iz <= 1; iz++) {
                        const int img[3] = {ix, iy, iz};
                        int skip = 0;
                        double r2 = 0;
                        for (int a = 0; a < 3; a++) {
                            if (img[a] && !d->periodic[a]) skip = 1;
                            const double dx = d->x[3 * i + a] - d->x[3 * j + a] - img[a] * d->L[a];
                            r2 += dx * dx;
                        }
                        if (skip) continue;
                        const double rs = d->r[i] + d->r[j];
                        if (r2 < rs * rs) over++;
                        if (r2 >= (rs + cut_extra) * (rs + cut_extra)) continue;
                        expected++;
                        if (count_entries(d, i, j, img) != 1) bad++;
                    }
        }
    if (d->nb_n != expected) bad += labs(d->nb_n - expected);
    *n_overlap = over;
    return bad;
}

static void list_case(const char *box, const char *bnd, int n)
{
    dem_t *d = scene(box, bnd, n, 2.0, "", MPI_COMM_WORLD, 0.0);
    assert_int_equal(dem_step(d), DEM_OK);
    assert_int_equal(dem_neigh_build(d), DEM_OK); /* the list of the current positions */
    long over;
    long bad = check_list(d, d->skin, &over);
    printf("  box %s, %d particles, cells %d x %d x %d: %ld pairs listed, %ld mismatches\n", box, n, d->nc[0], d->nc[1],
           d->nc[2], d->nb_n, bad);
    assert_int_equal(bad, 0);
    /* after many steps (rebuilds, reordering, wrapping): the force loop's
     * contacts are the brute-force overlaps */
    const long b0 = d->rebuilds;
    for (int s = 0; s < 3000; s++) assert_int_equal(dem_step(d), DEM_OK);
    long miss = 0;
    check_list(d, 0.0, &over);
    dem_diag_t g;
    dem_diag(d, &g);
    miss = labs(g.n_contacts - over);
    assert_true(g.contacts_started > n / 2); /* the particles did collide */
    printf("    after %ld rebuilds: %ld contacts in the force loop, %ld overlapping pairs by brute force\n",
           d->rebuilds - b0, g.n_contacts, over);
    assert_true(d->rebuilds - b0 >= 2);
    assert_int_equal(miss, 0);
    dem_free(d);
}

static void test_list_periodic_wide(void **state)
{
    list_case("0.012 0.012 0.012", "", 100);
}

static void test_list_periodic_narrow(void **state)
{
    /* 1 and 2 cells across a periodic direction (L = 2.1 and 2.3 d_max) */
    list_case("0.012 0.0055 0.012", "z_lo = noslip\nz_hi = noslip", 40);
    list_case("0.012 0.006 0.012", "z_lo = noslip\nz_hi = noslip", 45);
}

static void test_list_walls(void **state)
{
    list_case("0.012 0.012 0.012",
              "x_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip", 80);
}

/* The multiset of (id_i, id_j, ξ) of the active contacts, sorted. */
typedef struct {
    long a, b;
    double xi[3];
} contact_t;

static int cmp_contact(const void *p, const void *q)
{
    const contact_t *x = p, *y = q;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    if (x->b != y->b) return x->b < y->b ? -1 : 1;
    return 0;
}

static long contacts_of(const dem_t *d, contact_t *c)
{
    long m = 0;
    for (int i = 0; i < d->n; i++)
        for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++)
            if (d->nb_on[k]) {
                const int j = d->nb_j[k];
                const int swap = d->id[i] > d->id[j];
                c[m].a = swap ? d->id[j] : d->id[i];
                c[m].b = swap ? d->id[i] : d->id[j];
                for (int a = 0; a < 3; a++) c[m].xi[a] = (swap ? -1 : 1) * d->nb_hist[3 * k + a];
                m++;
            }
    qsort(c, (size_t)m, sizeof *c, cmp_contact);
    return m;
}

static void test_history_kept(void **state)
{
    /* a pile under strong gravity (100 g): many sticking and sliding contacts */
    dem_t *d = scene("0.012 0.012 0.012", "z_lo = noslip\nz_hi = noslip", 95, 0.3, "parallel = replicated",
                     MPI_COMM_WORLD, -981.0);
    for (int s = 0; s < 4000; s++) assert_int_equal(dem_step(d), DEM_OK);
    contact_t *c0 = malloc(20 * (size_t)d->n * sizeof *c0), *c1 = malloc(20 * (size_t)d->n * sizeof *c1);
    const long m0 = contacts_of(d, c0);
    d->sort_every = 1;
    assert_int_equal(dem_neigh_build(d), DEM_OK);
    const long m1 = contacts_of(d, c1);
    long bad = m0 != m1;
    for (long k = 0; k < m0 && !bad; k++) {
        if (c0[k].a != c1[k].a || c0[k].b != c1[k].b) bad++;
        for (int a = 0; a < 3; a++) bad += c0[k].xi[a] != c1[k].xi[a];
    }
    double xin = 0;
    for (long k = 0; k < m0; k++) xin = fmax(xin, fabs(c0[k].xi[0]) + fabs(c0[k].xi[1]) + fabs(c0[k].xi[2]));
    printf("  %ld contacts (max |xi| %.2e m) kept across a rebuild with reordering: %ld mismatches\n", m0, xin, bad);
    assert_true(m0 > 50 && xin > 0);
    assert_int_equal(bad, 0);
    free(c0);
    free(c1);
    dem_free(d);
}

/* Serial (each rank alone) against the pairs split over the ranks. */
static void test_reproducible_and_split(void **state)
{
    const char *bnd = "z_lo = noslip\nz_hi = noslip";
    dem_t *a = scene("0.012 0.012 0.012", bnd, 95, 0.3, "parallel = replicated", MPI_COMM_SELF, -981.0);
    dem_t *b = scene("0.012 0.012 0.012", bnd, 95, 0.3, "parallel = replicated", MPI_COMM_SELF, -981.0);
    dem_t *c = scene("0.012 0.012 0.012", bnd, 95, 0.3, "parallel = split", MPI_COMM_WORLD, -981.0);
    for (int s = 0; s < 3000; s++) {
        assert_int_equal(dem_step(a), DEM_OK);
        assert_int_equal(dem_step(b), DEM_OK);
        assert_int_equal(dem_step(c), DEM_OK);
    }
    const int n = dem_count(a);
    int same = 1;
    double dmax = 0;
    for (int i = 0; i < n; i++) {
        for (int q = 0; q < 3; q++) same &= dem_positions(a)[3 * i + q] == dem_positions(b)[3 * i + q];
        for (int k = 0; k < n; k++)
            if (dem_ids(c)[k] == dem_ids(a)[i])
                for (int q = 0; q < 3; q++)
                    dmax = fmax(dmax, fabs(dem_positions(c)[3 * k + q] - dem_positions(a)[3 * i + q]));
    }
    int all_same;
    MPI_Allreduce(&same, &all_same, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &dmax, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    int sz;
    MPI_Comm_size(MPI_COMM_WORLD, &sz);
    printf("  two identical serial runs bit-identical: %s; split over %d rank(s) vs serial: max |dx| = %.2e m\n",
           all_same ? "yes" : "no", sz, dmax);
    assert_true(all_same);
    assert_true(dmax < 1e-12); /* round-off of ~1e-2 m positions, grown by the collisions over 3000 steps */
    dem_free(a);
    dem_free(b);
    dem_free(c);
}

/* Momentum of a frictional, dissipative gas in a periodic box with the pairs
 * split over the ranks: constant to round-off (each pair force is summed
 * into both particles, whichever rank computed it). */
static void test_split_momentum(void **state)
{
    dem_t *d = scene("0.012 0.012 0.012", "", 100, 2.0, "parallel = split", MPI_COMM_WORLD, 0.0);
    assert_int_equal(dem_step(d), DEM_OK);
    dem_diag_t g0, g;
    dem_diag(d, &g0);
    for (int s = 0; s < 2000; s++) assert_int_equal(dem_step(d), DEM_OK);
    dem_diag(d, &g);
    double pm = 0, dp = 0;
    for (int i = 0; i < dem_count(d); i++) {
        double v2 = 0;
        for (int a = 0; a < 3; a++) v2 += dem_velocities(d)[3 * i + a] * dem_velocities(d)[3 * i + a];
        pm += sqrt(v2) * dem_mass(d, i);
    }
    for (int a = 0; a < 3; a++) dp = fmax(dp, fabs(g.momentum[a] - g0.momentum[a]));
    printf("  split gas: %ld contacts started, |dP| = %.2e, Sum m|v| = %.2e kg m/s\n",
           g.contacts_started - g0.contacts_started, dp, pm);
    assert_true(g.contacts_started - g0.contacts_started > 20);
    assert_true(dp < 1e-13 * pm);
    dem_free(d);
}

/* OpenMP threads: two runs with 2 threads are bit-identical, and agree with
 * the serial run to round-off. */
static void test_threads(void **state)
{
    int size;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size > 1) skip(); /* 2 ranks x 2 spinning threads on 2 cores: run once, on 1 rank */
    const char *bnd = "z_lo = noslip\nz_hi = noslip";
    dem_t *a = scene("0.012 0.012 0.012", bnd, 95, 0.3, "parallel = replicated", MPI_COMM_SELF, -981.0);
    dem_t *b = scene("0.012 0.012 0.012", bnd, 95, 0.3, "parallel = replicated\nthreads = 2", MPI_COMM_SELF, -981.0);
    dem_t *c = scene("0.012 0.012 0.012", bnd, 95, 0.3, "parallel = replicated\nthreads = 2", MPI_COMM_SELF, -981.0);
    for (int s = 0; s < 3000; s++) {
        assert_int_equal(dem_step(a), DEM_OK);
        assert_int_equal(dem_step(b), DEM_OK);
        assert_int_equal(dem_step(c), DEM_OK);
    }
    double dmax = 0;
    int same = 1;
    for (int i = 0; i < dem_count(a); i++)
        for (int q = 0; q < 3; q++) {
            dmax = fmax(dmax, fabs(dem_positions(b)[3 * i + q] - dem_positions(a)[3 * i + q]));
            same &= dem_positions(b)[3 * i + q] == dem_positions(c)[3 * i + q];
        }
    printf("  2 threads: runs bit-identical: %s; against 1 thread: max |dx| = %.2e m\n", same ? "yes" : "no", dmax);
    assert_true(same);
    assert_true(dmax < 1e-12);
    dem_free(a);
    dem_free(b);
    dem_free(c);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_list_periodic_wide),
        cmocka_unit_test(test_list_periodic_narrow),
        cmocka_unit_test(test_list_walls),
        cmocka_unit_test(test_history_kept),
        cmocka_unit_test(test_reproducible_and_split),
        cmocka_unit_test(test_split_momentum),
        cmocka_unit_test(test_threads),
    };
    TEST_MPI_RUN("dem_lists", tests);
}
