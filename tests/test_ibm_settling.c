/* test_ibm_settling.c — free spheres under gravity in the axisymmetric
 * geometry (x = r, y = z, the sphere on the axis), the coarse versions of
 * the validation cases (scripts/validate.sh runs them at D/Δx = 20):
 *
 *  - the settling sphere of Izard (2014) §2.2.3 (reference notes §2.5):
 *    ρ_p/ρ = 4, Ar = ρ(ρ_p − ρ)gD³/η² = 800.  Initial acceleration against
 *    (ρ_p − ρ)g/(ρ_p + ρ/2) (eq. 2.34, added mass ½), terminal velocity
 *    against Schiller–Naumann (u_T/√(gD) = 1.2442, Re_T = 20.3);
 *  - density ratios 0.5 (rising), 1 (neutral: stays at rest), 1.1
 *    (settling) and 1000: steady motion without oscillation;
 *  - the rigid-body force model of the seed against the momentum model.
 *
 * Units: D = 1, g = 1, ρ = 1; ν = √(|ρ_p/ρ − 1|/Ar).  Grid D/Δx = 10,
 * r ≤ 6D (free-slip wall), 28D long, Δt √(g/D) = 0.08 (the seed's 0.04 at
 * D/Δx = 20, same CFL ≈ 1).
 * RANKS: 2
 */
#include "ibmtest.h"
#include "modules.h"
#include "testutil.h"

typedef struct {
    double ratio, Ar, dt, t_end, cv, kappa;
    int dpd;
    int alpha_step; /* [ibm] free_alpha = step */
    double Lr, Lz;
    const char *model;
    /* results */
    int n;
    double *t, *v, *y;
} settle_t;

static double env_double(const char *name, double def)
{
    const char *s = getenv(name);
    return s ? atof(s) : def;
}

static double nu_of(const settle_t *s) { return sqrt(fabs(s->ratio - 1.0) / s->Ar); }

/* Run one case; records the axial velocity after every step. */
static void run_settling(settle_t *s)
{
    double nu = s->ratio == 1.0 ? 0.05 : nu_of(s);
    /* heavy spheres start 2.5 D below the top, light ones 2.5 D above the bottom */
    double y0 = s->ratio >= 1.0 ? s->Lz - 2.5 : 2.5;
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\ngeometry = axisymmetric\nnx = %d\nny = %d\nlength = %g %g 1\n"
             "[boundary]\nx_lo = axis\nx_hi = freeslip\ny_lo = freeslip\ny_hi = freeslip\n"
             "[fluid]\nnu = %.17g\nviscous = implicit\ndt = %.17g\n"
             "[ibm]\ngravity = 0 -1 0\nvirtual_mass = %g\nforcing_time = %g\nforce_model = %s\nfree_alpha = %s\n"
             "sphere1 = free center 0 %g 0 diameter 1 density %g\n",
             (int)lround(s->Lr * s->dpd), (int)lround(s->Lz * s->dpd), s->Lr, s->Lz, nu, s->dt, s->cv, s->kappa,
             s->model ? s->model : "momentum", s->alpha_step ? "step" : "stage", y0, s->ratio);
    it_case_t tc = it_from_case(text);
    int cap = (int)(s->t_end / s->dt) + 2;
    s->t = calloc(cap, sizeof(double));
    s->v = calloc(cap, sizeof(double));
    s->y = calloc(cap, sizeof(double));
    s->n = 0;
    while (tc.f->time < s->t_end - 1e-9 && s->n < cap) {
        fluid_step(tc.f, s->dt);
        s->t[s->n] = tc.f->time;
        s->v[s->n] = tc.ibm->s[0].u[1];
        s->y[s->n] = tc.ibm->s[0].x[1];
        s->n++;
    }
    it_free(&tc);
}

static void settle_free(settle_t *s)
{
    free(s->t);
    free(s->v);
    free(s->y);
}

/* Mean velocity over t in [t0, t1]. */
static double mean_velocity(const settle_t *s, double t0, double t1)
{
    double sum = 0;
    int k = 0;
    for (int i = 0; i < s->n; i++)
        if (s->t[i] >= t0 - 1e-9 && s->t[i] <= t1 + 1e-9) sum += s->v[i], k++;
    return sum / k;
}

/* Least-squares fit of v(t)/t = a0 + a1 √t + a2 t over the samples with
 * t ≤ tmax: the initial acceleration a0, with the history (Basset) force's
 * √t and the next order as the other terms. */
static double initial_acceleration(const settle_t *s, double tmax)
{
    int n = 0;
    double *basis = calloc(3 * (size_t)s->n + 3, sizeof(double)), *y = calloc((size_t)s->n + 1, sizeof(double)), x[3];
    for (int i = 0; i < s->n && s->t[i] <= tmax + 1e-12; i++, n++) {
        double t = s->t[i];
        basis[3 * n] = 1.0, basis[3 * n + 1] = sqrt(t), basis[3 * n + 2] = t;
        y[n] = s->v[i] / t;
    }
    it_lsq3(n, basis, y, x);
    free(basis);
    free(y);
    return x[0];
}

static settle_t base_case(double ratio)
{
    settle_t s = {.ratio = ratio, .Ar = 800, .dt = env_double("IBM_DT", 0.08), .t_end = 20, .dpd = 10, .Lr = 6,
                  .Lz = 28, .cv = env_double("IBM_CV", 0.1), .kappa = env_double("IBM_KAPPA", 0.0)};
    return s;
}

/* ---- the settling sphere ------------------------------------------------------------- */

static void test_settling_sphere(void **state)
{
    (void)state;
    settle_t s = base_case(4.0);
    s.dpd = (int)env_double("IBM_DPD", 10);
    s.Lr = env_double("IBM_LR", 6);
    s.Lz = env_double("IBM_LZ", 28);
    s.t_end = env_double("IBM_TEND", 20);
    run_settling(&s);
    double uT = it_schiller_naumann(1.0, 4.0, 1.0, nu_of(&s));
    double u1 = -mean_velocity(&s, s.t_end - 4, s.t_end - 2), u2 = -mean_velocity(&s, s.t_end - 2, s.t_end);
    print_message("  rho_p/rho = 4, Ar = 800, D/dx = %d, dt = %g: terminal velocity %.5f (t in [%g, %g]; %.5f "
                  "two time units before), Schiller-Naumann %.5f: error %+.2f %%\n",
                  s.dpd, s.dt, u2, s.t_end - 2, s.t_end, u1, uT, 100 * (u2 / uT - 1));
    for (int i = 0; i < s.n; i++)
        if (getenv("IBM_PRINT")) print_message("    %.4f %.6f %.6f\n", s.t[i], s.y[i], s.v[i]);
    /* Tolerance of this coarse version: the error is that of the resolution
     * (the forced band of ~1 cell around the sphere adds drag): measured
     * −5.8 % here, −1.7 % at D/Δx = 20 (scripts/validate.sh, 3 % bound);
     * confinement by the wall at r = 6D: +0.5 % (measured against r = 12D).
     * 7 % leaves room for the machine only, not for a change of method. */
    if (s.dpd == 10) assert_float_equal(u2 / uT, 1.0, 0.07);
    assert_float_equal(u2 / u1, 1.0, 0.002); /* steady */
    settle_free(&s);
}

/* Steady approach to the terminal velocity: |v| never decreases by more
 * than 1e-3 of its final value from one step to the next after the first
 * steps, never overshoots the final value by more than 0.5 %, and has
 * settled (change over the last 2 time units < 0.5 %). */
static void check_steady(const settle_t *s, const char *what, double uT, double tol_sn)
{
    double vf = fabs(s->v[s->n - 1]), vmax = 0, drop = 0;
    for (int i = 3; i < s->n; i++) {
        drop = fmax(drop, fabs(s->v[i - 1]) - fabs(s->v[i]));
        vmax = fmax(vmax, fabs(s->v[i]));
    }
    double v2 = fabs(mean_velocity(s, s->t_end - 4, s->t_end - 2)), v1 = fabs(mean_velocity(s, s->t_end - 2, s->t_end));
    print_message("  %s: terminal %.5f (Schiller-Naumann %.5f, %+.2f %%), largest step-to-step decrease of |v| "
                  "%.1e of it, overshoot %.2e, last change %.2e\n",
                  what, vf, uT, 100 * (vf / uT - 1), drop / vf, vmax / vf - 1, fabs(v1 / v2 - 1));
    assert_true(drop < 1e-3 * vf);
    assert_true(vmax < 1.005 * vf);
    assert_true(fabs(v1 / v2 - 1) < 0.005);
    assert_float_equal(vf / uT, 1.0, tol_sn);
}

/* The rising (ρ_p/ρ = 0.5) and barely heavy (1.1) spheres, steady.  Ar = 800
 * for each: the same Re_T = 20.3, velocity scale √(|ρ_p/ρ − 1| g D).  Δt at
 * the CFL of the ρ_p/ρ = 4 case (0.94 at the terminal velocity), so that
 * Δt ν/Δx² is the same too: the seed's forcing depends on it.  Run for
 * 20 D/u_T, as long as the ρ_p/ρ = 4 case takes to be steady.  Against
 * Schiller–Naumann: the resolution error of the ρ_p/ρ = 4 case (−5.8 %)
 * plus what the lighter sphere adds (measured −8.2 % in all; 10 % bound). */
static void light_and_heavy(int alpha_step, const char *label)
{
    const double ratio[2] = {0.5, 1.1};
    const char *what[2] = {"rho_p/rho = 0.5 (rising)", "rho_p/rho = 1.1 (settling)"};
    for (int k = 0; k < 2; k++) {
        settle_t s = base_case(ratio[k]);
        s.alpha_step = alpha_step;
        s.dt = 0.08 * sqrt(4.0 - 1.0) / sqrt(fabs(ratio[k] - 1.0));
        s.t_end = 40 * s.dt / 0.08 * 0.5;
        run_settling(&s);
        char name[128];
        snprintf(name, sizeof name, "%s%s", label, what[k]);
        check_steady(&s, name, it_schiller_naumann(1, ratio[k], 1, nu_of(&s)), 0.10);
        assert_true(ratio[k] < 1.0 ? s.v[s.n - 1] > 0 : s.v[s.n - 1] < 0);
        settle_free(&s);
    }
}

static void test_density_ratios(void **state)
{
    (void)state;
    light_and_heavy(0, "");
    /* neutrally buoyant: no immersed weight, a fluid at rest exerts nothing */
    settle_t z = base_case(1.0);
    z.dt = 0.1;
    z.t_end = 5;
    run_settling(&z);
    double vm = 0;
    for (int i = 0; i < z.n; i++) vm = fmax(vm, fabs(z.v[i]));
    print_message("  rho_p/rho = 1: max |v| = %.1e over %d steps\n", vm, z.n);
    assert_true(vm == 0.0);
    settle_free(&z);
}

/* The seed's rigid-body force model and the momentum model reach the same
 * terminal velocity: at a steady translation both reduce to ρ ∫ f dV =
 * (ρ_p − ρ) V_p g (the momentum inside the moving sphere is constant). */
static void test_rigid_model(void **state)
{
    (void)state;
    settle_t a = base_case(4.0), b = base_case(4.0);
    a.t_end = b.t_end = 16;
    b.model = "rigid";
    run_settling(&a);
    run_settling(&b);
    double ua = mean_velocity(&a, 14, 16), ub = mean_velocity(&b, 14, 16);
    print_message("  terminal velocity: momentum model %.5f, rigid model %.5f: difference %.2e\n", -ua, -ub,
                  fabs(ua / ub - 1));
    assert_float_equal(ua / ub, 1.0, 0.005);
    settle_free(&a);
    settle_free(&b);
}

/* Run s from rest; its fitted initial acceleration over (ρ_p − ρ)g/(ρ_p + ρ/2)
 * (eq. 2.34, added mass ½), printed after `label`. */
static double initial_acceleration_ratio(settle_t *s, const char *label)
{
    run_settling(s);
    double a0 = -initial_acceleration(s, s->t_end), a_th = (s->ratio - 1.0) / (s->ratio + 0.5);
    print_message("  %s: initial acceleration (fit of v/t = a0 + a1 sqrt(t) + a2 t, t <= %g, dt = %g) %.5f, "
                  "(rho_p - rho) g/(rho_p + rho/2) = %.5f: error %+.2f %%; first step %.5f\n",
                  label, s->t_end, s->dt, a0, a_th, 100 * (a0 / a_th - 1), -s->v[0] / s->t[0]);
    settle_free(s);
    return a0 / a_th;
}

static void test_initial_acceleration(void **state)
{
    (void)state;
    double cvs[3] = {0.0, 0.1, 0.5};
    for (int k = 0; k < 3; k++) {
        settle_t s = base_case(4.0);
        s.cv = cvs[k];
        s.dt = env_double("IBM_DT0", 0.01);
        s.t_end = env_double("IBM_T0", 0.5);
        char label[64];
        snprintf(label, sizeof label, "rho_p/rho = 4, C_v = %.1f", cvs[k]);
        /* the bound: 5 % (measured 1.6 %, 1.2 %, 0.5 % for C_v = 0, 0.1, 0.5) */
        assert_float_equal(initial_acceleration_ratio(&s, label), 1.0, 0.05);
    }
    /* ρ_p/ρ = 1000: (ρ_p − ρ)g/(ρ_p + ρ/2) = 0.9985 g; the history force is
     * O(ρ/ρ_p) smaller: 2 % */
    settle_t s = base_case(1000.0);
    s.dt = 0.01;
    s.t_end = 0.5;
    assert_float_equal(initial_acceleration_ratio(&s, "rho_p/rho = 1000"), 1.0, 0.02);
}

/* [ibm] free_alpha = step: the solid fraction held over each fluid step and
 * moved between steps, the fluid momentum over the jump counted in the next
 * force (docs/theory.md §6b), instead of moved after every stage.  At this
 * CFL (0.94) the held α lags the sphere by up to one cell within a step.
 * Bounds: the terminal velocity within 0.5 % of the per-stage solid
 * fraction's (measured +0.13 % here, +0.045 % at D/Δx = 20 with
 * cases/settling_sphere/settling_axi.ini; a tenth of the resolution error
 * of this grid), the initial acceleration within the 5 % (the same
 * 1.19 % as per stage), and the light (ρ_p/ρ = 0.5) and barely heavy (1.1)
 * spheres steady as above (their terminal velocities +1.8 % and +0.65 %
 * from the per-stage ones, at Δt 2.4 and 5.5 times longer). */
static void test_free_alpha_step(void **state)
{
    (void)state;
    settle_t a = base_case(4.0), b = base_case(4.0);
    b.alpha_step = 1;
    run_settling(&a);
    run_settling(&b);
    double ua = mean_velocity(&a, a.t_end - 2, a.t_end), ub = mean_velocity(&b, b.t_end - 2, b.t_end);
    print_message("  free_alpha = step: terminal velocity %.5f against %.5f with the per-stage solid fraction: %+.3f %%\n",
                  -ub, -ua, 100 * (ub / ua - 1));
    assert_float_equal(ub / ua, 1.0, 0.005);
    assert_float_equal(mean_velocity(&b, b.t_end - 4, b.t_end - 2) / ub, 1.0, 0.002); /* steady */
    settle_free(&a);
    settle_free(&b);
    settle_t s = base_case(4.0);
    s.alpha_step = 1, s.dt = 0.01, s.t_end = 0.5;
    assert_float_equal(initial_acceleration_ratio(&s, "free_alpha = step, rho_p/rho = 4"), 1.0, 0.05);
    light_and_heavy(1, "free_alpha = step, ");
}

/* scripts/validate.sh (IBM_FULL=1): the seed's case at D/Δx = 20, r ≤ 10 D,
 * 40 D long, Δt √(g/D) = 0.04: initial acceleration within 5 % and terminal
 * velocity within 3 % (the bounds); the wall at r = 10 D slows the
 * sphere by about 0.2 % (0.3 % at 8 D against 20 D, measured at D/Δx = 10). */
static void test_settling_full(void **state)
{
    (void)state;
    if (!getenv("IBM_FULL")) {
        print_message("  (IBM_FULL=1 runs the D/dx = 20 version: scripts/validate.sh)\n");
        return;
    }
    settle_t a = base_case(4.0);
    a.dpd = 20, a.Lr = 10, a.Lz = 40, a.dt = 0.005, a.t_end = 0.5;
    assert_float_equal(initial_acceleration_ratio(&a, "D/dx = 20"), 1.0, 0.05);
    settle_t s = base_case(4.0);
    s.dpd = 20, s.Lr = 10, s.Lz = 40, s.dt = 0.04, s.t_end = 30;
    run_settling(&s);
    double uT = it_schiller_naumann(1.0, 4.0, 1.0, nu_of(&s));
    double u1 = -mean_velocity(&s, 26, 28), u2 = -mean_velocity(&s, 28, 30);
    print_message("  D/dx = 20: terminal velocity %.5f (t in [28, 30]; %.5f in [26, 28]), Schiller-Naumann %.5f: "
                  "error %+.2f %%\n",
                  u2, u1, uT, 100 * (u2 / uT - 1));
    assert_float_equal(u2 / uT, 1.0, 0.03);
    assert_float_equal(u2 / u1, 1.0, 0.002);
    settle_free(&s);
}

/* IBM_FULL3D=1 (scripts/validate.sh): the same sphere in 3-D at D/Δx = 16,
 * in a free-slip box of 6 D × 24 D × 6 D, Δt √(g/D) = 0.05 (CFL ≈ 1).  The
 * box slows the sphere: the correction is estimated with the axisymmetric
 * solver at the same D/Δx and Δt, as the ratio of the terminal velocities
 * in a free-slip cylinder of r = 10 D and in one of the box's cross-section
 * area (r = 6/√π D = 3.385 D).  The corrected 3-D velocity must be within
 * 5 % of Schiller–Naumann (the bound). */
static void test_settling_3d(void **state)
{
    (void)state;
    if (!getenv("IBM_FULL3D")) {
        print_message("  (IBM_FULL3D=1 runs the 3-D version at D/dx = 16: scripts/validate.sh)\n");
        return;
    }
    double W = 6, Lz = 24, dt = 0.05, t_end = 18, nu = sqrt(3.0 / 800.0);
    int dpd = 16;
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nnx = %d\nny = %d\nnz = %d\nlength = %g %g %g\n"
             "[boundary]\nx_lo = freeslip\nx_hi = freeslip\ny_lo = freeslip\ny_hi = freeslip\nz_lo = freeslip\n"
             "z_hi = freeslip\n[fluid]\nnu = %.17g\nviscous = implicit\ndt = %g\n"
             "[ibm]\ngravity = 0 -1 0\nsphere1 = free center %g %g %g diameter 1 density 4\n",
             (int)(W * dpd), (int)(Lz * dpd), (int)(W * dpd), W, Lz, W, nu, dt, 0.5 * W, Lz - 2.5, 0.5 * W);
    it_case_t tc = it_from_case(text);
    double sum = 0, sum1 = 0, w0 = wtime();
    int k = 0, k1 = 0;
    while (tc.f->time < t_end - 1e-9) {
        fluid_step(tc.f, dt);
        if (tc.f->time > t_end - 2 - 1e-9) sum += tc.ibm->s[0].u[1], k++;
        else if (tc.f->time > t_end - 4 - 1e-9) sum1 += tc.ibm->s[0].u[1], k1++;
        if (tc.f->step % 20 == 0)
            print_message("    t = %.2f: y = %.4f, v = %.5f, lateral drift %.1e (%.0f s)\n", tc.f->time,
                          tc.ibm->s[0].x[1], tc.ibm->s[0].u[1], hypot(tc.ibm->s[0].x[0] - 3, tc.ibm->s[0].x[2] - 3),
                          wtime() - w0);
    }
    double u3 = -sum / k, u3b = -sum1 / k1;
    it_free(&tc);
    double ua[2], Lr[2] = {W / sqrt(M_PI), 10};
    for (int i = 0; i < 2; i++) {
        settle_t a = base_case(4.0);
        a.dpd = dpd, a.Lr = Lr[i], a.Lz = Lz, a.dt = dt, a.t_end = t_end;
        run_settling(&a);
        ua[i] = -mean_velocity(&a, t_end - 2, t_end);
        settle_free(&a);
    }
    double uT = it_schiller_naumann(1.0, 4.0, 1.0, nu), k_box = ua[1] / ua[0];
    print_message("  3-D, D/dx = %d, box %g x %g x %g D: terminal velocity %.5f (%.5f two time units before); "
                  "axisymmetric, same D/dx and dt: %.5f in r <= %.3f D (the box's area), %.5f in r <= 10 D: box "
                  "correction x %.4f; corrected %.5f, Schiller-Naumann %.5f: error %+.2f %% (uncorrected %+.2f %%)\n",
                  dpd, W, Lz, W, u3, u3b, ua[0], Lr[0], ua[1], k_box, u3 * k_box, uT, 100 * (u3 * k_box / uT - 1),
                  100 * (u3 / uT - 1));
    assert_float_equal(u3 * k_box / uT, 1.0, 0.05);
    /* the 3-D sphere and its axisymmetric twin in the same cross-section agree */
    assert_float_equal(u3 / ua[0], 1.0, 0.03);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    /* IBM_TESTS=pattern runs only the matching tests (scripts/validate.sh) */
    if (getenv("IBM_TESTS")) cmocka_set_test_filter(getenv("IBM_TESTS"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_initial_acceleration),
        cmocka_unit_test(test_settling_sphere),
        cmocka_unit_test(test_density_ratios),
        cmocka_unit_test(test_rigid_model),
        cmocka_unit_test(test_free_alpha_step),
        cmocka_unit_test(test_settling_full),
        cmocka_unit_test(test_settling_3d),
    };
    TEST_MPI_RUN("ibm_settling", tests);
}
