/* test_coupling_drag.c — the linearised drag of the DEM sub-steps ([coupling]
 * implicit_drag = K, implicit_drag_hindrance; coupling.h, src/coupling/ibm_dem.c,
 * docs/theory.md §9.1b).
 * RANKS: 1
 *
 * Grains at rest (U_n = 0, the fluid step's velocities of a fake immersed
 * boundary) are given a held force F over one fluid step Δt, no gravity, no
 * contact (centres 1.05 D apart).  A grain whose term has the coefficient c
 * then follows m dU/dt = F − cU: U(Δt) = (F/c)(1 − e^{−cΔt/m}).  The term is
 * updated in chunks of at most 5 % of m/c (forward Euler on the relaxation):
 * U differs from the exponential by at most 1.5 % at cΔt/m = 1 (0.95^20 against
 * e^{−1}) and less at other ratios, hence the 3 % tolerance (measured: 0.07–0.27 %).  Exact cases:
 *  1. A periodic lattice of 27 mobile grains, the same F on each (the whole
 *     neighbourhood accelerates together): with `relative` every grain follows
 *     the isolated sphere's coefficient K 3πηD; with `richardson_zaki` the
 *     hindered one c_h = 3πηD (1 − φ)^−4.65 (φ the lattice's local fraction):
 *     the two differ by more than a factor 2, so each check can fail.  Along a
 *     direction bounded by walls (not periodic) `relative` gives c_h too.
 *  2. The same lattice with every grain fixed but one, F on that one (a grain
 *     moving against its neighbours): `relative` gives it c_h, as
 *     `richardson_zaki` does.
 *  3. A grain alone in the box: its neighbourhood is empty, and `relative` is
 *     K, bit for bit the run with `none`.
 */
#include <stdlib.h>
#include <string.h>

#include "coupling.h"
#include "couplingtest.h"
#include "dem.h"
#include "modules.h"
#include "testutil.h"
#include "util.h"

static const double R = 1e-3, RHO_P = 2500, MU = 0.2, K = 1, L = 6.3e-3; /* 3 x 1.05 D */

static dem_t *make(void)
{
    char text[1024];
    snprintf(text, sizeof text,
             "[domain]\nlength = %.17g %.17g %.17g\n[boundary]\nx_lo = periodic\nx_hi = periodic\n"
             "y_lo = periodic\ny_hi = periodic\nz_lo = periodic\nz_hi = periodic\n"
             "[contact]\nrestitution = 0.9\ncontact_time = 1e-4\nfriction = 0.3\n"
             "[dem]\ngravity = 0 0 0\nsteps_per_contact = 50\n",
             L, L, L);
    return test_dem_from_text(text);
}

/* One fluid step dt of a lattice (lattice = 1: 27 grains, else one grain), force F along x on the
 * grains `pushed` selects (all, or grain 0), the others fixed when `others_fixed`; returns grain 0's
 * x velocity, *c0 the coefficient the term gave it (factor × 3πηD) and *m0 its mass. */
static double push(int mode, int lattice, int others_fixed, int bounded_x, double F, double dt, double *c0,
                   double *m0)
{
    dem_t *d = make();
    const int n = lattice ? 27 : 1;
    const double h = 1.05 * 2 * R, v[3] = {0, 0, 0};
    for (int q = 0; q < n; q++) {
        const double x[3] = {(q % 3 + 0.5) * h, (q / 3 % 3 + 0.5) * h, (q / 9 + 0.5) * h};
        dem_add_particle(d, x, v, R, RHO_P, q > 0 && others_fixed);
    }
    assert_int_equal(dem_advance(d, dem_time(d)), DEM_OK); /* the set-up (time step, lists, order) */
    ibm_t *ibm = test_fake_ibm(n);
    coupling_drag_t dr;
    coupling_drag_init(&dr, n, K, MU, mode);
    const int periodic[3] = {!bounded_x, 1, 1};
    coupling_drag_set_bounded(&dr, periodic);
    double *fe = dem_ext_force(d);
    memset(fe, 0, 3 * (size_t)n * sizeof *fe);
    memset(dem_ext_torque(d), 0, 3 * (size_t)n * sizeof(double));
    const long *id = dem_ids(d);
    for (int i = 0; i < n; i++)
        if (!others_fixed || id[i] == 0) fe[3 * i] = F;
    assert_int_equal(coupling_drag_advance(&dr, ibm, d, NULL, dt), DEM_OK);
    double u = 0;
    id = dem_ids(d);
    for (int i = 0; i < dem_count(d); i++)
        if (id[i] == 0) {
            u = dem_velocities(d)[3 * i];
            *m0 = dem_mass(d, i);
        }
    *c0 = dr.factor[0] * 6 * M_PI * MU * R;
    coupling_drag_free(&dr);
    test_free_ibm(ibm);
    dem_free(d);
    return u;
}

static double relax(double F, double c, double m, double dt) { return F / c * (1 - exp(-c * dt / m)); }

static void test_collective_and_relative(void **state)
{
    (void)state;
    const double F = 1e-4, dt = 2e-3, cK = K * 6 * M_PI * MU * R;
    double c, m;
    /* 1. the lattice pushed as a whole */
    const double ur = push(DRAG_HINDRANCE_RELATIVE, 1, 0, 0, F, dt, &c, &m);
    const double ch = c, uK = relax(F, cK, m, dt), uh = relax(F, ch, m, dt);
    const double uz = push(DRAG_HINDRANCE_RICHARDSON_ZAKI, 1, 0, 0, F, dt, &c, &m);
    printf("# lattice pushed as a whole: c_h = %.1f x 3 pi eta D (K = %g), m/c_K = %.3g s, dt = %g s\n",
           ch / (6 * M_PI * MU * R), K, m / cK, dt);
    printf("#   relative U = %.6g (K: %.6g, %+.2f %%), richardson_zaki U = %.6g (c_h: %.6g, %+.2f %%)\n", ur, uK,
           100 * (ur / uK - 1), uz, uh, 100 * (uz / uh - 1));
    assert_true(ch > 4 * cK); /* a dense lattice (simple cubic, gaps of 0.05 D): the checks below can tell the two apart */
    assert_true(fabs(ur / uK - 1) < 0.03);
    assert_true(fabs(uz / uh - 1) < 0.03);
    assert_true(ur > 2 * uz);
    /* the same push along a direction bounded by walls: the whole change meets c_h */
    const double ub = push(DRAG_HINDRANCE_RELATIVE, 1, 0, 1, F, dt, &c, &m);
    printf("#   relative, x bounded: U = %.6g (c_h: %+.2f %%)\n", ub, 100 * (ub / uh - 1));
    assert_true(fabs(ub / uh - 1) < 0.03);
    /* 2. one grain pushed among fixed neighbours */
    const double u1 = push(DRAG_HINDRANCE_RELATIVE, 1, 1, 0, F, dt, &c, &m), u1z = push(DRAG_HINDRANCE_RICHARDSON_ZAKI, 1, 1, 0, F, dt, &c, &m);
    const double u1h = relax(F, c, m, dt);
    printf("# one grain among fixed ones: relative U = %.6g, richardson_zaki U = %.6g, c_h: %.6g (%+.2f %%)\n", u1,
           u1z, u1h, 100 * (u1 / u1h - 1));
    assert_true(fabs(u1 / u1h - 1) < 0.03);
    assert_true(fabs(u1z / u1h - 1) < 0.03);
    /* 3. a grain alone: relative is K, bit for bit */
    const double ua = push(DRAG_HINDRANCE_RELATIVE, 0, 0, 0, F, dt, &c, &m), un = push(DRAG_HINDRANCE_NONE, 0, 0, 0, F, dt, &c, &m);
    printf("# a grain alone: relative U = %.17g, none U = %.17g\n", ua, un);
    assert_true(ua == un);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_collective_and_relative)};
    TEST_MPI_RUN("coupling_drag", tests);
}
