/* test_ibm_perm.c — permeability from the resolved solver on a case with an
 * exact answer: Stokes flow through the simple cubic (SC) array of fixed
 * spheres, against the multipole solution of Zick & Homsy (1982, Table 2):
 * the drag per sphere F = 6πμaKU, U the superficial velocity, i.e. the
 * permeability κ = μU/(ρf) = 2a²/(9cK) at solid fraction c.
 *
 * Set-up: 2 × 2 × 2 spheres of diameter D = 1 in a triply periodic box of
 * two periods (one sphere per period would not leave room for its band of
 * 2.26 Δx on each side at the dense fractions), all fixed; a uniform body
 * force f along x (a mean pressure gradient ρf: the force of the body force
 * on the spheres' interior is balanced there by the forcing) drives the
 * fluid; Stokes regime (Re = UD/ν ≤ 0.01). At the steady state U is the
 * mean of u over the whole box, which by discrete continuity is the flux
 * through any cross-section per unit area — the Darcy flux (solid included:
 * the immersed boundary's own leakage through the spheres is part of its
 * error; on the packing of cases/permeability_crosscheck it carries < 1e-4
 * of the flux).
 *
 * Forcing: forcing_time κ_f = 0.2 (docs/theory.md §6b) with the explicit
 * viscous term, whose steady state does not depend on Δt (the packing of
 * cases/permeability_crosscheck: 7.62695e-3 and 7.62690e-3 at Δt ν/Δx² =
 * 0.2 and 0.1); Crank–Nicolson adds a Δt dependence to the steady state
 * (+1.4 %, +2.8 %, +5.2 %, +9.1 % of κ at Δt ν/Δx² = 0.125, 0.25, 0.5, 1 on
 * that packing, docs/validation.md).
 *
 * make test: c = 0.216 at D/Δx ≈ 8 and 0.343 at 8 and 12; the dilute
 * array c = 0.064 (one sphere per period) with and without
 * radius_correction = calibrated at D/Δx ≈ 8 and 12; c = 0.216 and 0.343
 * at D/Δx ≈ 8 with radius_correction = gaps (and 0.343 with calibrated);
 * scripts/permeability_crosscheck.sh (IBM_PERM_FULL=1): c = 0.125 … 0.5236 at
 * D/Δx ≈ 8, 12, 16 (on 2 ranks: the same K to 6 digits as on 1), and
 * c = 0.064 calibrated at 16 and 24.  One rank
 * here: 20–27 s on the shared machine, 92 s on 2 ranks at load 12.
 * RANKS: 1
 */
#include "ibmtest.h"
#include "modules.h"
#include "testutil.h"

/* Zick & Homsy (1982), Table 2, simple cubic array: solid fraction c, K */
static const double zick_homsy[7][2] = {{0.027, 2.008}, {0.064, 2.810}, {0.125, 4.292}, {0.216, 7.442},
                                        {0.343, 15.4},  {0.45, 28.1},   {0.5236, 42.1}};

/* Steady flow through the SC array of solid fraction c with n cells across
 * the box of `periods` periods (1 or 2); ibm_extra: more [ibm] lines;
 * u0 > 0: the flow starts as the uniform u0 (else from rest).  Returns the
 * measured K, with D/Δx and the wall time. */
static double sc_array_K(double c, int n, int periods, const char *ibm_extra, double u0, double *dpd, double *wall)
{
    const double D = 1.0, a = 0.5 * D, nu = 1.0, f = 0.1;
    const double P = D * cbrt(M_PI / (6.0 * c)); /* period of the array */
    const double L = periods * P, dx = L / n, dt = 0.2 * dx * dx / nu;
    const int ns = periods * periods * periods;
    char text[4096];
    int len = snprintf(text, sizeof text,
                       "[domain]\nnx = %d\nny = %d\nnz = %d\nlength = %.17g %.17g %.17g\n"
                       "[fluid]\nnu = %g\nviscous = explicit\nbody_force = %g 0 0\ndt = %.17g\n"
                       "[ibm]\n%s%g\n%s\n",
                       n, n, n, L, L, L, nu, f, dt, strstr(ibm_extra, "forcing_time") ? "# forcing_time in the extra: " : "forcing_time = ",
                       getenv("IBM_PERM_KAPPA") ? atof(getenv("IBM_PERM_KAPPA")) : 0.2, ibm_extra);
    for (int s = 0; s < ns; s++)
        len += snprintf(text + len, sizeof text - (size_t)len, "sphere%d = fixed center %.17g %.17g %.17g radius %g\n",
                        s + 1, (0.5 + (s & 1)) * P, (0.5 + ((s >> 1) & 1)) * P, (0.5 + ((s >> 2) & 1)) * P, a);
    it_case_t tc = it_from_case(text);
    if (u0 > 0)
        for (long i = 0; i < tc.g->nalloc; i++) tc.f->u[0][i] = u0;
    /* The mean flow relaxes on the Darcy time κ/ν (κ ≤ 0.16 D² here) and the
     * box's modes on L²/(4π²ν) ≤ 0.27 D²/ν: 2 time units are more than 7 of
     * the slowest; the last change is printed. */
    const double t_end = 2.0;
    double t0 = MPI_Wtime(), U = 0, Uprev = 0;
    int steps = 0;
    while (tc.f->time < t_end - 0.5 * dt) {
        fluid_step(tc.f, dt);
        steps++;
        Uprev = U;
        U = it_mean_velocity(tc.f, 0);
    }
    *wall = MPI_Wtime() - t0;
    double Fs = 0; /* the spheres' own drag (momentum balance of the immersed boundary) */
    for (int s = 0; s < ns; s++) Fs += tc.ibm->s[s].force[0];
    const double F = f * L * L * L / ns; /* drag per sphere at the steady state (ρ = 1) */
    const double K = F / (6 * M_PI * nu * a * U);
    *dpd = D / dx;
    print_message("  c = %.4f, D/dx = %5.2f (%3d^3): %d steps, U = %.6e (relative change per unit time %.1e), "
                  "K = %.4f, spheres' drag / (rho f V) = %.6f, %.1f s\n",
                  c, *dpd, n, steps, U, fabs(U - Uprev) / (U * dt), K, Fs / (ns * F), *wall);
    it_free(&tc);
    return K;
}

/* The cells across the box of two periods for a target D/Δx (even, for 2 ranks). */
static int cells_for(double c, double dpd)
{
    double L = 2 * cbrt(M_PI / (6.0 * c));
    int n = (int)lround(dpd * L / 2) * 2;
    return n < 4 ? 4 : n;
}

/* κ/κ_ZH = K_ZH/K of the SC array at solid fraction index ic (Zick & Homsy's
 * table) and D/Δx ≈ dpd; prints the row that scripts/permeability_crosscheck.sh
 * collects. */
static double kappa_ratio(int ic, double dpd_target)
{
    double c = zick_homsy[ic][0], Kzh = zick_homsy[ic][1], dpd, wall;
    double K = sc_array_K(c, cells_for(c, dpd_target), 2, "", 0.0, &dpd, &wall);
    print_message("SC c %.4f D/dx %.3f K %.5f K_ZH %.4f K/K_ZH %.5f kappa/kappa_ZH %.5f wall %.2f\n", c, dpd, K, Kzh,
                  K / Kzh, Kzh / K, wall);
    return Kzh / K;
}

/* Two errors of opposite sign (docs/validation.md): the smoothed solid
 * fraction encloses more than the sphere (+6 % of its volume at D/Δx = 8,
 * second order), which lowers κ, and the band of partially forced nodes
 * lets fluid through the gaps between neighbours, which raises it; the
 * second dominates in dense arrays, where the gaps are a fraction of a cell
 * (c = 0.343: 0.15 D = 1.2 Δx at D/Δx = 8), and falls fast with Δx.
 *
 * make test (20–27 s on one rank of the loaded machine): c = 0.216 at
 * D/Δx ≈ 8, κ within 5 % of Zick & Homsy (measured +2.7 %; the dilute
 * array's drag is within 2 % at this resolution, theory §6b); c = 0.343 at
 * D/Δx ≈ 8 and 12, measured +17.3 % and +4.0 %: bound 6 % at 12 and the
 * error at least halved from 8 to 12 (measured 4.3 times smaller; a
 * first-order error would fall by 1.56).
 * IBM_PERM_FULL=1 (validate): c = 0.125 … 0.5236 at D/Δx ≈ 8, 12, 16, and
 * at 16 every c within 7 % (measured −2.3 % … +6.3 %, the largest for
 * touching spheres). */
static void test_sc_array_zick_homsy(void **state)
{
    (void)state;
    double r216 = kappa_ratio(3, 8), r343_8 = kappa_ratio(4, 8), r343_12 = kappa_ratio(4, 12);
    assert_float_equal(r216, 1.0, 0.05);
    assert_float_equal(r343_12, 1.0, 0.06);
    assert_true(fabs(r343_12 - 1) < 0.5 * fabs(r343_8 - 1));
    if (!getenv("IBM_PERM_FULL")) return;
    /* the dilute end is the Hasimoto test of test_ibm_stokes.c (and its Darcy
     * time, 0.3 D²/ν at c = 0.064, would need longer runs) */
    const int ic[5] = {2, 3, 4, 5, 6};
    const double dpd[3] = {8, 12, 16};
    for (int k = 0; k < 5; k++)
        for (int j = 0; j < 3; j++)
            if (!((ic[k] == 3 && j == 0) || (ic[k] == 4 && j < 2))) {
                double r = kappa_ratio(ic[k], dpd[j]);
                if (j == 2) assert_float_equal(r, 1.0, 0.07);
            }
}

/* The dilute array (c = 0.064, one sphere per period, Zick & Homsy's K =
 * 2.810) against the radius of the forced band.  With the seed's volume
 * fraction the band acts as a sphere larger by 0.10 cell less 0.28 Δx²/R
 * (docs/theory.md §6b): K is +2.14 % at D/Δx = 7.9, +2.33 % at 11.9, +2.13 %
 * at 15.9 and +1.69 % at 23.8 (converged values; first order, masked on
 * coarse grids).  radius_correction = calibrated retracts the forced radius
 * by that thickening: +0.13 %, −0.01 %, −0.006 %, +0.022 %.
 * The runs start from the uniform flow of the reference K (the mean flow
 * relaxes on the Darcy time 0.3 D²/ν), and K at t = 2 is within 0.09 % of
 * its converged value: bound 0.5 % with the correction, and the seed's
 * bias asserted in [1.5 %, 3 %] at D/Δx = 7.9 (4 s on the loaded machine). */
static void test_sc_dilute_radius_correction(void **state)
{
    (void)state;
    const double c = 0.064, Kzh = zick_homsy[1][1], L = cbrt(M_PI / (6.0 * c));
    const double u0 = 0.1 * L * L * L / (6 * M_PI * 0.5 * Kzh); /* f L³/(6πνaK) */
    double dpd, wall;
    double e_none = sc_array_K(c, 16, 1, "", u0, &dpd, &wall) / Kzh - 1;
    double e8 = sc_array_K(c, 16, 1, "radius_correction = calibrated", u0, &dpd, &wall) / Kzh - 1;
    double e12 = sc_array_K(c, 24, 1, "radius_correction = calibrated", u0, &dpd, &wall) / Kzh - 1;
    print_message("SC c 0.0640 K/K_ZH - 1: seed's fraction %+.3f %% (D/dx 7.94); calibrated %+.3f %% (7.94), "
                  "%+.3f %% (11.91)\n",
                  100 * e_none, 100 * e8, 100 * e12);
    assert_true(e_none > 0.015 && e_none < 0.03);
    assert_float_equal(e8, 0.0, 0.005);
    assert_float_equal(e12, 0.0, 0.005);
    if (!getenv("IBM_PERM_FULL")) return;
    /* validate: D/Δx = 15.9 and 23.8, the targets 1 % and 0.5 % (measured
     * +0.09 % and +0.12 % at t = 2; converged −0.006 % and +0.022 %) */
    double e16 = sc_array_K(c, 32, 1, "radius_correction = calibrated", u0, &dpd, &wall) / Kzh - 1;
    double e24 = sc_array_K(c, 48, 1, "radius_correction = calibrated", u0, &dpd, &wall) / Kzh - 1;
    print_message("SC c 0.0640 K/K_ZH - 1 calibrated: %+.3f %% (15.88), %+.3f %% (23.82)\n", 100 * e16, 100 * e24);
    assert_float_equal(e16, 0.0, 0.01);
    assert_float_equal(e24, 0.0, 0.005);
}

/* The narrow band (band_width = 0.5 with forcing_time = 0.05, docs/theory.md
 * §6b) on the dilute array, without any calibration: K −1.33 % and −0.43 %
 * at D/Δx = 7.94 and 11.91 (the harness's steady runs; −0.06 % and +0.20 %
 * at 17.9 and 26.8; at t = 2 here −1.23 % and −0.34 %), against the
 * seed's band's +2.1 % and +2.3 % (+2.41 % at t = 2).  Bounds 2 % and
 * 0.75 %, and the seed's band asserted above 1.5 % at 11.91. */
static void test_sc_dilute_band_width(void **state)
{
    (void)state;
    const double c = 0.064, Kzh = zick_homsy[1][1], L = cbrt(M_PI / (6.0 * c));
    const double u0 = 0.1 * L * L * L / (6 * M_PI * 0.5 * Kzh); /* f L³/(6πνaK) */
    const char *narrow = "band_width = 0.5\nforcing_time = 0.05";
    double dpd, wall;
    double e8 = sc_array_K(c, 16, 1, narrow, u0, &dpd, &wall) / Kzh - 1;
    double e12 = sc_array_K(c, 24, 1, narrow, u0, &dpd, &wall) / Kzh - 1;
    double s12 = sc_array_K(c, 24, 1, "", u0, &dpd, &wall) / Kzh - 1;
    print_message("SC c 0.0640 K/K_ZH - 1: band_width 0.5 %+.3f %% (D/dx 7.94), %+.3f %% (11.91); seed's band "
                  "%+.3f %% (11.91)\n",
                  100 * e8, 100 * e12, 100 * s12);
    assert_float_equal(e8, 0.0, 0.02);
    assert_float_equal(e12, 0.0, 0.0075);
    assert_true(s12 > 0.015);
}

/* The dense arrays against radius_correction = gaps (docs/theory.md §6b):
 * with `calibrated` (a radius fitted on the dilute array) the drag of the
 * narrow gaps is too low, K −6.2 % at c = 0.216 and −17.1 % at c = 0.343
 * at D/Δx ≈ 8 (docs/validation.md); the local gap term of `gaps` brings
 * them to −0.19 % and −2.85 % (crosscheck harness, steady_tol = 1e-3).
 * Bounds 1 % and 4 % at D/Δx ≈ 8 (2 × 2 × 2 periods, 22³ and 19³ cells,
 * about 1 s each), and `calibrated` asserted outside 10 % on c = 0.343. */
static void test_sc_dense_radius_correction_gaps(void **state)
{
    (void)state;
    double dpd216, dpd343, dpdc, wall;
    double e216 = sc_array_K(0.216, 22, 2, "radius_correction = gaps", 0.0, &dpd216, &wall) / zick_homsy[3][1] - 1;
    double e343 = sc_array_K(0.343, 19, 2, "radius_correction = gaps", 0.0, &dpd343, &wall) / zick_homsy[4][1] - 1;
    double c343 = sc_array_K(0.343, 19, 2, "radius_correction = calibrated", 0.0, &dpdc, &wall) / zick_homsy[4][1] - 1;
    print_message("SC dense K/K_ZH - 1 with gaps: c 0.216 %+.3f %% (D/dx %.2f), c 0.343 %+.3f %% (%.2f); "
                  "calibrated: c 0.343 %+.3f %%\n",
                  100 * e216, dpd216, 100 * e343, dpd343, 100 * c343);
    assert_float_equal(e216, 0.0, 0.01);
    assert_float_equal(e343, 0.0, 0.04);
    assert_true(fabs(c343) > 0.1);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sc_array_zick_homsy),
        cmocka_unit_test(test_sc_dilute_radius_correction),
        cmocka_unit_test(test_sc_dilute_band_width),
        cmocka_unit_test(test_sc_dense_radius_correction_gaps),
    };
    TEST_MPI_RUN("ibm_perm", tests);
}
