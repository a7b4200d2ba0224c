/* test_ibm_stokes.c — Stokes flow past spheres, against exact results.
 *
 * Drag: a fixed sphere in a triply periodic cube is a simple cubic array
 * of spheres.  A body force f drives the fluid; at the steady state the
 * forcing of the immersed boundary balances the whole body force, so the
 * drag is known exactly, F = ρ f L³, and the test measures the superficial
 * velocity U (the mean of u over the whole box).  Hasimoto (1959), for the
 * dilute simple cubic array:
 *     K = F/(6πμaU) = 1/(1 − 1.7601 c^{1/3} + c − 1.5593 c²),  c = (4/3)πa³/L³.
 * Box L = 4 D (c = 0.00818) at D/Δx = 8, 12 (and 16, 24 in
 * scripts/validate.sh); Re = UD/ν = 0.01.
 *
 * Torque: a sphere rotating at Ω in a still fluid (periodic box of 4 D,
 * c = 0.008) feels T = −8πμa³Ω (Stokes flow), within O(c) of the unbounded
 * value; Re = Ωa²/ν = 0.0025.
 *
 * The forced band of partially covered nodes (about 2.5 cells) sets an
 * effective radius that differs from a by a fraction of a cell, which
 * depends on Δt ν/Δx² with the seed's forcing (docs/theory.md §6b): the
 * errors are first order in Δx/D (measured below) at Δt ν/Δx² = 1.
 * RANKS: 2
 */
#include "ibmtest.h"
#include "modules.h"
#include "testutil.h"

static double hasimoto_K(double c)
{
    return 1.0 / (1.0 - 1.7601 * cbrt(c) + c - 1.5593 * c * c);
}

static double env_double(const char *name, double def)
{
    const char *s = getenv(name);
    return s ? atof(s) : def;
}

/* Steady Stokes flow through the simple cubic array at D/Δx = dpd with n
 * cells per side; returns K measured / K of Hasimoto.
 *
 * The mean flow of a fixed array relaxes on the Darcy time L³/(6πaνK),
 * which is 10 times the viscous time of the box here: the body force is
 * therefore set by a proportional controller, f = f_H + (U_H − U)/τ_c,
 * which only shortens that relaxation (to τ_c = 10 Δt); K is measured from
 * the final pair (f, U), both steady, so the controller does not bias it. */
static double drag_ratio(int dpd, int n, double fo, double *c_out)
{
    double dx = 1.0 / dpd, L = n * dx, a = 0.5, nu = 1.0;
    double c = 4.0 / 3.0 * M_PI * a * a * a / (L * L * L), K = hasimoto_K(c);
    double U = 0.01; /* Re = U D / ν */
    double fH = 6 * M_PI * nu * a * U * K / (L * L * L);
    double dt = fo * dx * dx / nu, tau = env_double("IBM_TAUC", 10.0) * dt;
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nnx = %d\nny = %d\nnz = %d\nlength = %.17g %.17g %.17g\n"
             "[fluid]\nnu = %g\nviscous = %s\nbody_force = %.17g 0 0\ndt = %.17g\n"
             "[ibm]\nsphere1 = fixed center %.17g %.17g %.17g radius %g\n"
             "retraction = %g\nforcing_time = %g\ncn_forcing = %s\n",
             n, n, n, L, L, L, nu, getenv("IBM_VISC") ? getenv("IBM_VISC") : "implicit", fH, dt, 0.5 * L, 0.5 * L, 0.5 * L, a, env_double("IBM_RETRACTION", 0.0), env_double("IBM_KAPPA", 0.0),
             getenv("IBM_CNF") ? getenv("IBM_CNF") : "after_solve");
    it_case_t tc = it_from_case(text);
    /* the slowest viscous mode of the box decays as exp(−ν(2π/L)² t) */
    double t_end = env_double("IBM_TDECAY", 5.0) * L * L / (4 * M_PI * M_PI * nu);
    double Um = 0, Km = 0, Km_prev = 0;
    int steps = 0;
    while (tc.f->time < t_end) {
        fluid_step(tc.f, dt);
        steps++;
        Um = it_mean_velocity(tc.f, 0);
        Km_prev = Km;
        Km = tc.f->prm.body_force[0] * L * L * L / (6 * M_PI * nu * a * Um);
        tc.f->prm.body_force[0] = fH + (U - Um) / tau;
    }
    print_message("  D/dx = %2d, n = %3d, c = %.5f: %d steps, U = %.6g, drag %.6g (sphere's own: %.6g), "
                  "K = %.5f (last step change %.1e), Hasimoto %.5f, ratio %.5f\n",
                  dpd, n, c, steps, Um, tc.f->prm.body_force[0] * L * L * L, tc.ibm->s[0].force[0], Km,
                  fabs(Km - Km_prev) / Km, K, Km / K);
    it_free(&tc);
    if (c_out) *c_out = c;
    return Km / K;
}

/* Drag at D/Δx = 8 and 12 (16 and 24 in scripts/validate.sh), Δt ν/Δx² = 1
 * (the seed's value: Δt √(g/D) = 0.04 at D/Δx = 20 in the settling case):
 * measured K/K_H = 0.934 and 0.961, first order (1.1); the bounds are
 * those errors plus 1 %. */
static void test_hasimoto_drag(void **state)
{
    (void)state;
    /* IBM_FULL=1 (scripts/validate.sh): D/Δx = 8, 12, 16, 24 */
    int full = getenv("IBM_FULL") != NULL, nl = full ? 4 : 2;
    int dpd[4] = {8, 12, 16, 24};
    double r[4], c, bound[4] = {0.077, 0.05, 0.04, 0.03};
    for (int i = 0; i < nl; i++) {
        r[i] = drag_ratio(dpd[i], 4 * dpd[i], env_double("IBM_FO", 1.0), &c);
        assert_float_equal(r[i], 1.0, bound[i]);
    }
    for (int i = 0; i + 1 < nl; i++) {
        double e0 = fabs(r[i] - 1), e1 = fabs(r[i + 1] - 1), p = conv_order(e0, e1, (double)dpd[i + 1] / dpd[i]);
        print_message("  |K/K_H - 1| = %.4f (D/dx = %d) -> %.4f (%d): order %.2f\n", e0, dpd[i], e1, dpd[i + 1], p);
        assert_true(p > 0.8);
    }
}

/* Torque on a sphere rotating at Ω about z in a periodic box of 4 D, at
 * D/Δx = dpd; returns T / (−8πμa³Ω). */
static double torque_ratio(int dpd, double fo)
{
    double dx = 1.0 / dpd, a = 0.5, nu = 1.0, Om = 0.01;
    int n = 4 * dpd;
    double L = n * dx, dt = fo * dx * dx / nu;
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nnx = %d\nny = %d\nnz = %d\nlength = %.17g %.17g %.17g\n"
             "[fluid]\nnu = %g\nviscous = implicit\ndt = %.17g\n"
             "[ibm]\nsphere1 = prescribed center %.17g %.17g %.17g radius %g omega 0 0 %g\n"
             "retraction = %g\nforcing_time = %g\n",
             n, n, n, L, L, L, nu, dt, 0.5 * L, 0.5 * L, 0.5 * L, a, Om, env_double("IBM_RETRACTION", 0.0), env_double("IBM_KAPPA", 0.0));
    it_case_t tc = it_from_case(text);
    double exact = -8 * M_PI * nu * a * a * a * Om, T = 0, Tp = 0;
    double t_end = env_double("IBM_TDECAY_T", 3.0) * L * L / (4 * M_PI * M_PI * nu);
    int steps = 0;
    while (tc.f->time < t_end) {
        fluid_step(tc.f, dt);
        steps++;
        Tp = T;
        T = tc.ibm->s[0].torque[2];
    }
    print_message("  D/dx = %2d, n = %3d: %d steps, torque %.6g (last step change %.1e), 8 pi mu a^3 Omega = %.6g, "
                  "ratio %.5f; other components %.1e %.1e, force %.1e\n",
                  dpd, n, steps, T, fabs(T - Tp) / fabs(T), -exact, T / exact, tc.ibm->s[0].torque[0],
                  tc.ibm->s[0].torque[1], tc.ibm->s[0].force[0]);
    it_free(&tc);
    return T / exact;
}

/* Torque at D/Δx = 8 and 12 (16 in scripts/validate.sh, where the 5 %
 * bound of the issue is checked): measured 0.923 and 0.947 of 8πμa³Ω;
 * bounds: those errors plus 1 %, and a convergence order above 0.8. */
static void test_rotating_sphere_torque(void **state)
{
    (void)state;
    /* IBM_FULL=1: also D/Δx = 16, where the 5 % applies */
    int full = getenv("IBM_FULL") != NULL, nl = full ? 3 : 2;
    int dpd[3] = {8, 12, 16};
    double r[3], bound[3] = {0.087, 0.063, 0.05};
    for (int i = 0; i < nl; i++) {
        r[i] = torque_ratio(dpd[i], env_double("IBM_FO", 1.0));
        assert_float_equal(r[i], 1.0, bound[i]);
    }
    for (int i = 0; i + 1 < nl; i++) {
        double e0 = fabs(r[i] - 1), e1 = fabs(r[i + 1] - 1), p = conv_order(e0, e1, (double)dpd[i + 1] / dpd[i]);
        print_message("  |T/(8 pi mu a^3 Omega) - 1| = %.4f (D/dx = %d) -> %.4f (%d): order %.2f\n", e0, dpd[i], e1,
                      dpd[i + 1], p);
        assert_true(p > 0.8);
    }
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    /* IBM_TESTS=pattern runs only the matching tests (scripts/validate.sh) */
    if (getenv("IBM_TESTS")) cmocka_set_test_filter(getenv("IBM_TESTS"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hasimoto_drag),
        cmocka_unit_test(test_rotating_sphere_torque),
    };
    TEST_MPI_RUN("ibm_stokes", tests);
}
