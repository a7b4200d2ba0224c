/* test_coupling_added_mass.c — the added-mass-consistent collision of the
 * resolved coupling ([coupling] added_mass = consistent; coupling.h,
 * src/coupling/ibm_dem.c, docs/theory.md §9.1).
 * RANKS: 1
 *
 * The fluid is replaced by an ideal one whose only force is the added-mass
 * reaction to the particle's velocity change of the previous fluid step,
 * F_h^{n+1} = −C_M ρ V ΔU^n/Δt_f — what the immersed boundary reports, a step
 * late, when the DEM changed the sphere's velocity (its response to an
 * impulsive change of velocity in potential flow).  Exact results:
 *  1. Held force: with no collision the DEM gives the particle the acceleration
 *     (F_h − ρ V g)/m_p + g of the held force, buoyancy and weight, although
 *     its inertia is m* = m_p + C_M ρ V (checked over one step to round-off).
 *  2. Collision: with the option, the correction cancels the ideal reaction
 *     (the held force is zero to round-off at every step), and the collision
 *     is that of a mass m* (Izard eqs. 3.24, 3.26): a sphere thrown at the
 *     wall without gravity reaches it at u_C = u₀ − (k/m*) ΔL, leaves at
 *     ε_max u_C and leaves the lubrication range at u_R = ε_max u_C − (k/m*) ΔL,
 *     ΔL = ln((Δ_lub + η_e)/η_e), k = 6πη_f R² (the lubrication's first
 *     integral is exact, test_dem_lubrication; the contact law's error at
 *     t_c/Δt_s = 50 is < 0.25 %, hence the 0.5 % tolerance).  The same for two
 *     fluid steps (one shorter and one longer than t_c): the result does not
 *     depend on the fluid step.  Without the option the same ideal fluid
 *     gives a different rebound (the m_p collision plus the reaction a step
 *     later), checked to differ by more than the tolerance so that test 2 can
 *     fail.
 */
#include <stdlib.h>
#include <string.h>

#include "coupling.h"
#include "couplingtest.h"
#include "dem.h"
#include "modules.h"
#include "testutil.h"
#include "util.h"

static const double R = 1e-3, RHO_P = 8000, RHO_F = 1000, TC = 1e-4, MU = 1e-2, CM = 0.5;

static dem_t *make(double gz)
{
    char text[2048];
    snprintf(text, sizeof text,
             "[domain]\nlength = 0.1 0.1 0.1\n[boundary]\nz_lo = noslip\nz_hi = noslip\n"
             "[walls]\nfaces = z_lo\n[contact]\nrestitution = 0.97\ncontact_time = %g\nfriction = 0.3\n"
             "[lubrication]\nmodel = brenner\nroughness = 4e-4\nrange = 0.5\nviscosity = %g\n"
             "[dem]\ngravity = 0 0 %.17g\nsteps_per_contact = 50\n",
             TC, MU, gz);
    return test_dem_from_text(text);
}

static void test_held_force_acceleration(void **state)
{
    (void)state;
    const double g = -9.81, dt = 1e-3;
    dem_t *d = make(g);
    const double x[3] = {0.05, 0.05, 0.05}, v[3] = {0, 0, 0};
    dem_add_particle(d, x, v, R, RHO_P, 0);
    ibm_t *ibm = test_fake_ibm(1);
    ibm->s[0].force[2] = 3e-6; /* some drag */
    coupling_added_mass_t am;
    coupling_added_mass_init(&am, 1, CM);
    coupling_added_mass_apply(&am, d, RHO_F);
    const double V = 4.0 / 3.0 * M_PI * R * R * R, mp = RHO_P * V;
    assert_true(fabs((dem_mass(d, 0)) - (mp + CM * RHO_F * V)) <= 1e-15 * mp);
    coupling_added_mass_apply(&am, d, RHO_F); /* idempotent */
    assert_true(fabs((dem_mass(d, 0)) - (mp + CM * RHO_F * V)) <= 1e-15 * mp);
    const double gravity[3] = {0, 0, g};
    coupling_forces_to_dem(ibm, d, RHO_F, gravity, NULL, &am, dt);
    assert_int_equal(dem_advance(d, dem_time(d) + dt), DEM_OK);
    coupling_added_mass_after_step(&am, d);
    const double expect = dt * ((3e-6 - RHO_F * V * g) / mp + g);
    printf("# one step: v_z %.15g, expected %.15g; collision dU %.3g\n", dem_velocities(d)[2], expect, am.dU[2]);
    assert_true(fabs((dem_velocities(d)[2]) - (expect)) <= 1e-12 * fabs(expect));
    assert_true(fabs(am.dU[2]) < 1e-12 * fabs(expect));
    coupling_added_mass_free(&am);
    test_free_ibm(ibm);
    dem_free(d);
}

/* A sphere thrown at the wall through the ideal fluid; returns the rebound
 * speed when it leaves the lubrication range, *worst the largest held force
 * over the run relative to the contact force scale m* u0 / t_c. */
static double throw_at_wall(int consistent, double dt, double u0, double *worst)
{
    dem_t *d = make(0.0);
    const double gap0 = 0.6 * R, x[3] = {0.05, 0.05, R + gap0}, v[3] = {0, 0, -u0};
    dem_add_particle(d, x, v, R, RHO_P, 0);
    ibm_t *ibm = test_fake_ibm(1);
    coupling_added_mass_t am;
    coupling_added_mass_init(&am, 1, CM);
    if (consistent) coupling_added_mass_apply(&am, d, RHO_F);
    const double V = 4.0 / 3.0 * M_PI * R * R * R, mstar = (RHO_P + CM * RHO_F) * V, gravity[3] = {0, 0, 0};
    *worst = 0;
    int touched = 0;
    double uR = 0;
    for (int n = 0; n < 100000; n++) {
        const double U0 = dem_velocities(d)[2];
        coupling_forces_to_dem(ibm, d, RHO_F, gravity, NULL, consistent ? &am : NULL, dt);
        const double held = fabs(dem_ext_force(d)[2]) / (mstar * u0 / TC);
        if (held > *worst) *worst = held;
        const dem_status_t st = dem_advance(d, dem_time(d) + dt);
        if (st != DEM_OK) printf("# %s\n", dem_error(d));
        assert_int_equal(st, DEM_OK);
        if (consistent) coupling_added_mass_after_step(&am, d);
        const double U1 = dem_velocities(d)[2], gap = dem_positions(d)[2] - R;
        ibm->s[0].force[2] = -CM * RHO_F * V * (U1 - U0) / dt; /* the ideal fluid's reaction, one step late */
        if (gap <= 0 || U1 > 0) touched = 1; /* a contact may lie inside one fluid step */
        if (touched && gap > 0.5 * R) {
            uR = U1;
            break;
        }
    }
    assert_true(touched);
    coupling_added_mass_free(&am);
    test_free_ibm(ibm);
    dem_free(d);
    return uR;
}

static void test_collision_on_mstar(void **state)
{
    (void)state;
    const double V = 4.0 / 3.0 * M_PI * R * R * R, mstar = (RHO_P + CM * RHO_F) * V, k = 6 * M_PI * MU * R * R;
    const double dL = log((0.5 * R + 4e-4 * R) / (4e-4 * R)), u0 = 0.5;
    const double uC = u0 - k / mstar * dL, uR = 0.97 * uC - k / mstar * dL;
    double worst;
    for (int c = 0; c < 2; c++) {
        const double dt = c ? 3 * TC : 0.4 * TC; /* fluid step longer and shorter than the contact */
        const double u = throw_at_wall(1, dt, u0, &worst);
        printf("# consistent, dt_f = %.1f t_c: u_R %.6f, expected %.6f (%.2e), largest held force %.2e\n", dt / TC, u,
               uR, u / uR - 1, worst);
        assert_true(fabs(u / uR - 1) < 5e-3);
        assert_true(worst < 1e-12);
    }
    const double u = throw_at_wall(0, 3 * TC, u0, &worst);
    printf("# without the option: u_R %.6f (%.2e from the m* collision)\n", u, u / uR - 1);
    assert_true(fabs(u / uR - 1) > 1e-2);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_held_force_acceleration),
        cmocka_unit_test(test_collision_on_mstar),
    };
    TEST_MPI_RUN("coupling_added_mass", tests);
}
