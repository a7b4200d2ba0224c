/* test_dem_lubrication.c — Brenner lubrication with effective roughness
 * (Izard eq. 3.18, decision 5; src/dem/lubrication.c).
 * RANKS: 1 2
 *
 * Exact results used:
 *  - Lubrication alone (no gravity, no contact yet): m* du/dt = −k u/(δ+η_e)
 *    with u = −dδ/dt has the first integral u − (k/m*) L(δ) = const,
 *    L(δ) = ln(δ + η_e) (minus δ/(Δ_lub + η_e) with subtract_resolved),
 *    clamped to the active range (0, Δ_lub].  The scheme keeps it exactly
 *    (lubrication.c), so it is checked at every step to round-off, for a
 *    sphere against a wall and for a pair (reduced mass, R_eff = R/2), with
 *    momentum conserved to round-off for the pair.
 *  - One step of a pair: the approach speed after it is the root of the
 *    scheme's implicit equation, solved here by bisection in long double.
 *  - With St = m* u₀/k below ΔL = ln((Δ_lub + η_e)/η_e) the sphere stops at
 *    the gap where L(δ*) = L(δ₀) − St; above, it reaches contact at
 *    u_C = u₀ − (k/m*) ΔL, leaves it at ε_max u_C (the calibrated contact law)
 *    and is slowed again by ΔL: u_R = ε_max u_C − (k/m*) ΔL.
 *  - Stiff case (η_e/R = 1e-6, St ≈ 1, constant push): the ODE
 *    m du/dt = F − k u/(δ + η_e) integrated by a fine adaptive reference;
 *    the DEM step t_c/50 is ≫ the explicit stability limit 2m(δ+η_e)/k near
 *    contact, and the solution must stay stable and converge.
 *  - [lubrication] overlap (dry, linear law unclipped, seed calibration):
 *    with saturated the overlap obeys the damped oscillator of eq. 3.26,
 *    m* δ'' + (γ_n + 6π η_f R_eff²/η_e) δ' + k_n δ = 0, so the approach speed
 *    when the overlap closes over the one when it opens is exp(−β π/ω_d),
 *    β = (γ_n + c)/(2m*), ω_d = √(k_n/m* − β²); with off it is the dry e.
 *    The force is continuous at δ = 0 with saturated, zero inside with off.
 *  - dem_time_to_contact (the alignment of fluid steps with contacts): along
 *    the lubricated approach the time to contact is ∫₀^δ₀ dδ/u(δ) with u(δ)
 *    from the first integral (no gravity), computed here by a fine midpoint
 *    rule in ln(δ + η_e); with gravity, and for a pair, it is checked against
 *    the contact time of the DEM itself; an approach that stops (St < ΔL)
 *    never touches (INFINITY); without lubrication it is gap/u exactly.
 */
#include <gsl/gsl_rng.h>
#include <stdlib.h>
#include <string.h>

#include "../src/dem/dem_private.h"
#include "dem.h"
#include "modules.h"
#include "testutil.h"

static const double R = 1e-3, RHO = 2500, TC = 1e-4, MU = 1e-2;

/* A DEM with walls on z_lo (wall != 0) or none, lubrication roughness eta,
 * range, subtract, viscosity mu; contact_keys, lub_keys and dem_keys are
 * extra lines of [contact], [lubrication] and [dem]. */
static dem_t *make_with(int wall, double eta, double range, int subtract, double mu, int nc, double gz, double e_dry,
                        const char *contact_keys, const char *lub_keys, const char *dem_keys)
{
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nlength = 0.1 0.1 0.1\n[boundary]\nz_lo = noslip\nz_hi = noslip\n"
             "[walls]\nfaces = %s\n[contact]\nrestitution = %.17g\ncontact_time = %g\nfriction = 0.3\n%s"
             "[lubrication]\nmodel = brenner\nroughness = %.17g\nrange = %.17g\nsubtract_resolved = %s\nviscosity = %.17g\n%s"
             "[dem]\ngravity = 0 0 %.17g\nsteps_per_contact = %d\n%s",
             wall ? "z_lo" : "none", e_dry, TC, contact_keys, eta / R, range / R, subtract ? "true" : "false", mu,
             lub_keys, gz, nc, dem_keys);
    cfg_t *cfg = cfg_load_string("test.ini", text, 0, NULL);
    assert_non_null(cfg);
    return dem_create_from_config(cfg, MPI_COMM_WORLD);
}

static dem_t *make(int wall, double eta, double range, int subtract, int nc, double gz, double e_dry)
{
    return make_with(wall, eta, range, subtract, MU, nc, gz, e_dry, "", "", "");
}

static double Lpot(double delta, double eta, double range, int subtract)
{
    const double c = delta < 0 ? 0 : delta > range ? range : delta;
    return log(c + eta) - (subtract ? c / (range + eta) : 0.0);
}

/* Lone sphere against the wall: the first integral at every step, and the
 * stopping gap (St < ΔL) or the rebound velocity (St > ΔL). */
static void wall_invariant(double St, int subtract, double *worst, double *stop_or_rebound, double *vmax_after)
{
    const double eta = 1e-4 * R, range = 0.5 * R;
    dem_t *d = make(1, eta, range, subtract, 50, 0.0, 0.9);
    const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R, k = 6 * M_PI * MU * R * R;
    const double u0 = St * k / m, gap0 = 0.6 * R;
    const double x[3] = {0.05, 0.05, R + gap0}, v[3] = {0, 0, -u0};
    dem_add_particle(d, x, v, R, RHO, 0);
    const double C = u0 - k / m * Lpot(gap0, eta, range, subtract);
    *worst = 0;
    double vmax_up = 0, min_gap = 1;
    int touched = 0;
    for (long s = 0; s < 400000; s++) {
        assert_int_equal(dem_step(d), DEM_OK);
        const double gap = dem_positions(d)[2] - R, u = -dem_velocities(d)[2];
        if (gap < min_gap) min_gap = gap;
        if (gap <= 0) touched = 1;
        if (!touched) {
            const double err = fabs(u - k / m * Lpot(gap, eta, range, subtract) - C) / u0;
            if (err > *worst) *worst = err;
        }
        if (-u > vmax_up) vmax_up = -u;
        if (gap > 0.7 * R && touched) break;
        if (!touched && fabs(u) < 1e-12 * u0) break; /* stopped */
    }
    *stop_or_rebound = touched ? dem_velocities(d)[2] : min_gap;
    *vmax_after = vmax_up;
    dem_free(d);
}

static void test_wall_first_integral(void **state)
{
    (void)state;
    const double eta = 1e-4 * R, range = 0.5 * R;
    const double dL = log((range + eta) / eta); /* 8.52 */
    for (int sub = 0; sub < 2; sub++) {
        const double dLs = dL - (sub ? range / (range + eta) : 0.0);
        /* St = 5 < ΔL: stops at L(δ*) = L(Δ_lub) − St */
        double worst, stop, vmax;
        wall_invariant(5.0, sub, &worst, &stop, &vmax);
        const double expect = exp(Lpot(range, eta, range, 0) - 5.0) - eta; /* no-subtract form */
        printf("wall St=5 subtract=%d: invariant error %.2e, stop gap %.6e R", sub, worst, stop / R);
        if (!sub) printf(" (exact %.6e R)", expect / R);
        printf("\n");
        /* the invariant holds to round-off: ~1e-16 per step over ~1e4 steps of a quantity of
         * size u0 (ln terms ~ 10 u0) */
        assert_true(worst < 1e-10);
        if (!sub) assert_true(fabs(stop - expect) < 1e-6 * R + 1e-3 * expect);
        assert_true(stop > 0);
        /* St = 40 > ΔL: contact at u_C, rebound at ε u_C (largest upward velocity), then slowed by
         * ΔL again while it leaves the lubrication range */
        double rebound;
        wall_invariant(40.0, sub, &worst, &rebound, &vmax);
        const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R, k = 6 * M_PI * MU * R * R;
        const double u0 = 40.0 * k / m, uC = u0 - k / m * dLs;
        const double uR = 0.9 * uC - k / m * dLs;
        printf("wall St=40 subtract=%d: invariant error %.2e, after contact %.6f u0 (exact %.6f), leaving the range "
               "%.6f u0 (exact %.6f u0)\n",
               sub, worst, vmax / u0, 0.9 * uC / u0, rebound / u0, uR / u0);
        assert_true(worst < 1e-10);
        /* the dry contact law's restitution error at t_c/dt = 50 is < 0.25 % of e (test_dem_collisions),
         * and the lubrication after the contact adds no error of its own */
        assert_true(fabs(vmax - 0.9 * uC) < 0.0025 * 0.9 * uC);
        assert_true(fabs(rebound - uR) < 0.0025 * 0.9 * uC);
    }
}

/* A pair of equal spheres head-on: relative first integral with m* = m/2,
 * k = 6πη(R/2)², and momentum. */
static void test_pair_first_integral(void **state)
{
    (void)state;
    const double eta = 2e-4 * R, range = 0.5 * R;
    dem_t *d = make(0, eta, range, 0, 50, 0.0, 0.9);
    const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R, ms = 0.5 * m, k = 6 * M_PI * MU * 0.25 * R * R;
    const double St = 6.0, u0 = St * k / ms, gap0 = 0.55 * R;
    const double xa[3] = {0.05, 0.05, 0.05 - R - gap0 / 2}, xb[3] = {0.05, 0.05, 0.05 + R + gap0 / 2};
    const double va[3] = {0, 0, 0.75 * u0}, vb[3] = {0, 0, -0.25 * u0};
    dem_add_particle(d, xa, va, R, RHO, 0);
    dem_add_particle(d, xb, vb, R, RHO, 0);
    const double C = u0 - k / ms * Lpot(gap0, eta, range, 0), P0 = m * 0.5 * u0;
    double worst = 0, worst_p = 0;
    for (long s = 0; s < 20000; s++) {
        assert_int_equal(dem_step(d), DEM_OK);
        const double *x = dem_positions(d), *v = dem_velocities(d);
        const long *id = dem_ids(d);
        const int a = id[0] == 0 ? 0 : 1, b = 1 - a;
        const double gap = x[3 * b + 2] - x[3 * a + 2] - 2 * R, u = v[3 * a + 2] - v[3 * b + 2];
        assert_true(gap > 0);
        worst = fmax(worst, fabs(u - k / ms * Lpot(gap, eta, range, 0) - C) / u0);
        worst_p = fmax(worst_p, fabs(m * (v[2] + v[5]) - P0) / P0);
    }
    const double *x = dem_positions(d);
    const double gap_end = fabs(x[5] - x[2]) - 2 * R, expect = exp(Lpot(gap0, eta, range, 0) - St) - eta;
    printf("pair St=6: invariant error %.2e, momentum error %.2e, final gap %.6e R (exact %.6e R)\n", worst,
           worst_p, gap_end / R, expect / R);
    /* Newton tolerance 1e-14 |u| per step, 2e4 steps, plus rounding; the momentum changes only by
     * the rounding of the two velocity updates of each step (±J/m, velocities up to 2 P0/m): a
     * random walk of 2e4 steps of a few 1e-16 P0, measured 0.9–1.2e-13 */
    assert_true(worst < 1e-9);
    assert_true(worst_p < 5e-13);
    assert_true(fabs(gap_end - expect) < 1e-6 * expect);
    dem_free(d);
}

/* Reference for the stiff case: m u' = F − k u/(δ+η), δ' = −u, by RK4 in
 * the variable s = ln(δ + η) with many small steps (smooth in s). */
static double stiff_reference_gap(double F, double m, double k, double eta, double gap0, double u0, double T)
{
    /* integrate in time with an adaptive step limited by the local rate k/(m(δ+η)) */
    double t = 0, g = gap0, u = u0;
    while (t < T) {
        const double rate = k / (m * (g + eta)) + fabs(u) / (g + eta);
        double h = 0.01 / rate;
        if (t + h > T) h = T - t;
#define RHS(G, U, dg, du) ((dg) = -(U), (du) = (F - k * (U) / ((G) + eta)) / m)
        double g1, u1, g2, u2, g3, u3, g4, u4;
        RHS(g, u, g1, u1);
        RHS(g + 0.5 * h * g1, u + 0.5 * h * u1, g2, u2);
        RHS(g + 0.5 * h * g2, u + 0.5 * h * u2, g3, u3);
        RHS(g + h * g3, u + h * u3, g4, u4);
#undef RHS
        g += h / 6 * (g1 + 2 * g2 + 2 * g3 + g4);
        u += h / 6 * (u1 + 2 * u2 + 2 * u3 + u4);
        t += h;
    }
    return g;
}

static double stiff_run(int nc, double T, double *gap_T, double *stiffness, int *bounced)
{
    const double eta = 1e-6 * R, range = 0.5 * R, gz = -9.81;
    dem_t *d = make(1, eta, range, 0, nc, gz, 0.97);
    const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R, k = 6 * M_PI * MU * R * R;
    const double u0 = 1.0 * k / m; /* St = 1 */
    const double gap0 = 0.4 * R;
    const double x[3] = {0.05, 0.05, R + gap0}, v[3] = {0, 0, -u0};
    dem_add_particle(d, x, v, R, RHO, 0);
    const double dt = TC / nc;
    const long n = lround(T / dt);
    *stiffness = 0;
    *bounced = 0;
    for (long s = 0; s < n; s++) {
        assert_int_equal(dem_step(d), DEM_OK);
        const double gap = dem_positions(d)[2] - R, vz = dem_velocities(d)[2];
        assert_true(isfinite(gap) && gap > -0.01 * R);
        *stiffness = fmax(*stiffness, k * dt / (m * (fmax(gap, 0) + eta)));
        if (vz > 1e-3 * u0) *bounced = 1;
    }
    *gap_T = dem_positions(d)[2] - R;
    dem_free(d);
    return stiff_reference_gap(m * fabs(gz), m, k, eta, gap0, u0, n * dt);
}

static void test_stiff_small_roughness(void **state)
{
    (void)state;
    /* T: the gap falls from 0.4 R to ~1e-5 R, where k dt/(m(δ+η)) > 2: an explicit
     * treatment of the lubrication would be unstable there (Mongruel's linear regime:
     * δ + η decays as exp(−t m g/k), k/(m g) = 1.8 ms) */
    const double T = 0.019;
    double e[3], ref[3];
    const int ncs[3] = {50, 100, 200};
    for (int q = 0; q < 3; q++) {
        double gapT, stiff;
        int bounced;
        ref[q] = stiff_run(ncs[q], T, &gapT, &stiff, &bounced);
        e[q] = fabs(gapT - ref[q]) / ref[q];
        printf("stiff eta/R=1e-6 St=1 t_c/dt=%d: gap(T) %.6e R, reference %.6e R, rel. error %.2e, max k dt/(m(δ+η)) %.3g, "
               "bounced %d\n",
               ncs[q], gapT / R, ref[q] / R, e[q], stiff, bounced);
        assert_false(bounced); /* St = 1 ≪ St_c: no rebound */
        if (q == 0) assert_true(stiff > 2.0); /* beyond the explicit stability limit: the test is stiff */
    }
    const double p1 = conv_order(e[0], e[1], 2), p2 = conv_order(e[1], e[2], 2);
    printf("stiff case: orders %.2f %.2f\n", p1, p2);
    /* first order at least (the lubrication impulse is implicit in the gap, the push explicit) */
    assert_true(p1 > 0.8 && p2 > 0.8);
    assert_true(e[0] < 0.05);
}

/* ---- [lubrication] overlap: off | saturated ---- */

/* Overlap tests: the linear law unclipped with the seed's calibration (eq. 3.16–3.17: G = −2 ln e/t_c,
 * K = π²/t_c² + G²/4 per unit effective mass), so that the normal force stays linear in (δ, δ̇) until the
 * overlap closes and the contact is exactly the oscillator of eq. 3.26 (no clip, eq. 3.13, to account for). */
static const double OV_ETA = 1e-3 * R, OV_RANGE = 0.5 * R, OV_EDRY = 0.9;
static const char OV_CONTACT[] = "calibration = seed\nnormal_clip = false\n";

static dem_t *make_overlap(int wall, const char *mode, int subtract, double mu, int nc)
{
    char lub[64];
    snprintf(lub, sizeof lub, "overlap = %s\n", mode);
    return make_with(wall, OV_ETA, OV_RANGE, subtract, mu, nc, 0.0, OV_EDRY, OV_CONTACT, lub, "max_overlap = 0.05\n");
}

/* Restitution of the oscillator δ'' + 2β δ' + K δ = 0 from δ = 0 back to δ = 0: exp(−β π/ω_d). */
static double oscillator_restitution(double K, double beta) { return exp(-beta * M_PI / sqrt(K - beta * beta)); }

/* One DEM step; the gap and the approach speed after it (particle 0 and the wall, or particles 0 and 1). */
static void overlap_step(dem_t *d, int wall, double *gap, double *u)
{
    assert_int_equal(dem_step(d), DEM_OK);
    const double *x = dem_positions(d), *v = dem_velocities(d);
    if (wall) {
        *gap = x[2] - R;
        *u = -v[2];
    } else {
        const int a = dem_ids(d)[0] == 0 ? 0 : 1, b = 1 - a;
        *gap = x[3 * b + 2] - x[3 * a + 2] - 2 * R;
        *u = v[3 * a + 2] - v[3 * b + 2];
    }
}

/* Normal collision with the wall (wall != 0) or of two equal spheres head-on, starting in the film at
 * gap 0.02 R with approach speed u0.  Returns u_off/u_on, the approach speeds when the overlap opens and
 * closes.  They are taken from the last step before the overlap and the first after it (gap δ > 0 at both
 * ends of the step) through the first integral of the film, u − (k/m*) L(δ) = const (exact in the
 * scheme, test_wall_first_integral): u(δ = 0) = u − (k/m*) (L(δ) − L(0)).  What is compared with the
 * oscillator is then the motion while overlapping, the steps across δ = 0 included. */
static double overlap_collision(int wall, const char *mode, int subtract, double mu, int nc, double u0)
{
    dem_t *d = make_overlap(wall, mode, subtract, mu, nc);
    const double gap_start = 0.02 * R, m = RHO * 4.0 / 3.0 * M_PI * R * R * R;
    const double ms = wall ? m : 0.5 * m, reff = wall ? R : 0.5 * R, kl = 6 * M_PI * mu * reff * reff / ms;
    if (wall) {
        const double x[3] = {0.05, 0.05, R + gap_start}, v[3] = {0, 0, -u0};
        dem_add_particle(d, x, v, R, RHO, 0);
    } else {
        const double xa[3] = {0.05, 0.05, 0.05 - R - gap_start / 2}, xb[3] = {0.05, 0.05, 0.05 + R + gap_start / 2};
        const double va[3] = {0, 0, u0 / 2}, vb[3] = {0, 0, -u0 / 2};
        dem_add_particle(d, xa, va, R, RHO, 0);
        dem_add_particle(d, xb, vb, R, RHO, 0);
    }
    const double L0 = Lpot(0.0, OV_ETA, OV_RANGE, subtract);
    double gap_prev = gap_start, u_prev = u0, u_on = NAN, u_off = NAN;
    for (long s = 0; s < 100L * nc && isnan(u_off); s++) {
        double gap, u;
        overlap_step(d, wall, &gap, &u);
        if (gap_prev > 0 && gap <= 0 && isnan(u_on)) u_on = u_prev - kl * (Lpot(gap_prev, OV_ETA, OV_RANGE, subtract) - L0);
        if (gap_prev <= 0 && gap > 0 && !isnan(u_on)) {
            /* the first step that ends outside may have started inside: take the next one */
            overlap_step(d, wall, &gap, &u);
            assert_true(gap > 0);
            u_off = -(u - kl * (Lpot(gap, OV_ETA, OV_RANGE, subtract) - L0));
        }
        gap_prev = gap;
        u_prev = u;
    }
    dem_free(d);
    assert_false(isnan(u_off));
    return u_off / u_on;
}

/* Viscosity giving the saturated lubrication damping c/m* = 6π η_f R_eff² (1/η_e [− 1/(Δ_lub + η_e)])/m* the
 * value rate (1/s); the same R_eff²/m* ratio for the wall (R, m) and the pair (R/2, m/2) up to the factor 2. */
static double overlap_rate_to_viscosity(int wall, int subtract, double rate)
{
    const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R, ms = wall ? m : 0.5 * m, reff = wall ? R : 0.5 * R;
    const double slope = 1.0 / OV_ETA - (subtract ? 1.0 / (OV_RANGE + OV_ETA) : 0.0);
    return rate * ms / (6 * M_PI * reff * reff * slope);
}

/* saturated: while overlapping the contact is the damped oscillator of eq. 3.26 with damping γ_n +
 * 6π η_f R_eff²/η_e, so u_off/u_on = exp(−β π/ω_d), β = (G + c/m*)/2, ω_d = √(K − β²); off: nothing acts
 * while overlapping and u_off/u_on is the dry restitution e of the unclipped seed law.  At 2–4 DEM
 * step sizes, for a particle against the wall (subtract_resolved false and true) and a head-on pair. */
static void test_overlap_restitution(void **state)
{
    (void)state;
    const double G = -2.0 * log(OV_EDRY) / TC, K = M_PI * M_PI / (TC * TC) + 0.25 * G * G;
    const double rate = 1.0 / TC; /* c/m* t_c = 1: the lubrication damping is ~5× γ_n (G t_c = 0.21) */
    const double u0 = 0.2;        /* St = m* u0/k = u0/(rate η_e) = 20 > ΔL = ln(501) = 6.2: it reaches contact */
    const int ncs[3] = {100, 200, 400};
    struct {
        int wall, subtract;
        const char *mode;
    } cases[] = {{1, 0, "saturated"}, {1, 1, "saturated"}, {0, 0, "saturated"}, {1, 0, "off"}, {0, 0, "off"}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const int saturated = !strcmp(cases[c].mode, "saturated");
        const double mu = overlap_rate_to_viscosity(cases[c].wall, cases[c].subtract, rate);
        const double exact = saturated ? oscillator_restitution(K, 0.5 * (G + rate)) : OV_EDRY;
        double err[3];
        for (int q = 0; q < 3; q++) {
            const double e = overlap_collision(cases[c].wall, cases[c].mode, cases[c].subtract, mu, ncs[q], u0);
            err[q] = fabs(e - exact) / exact;
            printf("overlap = %s, %s, subtract %d, t_c/dt = %d: u_off/u_on %.8f, exact %.8f, rel. error %.2e\n",
                   cases[c].mode, cases[c].wall ? "wall" : "pair", cases[c].subtract, ncs[q], e, exact, err[q]);
        }
        const double p = conv_order(err[1], err[2], 2);
        printf("  order %.2f\n", p);
        if (saturated) {
            /* The damping impulse is implicit in the half-step velocity (backward Euler in u, lubrication.c):
             * first order, measured 1.01e-3, 5.1e-4, 2.6e-4 (order 1.00) at t_c/dt = 100, 200, 400 in all
             * three set-ups; 5e-4 at 400 leaves a factor 2, while a wrong damping (γ_n alone: 0.90, c alone:
             * 0.60, c/2: 0.71) is off by > 10 %. */
            assert_true(p > 0.8 && p < 1.3);
            assert_true(err[2] < 5e-4);
        } else {
            /* Nothing acts while overlapping: the velocity Verlet contact of the dry law, second order
             * (measured 5.2e-5, 1.5e-5, 3.5e-6, order 2.04); any lubrication inside the contact (c/m* t_c = 1)
             * would lower it by ~40 %. */
            assert_true(p > 1.7);
            assert_true(err[2] < 1e-5);
        }
    }
}

/* The force is continuous at δ = 0 with saturated (it keeps the Brenner value k u/η_e there) and zero
 * while overlapping with off: one DEM step (t_c/1000, so that the gap moves by 1e-4 η_e and the implicit
 * impulse changes u by c dt/m = 1e-3) from δ₀ = ±1e-3 η_e. */
static void test_overlap_force_at_contact(void **state)
{
    (void)state;
    const double rate = 1.0 / TC, mu = overlap_rate_to_viscosity(1, 0, rate);
    const double k = 6 * M_PI * mu * R * R, u = 1e-3, brenner0 = k * u / OV_ETA;
    double F[2][2]; /* [off, saturated][δ₀ > 0, δ₀ < 0]: lubrication force on the particle, along +z */
    for (int mode = 0; mode < 2; mode++)
        for (int side = 0; side < 2; side++) {
            dem_t *d = make_overlap(1, mode ? "saturated" : "off", 0, mu, 1000);
            const double x[3] = {0.05, 0.05, R + (side ? -1e-3 : 1e-3) * OV_ETA}, v[3] = {0, 0, -u};
            dem_add_particle(d, x, v, R, RHO, 0);
            assert_int_equal(dem_step(d), DEM_OK);
            F[mode][side] = dem_lubrication_forces(d)[2];
            dem_free(d);
        }
    printf("lubrication force / (6 pi eta_f R^2 u/eta_e) at delta = +-1e-3 eta_e: off %.6f / %.6f, saturated %.6f / %.6f "
           "(c dt/m = %.1e)\n",
           F[0][0] / brenner0, F[0][1] / brenner0, F[1][0] / brenner0, F[1][1] / brenner0, rate * TC / 1000);
    /* off: exactly nothing while overlapping (the step starts and ends with δ < 0) */
    assert_true(F[0][1] == 0.0);
    /* saturated: the Brenner value at δ = 0, lowered by the implicit step (u′ = u/(1 + c dt/m), 1e-3) and
     * the contact's opening half kick (γ_n dt/(2m) = 1e-4): measured 0.99885 */
    assert_true(fabs(F[1][1] / brenner0 - 1) < 2e-3);
    /* continuous: the film at δ₀ = +1e-3 η_e is 1e-3 thicker; measured jump 7.9e-4 (off: 100 %) */
    assert_true(fabs(F[1][0] / F[1][1] - 1) < 2e-3);
    /* outside the overlap both modes solve the same equation, to the Newton tolerance 1e-15 (|u′| + scale)
     * on u′, where scale is k ΔL/m* = 63 u (off) or u (saturated): ≤ 6e-11 of the impulse (1e-3 m* u);
     * measured 2e-12 */
    assert_true(fabs(F[1][0] / F[0][0] - 1) < 1e-9);
}

/* The DEM's own time to the first contact of particle 0 (with the wall, or with
 * particle 1): steps until a contact force appears, the onset placed
 * at the step's end (resolution t_c/nc). */
static double dem_contact_onset(dem_t *d)
{
    for (long s = 0; s < 2000000; s++) {
        assert_int_equal(dem_step(d), DEM_OK);
        if (dem_in_contact(d, 0)) return dem_time(d);
    }
    return INFINITY;
}

static void test_time_to_contact(void **state)
{
    (void)state;
    const double eta = 1e-4 * R, range = 0.5 * R, m = RHO * 4.0 / 3.0 * M_PI * R * R * R, k = 6 * M_PI * MU * R * R;
    const double gap0 = 0.4 * R;
    const int nc = 200; /* DEM step t_c/200: the measured onset is within t_c/200 of the prediction */
    for (int sub = 0; sub < 2; sub++) {
        /* 1. lubrication alone, St = 12 > ΔL (8.5): the first integral's u(δ), integrated finely */
        const double u0 = 12.0 * k / m, C = u0 - k / m * Lpot(gap0, eta, range, sub);
        double tref = 0.0;
        const int N = 200000;
        const double s0 = log(eta), s1 = log(gap0 + eta), h = (s1 - s0) / N;
        for (int q = 0; q < N; q++) {
            const double sm = s0 + (q + 0.5) * h, delta = exp(sm) - eta;
            tref += h * (delta + eta) / (C + k / m * Lpot(delta, eta, range, sub));
        }
        dem_t *d = make(1, eta, range, sub, nc, 0.0, 0.9);
        const double x[3] = {0.05, 0.05, R + gap0}, v[3] = {0, 0, -u0};
        dem_add_particle(d, x, v, R, RHO, 0);
        const double t = dem_time_to_contact(d, INFINITY), t_dem = dem_contact_onset(d);
        printf("time to contact, wall, St 12, subtract %d: predicted %.8e, fine quadrature %.8e (%.1e), DEM %.8e "
               "(%.2f DEM steps); constant velocity %.3e\n",
               sub, t, tref, t / tref - 1, t_dem, (t_dem - t) / (TC / nc), gap0 / u0);
        /* RK4 in ln(δ + η_e), 2 × 48 steps: measured 2e-7 relative.  The DEM keeps the first
         * integral exactly, and sees the contact force at the end of the step after the overlap
         * begins: its onset lies 0-2 of its steps after the exact time (measured 1.26) */
        assert_true(fabs(t / tref - 1) < 1e-5);
        assert_true(t_dem >= t && t_dem - t < 2.0 * TC / nc);
        /* the constant-velocity estimate misses the slow-down: 9 % early here, 378 DEM steps */
        assert_true(gap0 / u0 < 0.95 * t);
        dem_free(d);
        /* 2. St = 5 < ΔL: the approach stops, no contact */
        d = make(1, eta, range, sub, nc, 0.0, 0.9);
        const double v5[3] = {0, 0, -5.0 * k / m};
        dem_add_particle(d, x, v5, R, RHO, 0);
        assert_true(isinf(dem_time_to_contact(d, INFINITY)));
        dem_free(d);
    }
    /* 3. with gravity towards the wall (the constant acceleration of the prediction), St = 6 at the
     * start: without gravity it would stop; g accelerates it into contact */
    {
        const double u0 = 6.0 * k / m, g = 40.0;
        dem_t *d = make(1, eta, range, 0, nc, -g, 0.9);
        const double x[3] = {0.05, 0.05, R + gap0}, v[3] = {0, 0, -u0};
        dem_add_particle(d, x, v, R, RHO, 0);
        const double t = dem_time_to_contact(d, INFINITY), t_dem = dem_contact_onset(d);
        printf("time to contact, wall, St 6 with gravity %.0f: predicted %.8e, DEM %.8e (%.2f DEM steps)\n", g, t,
               t_dem, (t_dem - t) / (TC / nc));
        /* the onset 0-2 DEM steps after the prediction as above; the constant force enters the
         * DEM's kick-drift splitting, so one step of slack before it */
        assert_true(isfinite(t) && t_dem - t > -1.0 * TC / nc && t_dem - t < 2.0 * TC / nc);
        dem_free(d);
    }
    /* 4. a head-on pair (reduced mass m/2, R_eff = R/2): DEM onset */
    {
        const double u0 = 12.0 * k / m; /* relative speed; St of the pair m* u/k_eff = 24 */
        dem_t *d = make(0, eta, range, 0, nc, 0.0, 0.9);
        const double x0[3] = {0.05, 0.05, 0.05}, x1[3] = {0.05, 0.05, 0.05 + 2 * R + gap0};
        const double v0[3] = {0, 0, 0.5 * u0}, v1[3] = {0, 0, -0.5 * u0};
        dem_add_particle(d, x0, v0, R, RHO, 0);
        dem_add_particle(d, x1, v1, R, RHO, 0);
        dem_step(d); /* the neighbour lists */
        const double t0 = dem_time(d), t = dem_time_to_contact(d, INFINITY), t_dem = dem_contact_onset(d) - t0;
        printf("time to contact, pair: predicted %.8e, DEM %.8e (%.2f DEM steps); constant velocity %.3e\n", t, t_dem,
               (t_dem - t) / (TC / nc), gap0 / u0);
        assert_true(isfinite(t) && t_dem >= t && t_dem - t < 2.0 * TC / nc);
        dem_free(d);
    }
    /* 5. without lubrication: gap/u exactly */
    {
        dem_t *d = make(1, eta, range, 0, nc, 0.0, 0.9);
        d->lub.on = 0; /* the same scene without its lubrication */
        const double u0 = 0.1, x[3] = {0.05, 0.05, R + gap0}, v[3] = {0, 0, -u0};
        dem_add_particle(d, x, v, R, RHO, 0);
        assert_true(dem_time_to_contact(d, INFINITY) == (x[2] - R) / u0);
        dem_free(d);
    }
}

/* ---- model = correction (only what the grid does not resolve) ---------------------------- */

/* A DEM with lubrication model = correction (cut-offs in cells of h) and extra [lubrication] lines. */
static dem_t *make_correction_in(double L, int wall, double eta, double cutoff, double tcutoff, int tangential, double h,
                                 int nc, double gz, const char *lub_keys)
{
    char lines[512];
    snprintf(lines, sizeof lines, "cutoff = %.17g\ntangential_cutoff = %.17g\ntangential = %s\n%s", cutoff, tcutoff,
             tangential ? "true" : "false", lub_keys);
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nlength = %g %g %g\n[boundary]\nz_lo = noslip\nz_hi = noslip\n"
             "[walls]\nfaces = %s\n[contact]\nrestitution = 0.9\ncontact_time = %g\nfriction = 0.3\n"
             "[lubrication]\nmodel = correction\nroughness = %.17g\nviscosity = %.17g\n%s"
             "[dem]\ngravity = 0 0 %.17g\nsteps_per_contact = %d\n",
             L, L, L, wall ? "z_lo" : "none", TC, eta / R, MU, lines, gz, nc);
    cfg_t *cfg = cfg_load_string("test.ini", text, 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    dem_lubrication_set_grid(d, h);
    return d;
}

static dem_t *make_correction(int wall, double eta, double cutoff, double tcutoff, int tangential, double h, int nc,
                              double gz, const char *lub_keys)
{
    return make_correction_in(0.1, wall, eta, cutoff, tcutoff, tangential, h, nc, gz, lub_keys);
}

/* The normal part of the correction is Brenner's force less its value at cutoff × h, i.e. brenner
 * with range = cutoff h and subtract_resolved; without a grid it is brenner up to range × R.  The
 * same bounce (St 40 against a wall) must be bit-identical. */
static void test_correction_normal(void **state)
{
    (void)state;
    const double eta = 1e-4 * R, h = 0.1 * R, cutoff = 1.1;
    const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R, k = 6 * M_PI * MU * R * R, u0 = 40.0 * k / m;
    for (int grid = 0; grid < 2; grid++) {
        dem_t *a = make_correction(1, eta, cutoff, 1.0, 0, grid ? h : 0.0, 50, 0.0, "range = 0.5\n");
        dem_t *b = grid ? make_with(1, eta, cutoff * h, 1, MU, 50, 0.0, 0.9, "", "", "")
                        : make_with(1, eta, 0.5 * R, 0, MU, 50, 0.0, 0.9, "", "", "");
        const double x[3] = {0.05, 0.05, R + 0.6 * R}, v[3] = {0, 0, -u0};
        dem_add_particle(a, x, v, R, RHO, 0);
        dem_add_particle(b, x, v, R, RHO, 0);
        long differ = 0, steps = 0;
        double vmin = 0;
        for (; steps < 20000; steps++) {
            assert_int_equal(dem_step(a), DEM_OK);
            assert_int_equal(dem_step(b), DEM_OK);
            differ += dem_positions(a)[2] != dem_positions(b)[2] || dem_velocities(a)[2] != dem_velocities(b)[2];
            vmin = fmin(vmin, dem_velocities(a)[2]);
            if (dem_positions(a)[2] > 1.7 * R && dem_velocities(a)[2] > 0) break;
        }
        printf("correction %s a grid: %ld of %ld steps differ from brenner %s\n", grid ? "with" : "without", differ,
               steps, grid ? "(range = cutoff h, subtract_resolved)" : "(range 0.5 R)");
        assert_int_equal(differ, 0);
        assert_true(dem_velocities(a)[2] > 0); /* it bounced */
        dem_free(a);
        dem_free(b);
    }
}

/* Tangential terms against a wall (Goldman, Cox & Brenner 1967): a sphere at a fixed gap δ
 * (no normal motion, no gravity) sliding at u along x and spinning at ω about y obeys, with
 * w = Rω, ℓ = ln((δ_t + η)/(δ + η)) and c = πμRℓ/m,
 *   du/dt = c (−16/5 u + 4/5 w),   dw/dt = c (2 u − 8 w)
 * (F = −6πμRℓ[8/15 u_t + 2/15 R ω × n], T = −8πμR²ℓ[1/10 n × u_t + 2/5 R ω_t], n towards the
 * wall, I = 2/5 m R²).  The DEM applies the terms explicitly: first order in its step. */
static void test_tangential_wall_exact(void **state)
{
    (void)state;
    const double eta = 1e-4 * R, h = 0.1 * R, delta = 0.03 * R, tcut = 1.1;
    const double m = RHO * 4.0 / 3.0 * M_PI * R * R * R;
    const double ell = log((tcut * h + eta) / (delta + eta)), c = M_PI * MU * R * ell / m;
    const double T = 0.3 / c; /* about one decay time of the slow mode (rate 2.9 c) */
    /* exact: x(T) = exp(A T) x0 with A = c [[-16/5, 4/5], [2, -8]], by its eigenvectors */
    const double a11 = -3.2 * c, a12 = 0.8 * c, a21 = 2.0 * c, a22 = -8.0 * c;
    const double tr = a11 + a22, det = a11 * a22 - a12 * a21, disc = sqrt(tr * tr / 4 - det);
    const double l1 = tr / 2 + disc, l2 = tr / 2 - disc;
    const double u0 = 1e-3, w0 = -0.5e-3; /* spinning against rolling */
    /* x(t) = e^{l1 t} P1 x0 + e^{l2 t} P2 x0, P1 = (A − l2 I)/(l1 − l2), P2 = (l1 I − A)/(l1 − l2) */
    const double e1 = exp(l1 * T), e2 = exp(l2 * T), dl = l1 - l2;
    const double uex = (e1 * ((a11 - l2) * u0 + a12 * w0) + e2 * ((l1 - a11) * u0 - a12 * w0)) / dl;
    const double wex = (e1 * (a21 * u0 + (a22 - l2) * w0) + e2 * (-a21 * u0 + (l1 - a22) * w0)) / dl;
    double err[2];
    for (int q = 0; q < 2; q++) {
        const int nc = q ? 100 : 50;
        dem_t *d = make_correction(1, eta, 1.1, tcut, 1, h, nc, 0.0, "");
        const double x[3] = {0.05, 0.05, R + delta}, v[3] = {u0, 0, 0};
        dem_add_particle(d, x, v, R, RHO, 0);
        d->w[1] = w0 / R;
        const double dt = TC / nc;
        const long n = lround(T / dt);
        for (long s = 0; s < n; s++) assert_int_equal(dem_step(d), DEM_OK);
        dem_sync_velocities(d);
        const double u = dem_velocities(d)[0], w = R * d->w[1], t = n * dt;
        /* exact at the DEM's end time t (n dt, within dt/2 of T): re-evaluate */
        const double f1 = exp(l1 * t), f2 = exp(l2 * t);
        const double ue = (f1 * ((a11 - l2) * u0 + a12 * w0) + f2 * ((l1 - a11) * u0 - a12 * w0)) / dl;
        const double we = (f1 * (a21 * u0 + (a22 - l2) * w0) + f2 * (-a21 * u0 + (l1 - a22) * w0)) / dl;
        err[q] = fmax(fabs(u - ue), fabs(w - we)) / u0;
        printf("tangential, wall, t_c/dt = %d, %ld steps: u %.8e (exact %.8e), R omega %.8e (exact %.8e), error %.2e; "
               "gap drift %.1e R\n",
               nc, n, u, ue, w, we, err[q], (dem_positions(d)[2] - R - delta) / R);
        assert_true(fabs(dem_positions(d)[2] - R - delta) < 1e-12 * R);
        dem_free(d);
    }
    (void)uex, (void)wex;
    const double order = log2(err[0] / err[1]);
    printf("tangential, wall: order %.3f\n", order);
    /* explicit impulses: first order; the error at t_c/dt = 100 is 2e-6 of u0 (measured) */
    assert_true(order > 0.9 && order < 1.1);
    assert_true(err[1] < 1e-5);
}

/* Tangential terms of a pair: momentum conserved to round-off, energy dissipated for random
 * motions (the resistance is symmetric and positive), angular momentum about a common point
 * conserved for equal spheres (to O(δ/R): the lever arm is R_i + R_j + δ), and a sphere against a
 * very large one (κ = 10⁴, held fixed) acts as against a wall. */
static void test_tangential_pair_properties(void **state)
{
    (void)state;
    const double eta = 1e-4 * R, h = 0.1 * R, delta = 0.02 * R;
    unsigned long long seed = 12345;
#define RND() ((seed = seed * 6364136223846793005ULL + 1442695040888963407ULL), ((double)(seed >> 11) / 9007199254740992.0) - 0.5)
    double worst_p = 0, worst_L = 0, max_dE = -INFINITY;
    for (int trial = 0; trial < 40; trial++) {
        const double kap = trial % 2 ? 1.0 : 2.5, Rj = kap * R;
        dem_t *d = make_correction(0, eta, 1.1, 1.1, 1, h, 50, 0.0, "");
        double n[3] = {RND(), RND(), RND()};
        const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int a = 0; a < 3; a++) n[a] /= nn;
        const double xi[3] = {0.05, 0.05, 0.05};
        double xj[3], vi[3], vj[3];
        for (int a = 0; a < 3; a++) {
            xj[a] = xi[a] + (R + Rj + delta) * n[a];
            vi[a] = 1e-3 * RND();
            vj[a] = 1e-3 * RND();
        }
        /* no relative normal motion: only the tangential terms act */
        double un = 0;
        for (int a = 0; a < 3; a++) un += (vj[a] - vi[a]) * n[a];
        for (int a = 0; a < 3; a++) vj[a] -= un * n[a];
        dem_add_particle(d, xi, vi, R, RHO, 0);
        dem_add_particle(d, xj, vj, Rj, RHO, 0);
        for (int p = 0; p < 2; p++)
            for (int a = 0; a < 3; a++) d->w[3 * p + a] = 1e-3 / R * RND();
        assert_int_equal(dem_step(d), DEM_OK); /* lists; then one measured step */
        dem_sync_velocities(d);
        double P0[3] = {0}, L0[3] = {0}, E0 = 0;
        for (int p = 0; p < 2; p++) {
            const double mp = 1.0 / d->invm[p], Ip = 1.0 / d->invI[p], *x = d->x + 3 * p, *v = d->v + 3 * p,
                         *w = d->w + 3 * p;
            for (int a = 0; a < 3; a++) {
                P0[a] += mp * v[a];
                L0[a] += Ip * w[a] + mp * (x[(a + 1) % 3] * v[(a + 2) % 3] - x[(a + 2) % 3] * v[(a + 1) % 3]);
                E0 += 0.5 * (mp * v[a] * v[a] + Ip * w[a] * w[a]);
            }
        }
        double S0[3] = {0};
        for (int p = 0; p < 2; p++)
            for (int a = 0; a < 3; a++) S0[a] += d->w[3 * p + a] / d->invI[p];
        assert_int_equal(dem_step(d), DEM_OK);
        dem_sync_velocities(d);
        double P1[3] = {0}, L1[3] = {0}, S1[3] = {0}, E1 = 0, pscale = 0;
        for (int p = 0; p < 2; p++) {
            const double mp = 1.0 / d->invm[p], Ip = 1.0 / d->invI[p], *x = d->x + 3 * p, *v = d->v + 3 * p,
                         *w = d->w + 3 * p;
            for (int a = 0; a < 3; a++) {
                P1[a] += mp * v[a];
                L1[a] += Ip * w[a] + mp * (x[(a + 1) % 3] * v[(a + 2) % 3] - x[(a + 2) % 3] * v[(a + 1) % 3]);
                S1[a] += Ip * w[a];
                E1 += 0.5 * (mp * v[a] * v[a] + Ip * w[a] * w[a]);
            }
            pscale += mp * 1e-3;
        }
        /* momentum relative to the particles' own; angular momentum relative to the change of the
         * spins the torques make over the step */
        double dP = 0, dL = 0, dS = 0;
        for (int a = 0; a < 3; a++) {
            dP = fmax(dP, fabs(P1[a] - P0[a]) / pscale);
            dL = fmax(dL, fabs(L1[a] - L0[a]));
            dS = fmax(dS, fabs(S1[a] - S0[a]));
        }
        dL /= dS;
        worst_p = fmax(worst_p, dP);
        if (kap == 1.0) worst_L = fmax(worst_L, dL);
        max_dE = fmax(max_dE, (E1 - E0) / E0);
        dem_free(d);
    }
#undef RND
    printf("tangential, pair, 40 random motions: momentum change %.1e, angular momentum change (equal spheres) %.1e, "
           "largest relative energy change %.2e (must be < 0)\n",
           worst_p, worst_L, max_dE);
    assert_true(worst_p < 1e-14);
    assert_true(max_dE < 0);
    /* the leading terms balance the torques about a common point for equal spheres with the lever
     * arm 2R; the arm is 2R + δ: an imbalance of order δ/(2R) = 1 % of the spin change */
    assert_true(worst_L < 0.02);

    /* κ = 10⁴ (the large sphere fixed) against the wall formula */
    double dv[2][6];
    for (int wall = 0; wall < 2; wall++) {
        const double big = 1e4 * R, L = 50 * big;
        dem_t *d = make_correction_in(L, wall, eta, 1.1, 1.1, 1, h, 50, 0.0, "");
        const double zi = wall ? R + delta : 0.5 * L + big + R + delta;
        const double xi[3] = {0.5 * L, 0.5 * L, zi}, vi[3] = {2e-3, -1e-3, 0};
        dem_add_particle(d, xi, vi, R, RHO, 0);
        if (!wall) {
            const double xb[3] = {0.5 * L, 0.5 * L, 0.5 * L}, zero[3] = {0, 0, 0};
            dem_add_particle(d, xb, zero, big, RHO, 1);
        }
        const int i = dem_ids(d)[0] == 0 ? 0 : 1;
        d->w[3 * i] = 1.5, d->w[3 * i + 1] = -0.7, d->w[3 * i + 2] = 0.3;
        assert_int_equal(dem_step(d), DEM_OK);
        dem_sync_velocities(d);
        const double v0[3] = {d->v[3 * i], d->v[3 * i + 1], d->v[3 * i + 2]};
        const double w0[3] = {d->w[3 * i], d->w[3 * i + 1], d->w[3 * i + 2]};
        assert_int_equal(dem_step(d), DEM_OK);
        dem_sync_velocities(d);
        for (int a = 0; a < 3; a++) {
            dv[wall][a] = d->v[3 * i + a] - v0[a];
            dv[wall][3 + a] = R * (d->w[3 * i + a] - w0[a]);
        }
        dem_free(d);
    }
    double diff = 0, scale = 0;
    for (int a = 0; a < 6; a++) {
        diff = fmax(diff, fabs(dv[0][a] - dv[1][a]));
        scale = fmax(scale, fabs(dv[1][a]));
    }
    printf("tangential, sphere against a sphere 1e4 times larger vs a wall: largest difference %.2e of the change\n",
           diff / scale);
    /* the pair coefficients approach the wall's as 1/κ */
    assert_true(diff < 1e-3 * scale);
}

/* One sub-step of a lone pair at gap δ₀ approaching at u (no gravity, no
 * contact): the approach speed after the step is the root u′ of
 *     m* (u′ − u) + k [L(δ₀) − L(δ₀ − Δt u′)] = 0
 * (lubrication.c), here by bisection in long double.  Gaps from 1e-5 Δ_lub to
 * Δ_lub and speeds from 1e-6 to 1 m/s, approaching and separating, with and
 * without subtract_resolved: both the series of small drifts
 * (|Δt u|/(δ₀ + η_e) < 1e-3) and the general Newton solve; steps whose drift
 * closes the gap are left out (the contact force acts in their closing
 * kick).  Bound 1e-14 |u|, the Newton solve's tolerance (measured: 6.5e-16). */
static long double root_ref(long double ms, long double k, long double dt, long double gap0, long double u,
                            long double eta, long double range, int subtract)
{
    long double lo = u < 0 ? u : 0, hi = u < 0 ? 0 : u;
    for (int it = 0; it < 200; it++) {
        const long double x = 0.5L * (lo + hi);
        const long double d0 = gap0, d1 = gap0 - dt * x;
        const long double c0 = d0 < 0 ? 0 : d0 > range ? range : d0, c1 = d1 < 0 ? 0 : d1 > range ? range : d1;
        const long double sub = subtract ? 1.0L / (range + eta) : 0.0L;
        const long double g = ms * (x - u) + k * (logl((c0 + eta) / (c1 + eta)) - (c0 - c1) * sub);
        if (g > 0)
            hi = x;
        else
            lo = x;
    }
    return 0.5L * (lo + hi);
}

static void test_step_root(void **state)
{
    (void)state;
    const double eta = 2e-4 * R, range = 0.5 * R, m = RHO * 4.0 / 3.0 * M_PI * R * R * R, ms = 0.5 * m;
    const double k = 6 * M_PI * MU * 0.25 * R * R, dt = TC / 50;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 19);
    double worst = 0;
    int nseries = 0, ngeneral = 0;
    for (int t = 0; t < 400; t++) {
        const int subtract = t % 2;
        const double gap0 = range * pow(10.0, -5.0 * gsl_rng_uniform(rng)) * (1 - 1e-6);
        const double u = (t % 4 < 2 ? 1 : -1) * pow(10.0, -6.0 * gsl_rng_uniform(rng));
        dem_t *d = make(0, eta, range, subtract, 50, 0.0, 0.9);
        const double xa[3] = {0.05, 0.05, 0.05 - R - gap0 / 2}, xb[3] = {0.05, 0.05, 0.05 + R + gap0 / 2};
        const double va[3] = {0, 0, 0.5 * u}, vb[3] = {0, 0, -0.5 * u};
        dem_add_particle(d, xa, va, R, RHO, 0);
        dem_add_particle(d, xb, vb, R, RHO, 0);
        assert_int_equal(dem_step(d), DEM_OK);
        const double *v = dem_velocities(d);
        const long *id = dem_ids(d);
        const int a = id[0] == 0 ? 0 : 1, b = 1 - a;
        const double up = v[3 * a + 2] - v[3 * b + 2];
        /* the gap as the DEM has it (the positions' rounding moves the root by up to 1e-12 |u|) */
        const double g0 = (xb[2] - xa[2] - R) - R;
        const long double ref = root_ref(ms, k, dt, g0, u, eta, range, subtract);
        dem_free(d);
        if (g0 - dt * up <= 0) continue; /* the contact acted in the closing kick */
        worst = fmax(worst, (double)fabsl(up - ref) / fabs(u));
        if (fabs(dt * u) < 1e-3 * (g0 + eta) && g0 - dt * u > 0 && g0 - dt * u < range)
            nseries++;
        else
            ngeneral++;
    }
    gsl_rng_free(rng);
    printf("one step of a pair: largest |u' - root| %.2e |u| (%d steps of small drift, %d others)\n", worst, nseries,
           ngeneral);
    assert_true(nseries > 50 && ngeneral > 50);
    assert_true(worst < 1e-14);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall_first_integral),
        cmocka_unit_test(test_pair_first_integral),
        cmocka_unit_test(test_step_root),
        cmocka_unit_test(test_stiff_small_roughness),
        cmocka_unit_test(test_overlap_restitution),
        cmocka_unit_test(test_overlap_force_at_contact),
        cmocka_unit_test(test_time_to_contact),
        cmocka_unit_test(test_correction_normal),
        cmocka_unit_test(test_tangential_wall_exact),
        cmocka_unit_test(test_tangential_pair_properties),
    };
    TEST_MPI_RUN("dem_lubrication", tests);
}
