/* test_dem_drag.c — the drag closure of the reduced fluid model `drag`
 * ([coupling] fluid = drag; src/dem/drag.c, docs/theory.md "Drag closure").
 * RANKS: 1 2
 *
 * Exact results used:
 *  - An isolated sphere released from rest in a fluid at rest reaches
 *    Stokes's terminal velocity v_t = (ρ_p − ρ_f) g d²/(18 μ) (the immersed
 *    weight against 3π μ d v), with either closure (its local solid fraction
 *    is 0: it is left out of its own sampling ball).  The backward-Euler
 *    relaxation of the half-step velocity has that fixed point exactly, so the
 *    velocity from the positions after 40 τ (τ = m/(3π μ d)) is v_t to
 *    round-off; its approach follows the scheme's recurrence v_k = (v_{k−1} +
 *    Δt g′ + (Δt/τ) U_f)/(1 + Δt/τ) (the displacement to t = τ checked to
 *    round-off, and the velocity within Δt/τ of the exact v_t (1 − e^−1)).  With a prescribed fluid velocity U_f
 *    the sphere moves at U_f + v_t.  Its Stokes torque −π μ d³ ω decays a spin
 *    as (1 + Δt/τ_r)^−k, τ_r = I/(π μ d³).
 *  - Hindered settling of a homogeneous suspension (triply periodic box, 382
 *    spheres at φ = 0.2, and 191 at 0.1, closure richardson_zaki): the
 *    momentum balance of the whole suspension (contacts cancel in pairs)
 *    gives ⟨Σ_i K(φ_i) v_i⟩/N = v_t exactly on time average; and the mean
 *    settling velocity is Richardson & Zaki's v_t (1 − φ)^4.65 within the
 *    bias of the local-fraction estimate (docs/theory.md: the other spheres
 *    cannot come closer than d, which the sampling ball's count shows as a
 *    deficit of about v_p (1 − φ − S(0))/(|B| − v_p), S(0) the hard-sphere
 *    structure factor; measured below).
 *  - A restart from a checkpoint between two updates of the local fractions
 *    continues exactly (the held fractions are in the checkpoint).
 *  - dem_local_fraction, shared with the coupling's hindered implicit drag:
 *    three spheres of diameter 1 mm, B and C at 1.05 and 1.3 mm from A along
 *    x and y (periodic box): A's fraction in a ball of radius 1.5 mm is the
 *    two exact lens volumes over the ball less A's own volume; B's ball of
 *    1.6 mm holds all of A (1.05 + 0.5 < 1.6) and part of C; a sphere
 *    at 0.5 mm from a wall z_lo has the wall's cap taken from its ball; and
 *    coupling_drag_hindrance is max(K, (1 − φ)^−4.65), φ capped at 0.64.
 */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "coupling.h"
#include "dem.h"
#include "modules.h"
#include "testutil.h"
#include "util.h"

static const double D = 1e-3, RHO_P = 2500, RHO_F = 1000, MU = 0.1, G = 9.81, TC = 1e-4;

static double gravity_z = -G; /* of the scenes made by make() */

static dem_t *make(const char *particles, const char *drag_keys, const char *boundary)
{
    char text[4096];
    snprintf(text, sizeof text,
             "[domain]\nlength = 0.01 0.01 0.01\n%s"
             "[particles]\n%s\n"
             "[contact]\nrestitution = 0.5\ncontact_time = %g\nfriction = 0.3\n"
             "[dem]\ngravity = 0 0 %g\nsteps_per_contact = 20\n"
             "[coupling]\nfluid = drag\n"
             "[drag]\nviscosity = %g\nfluid_density = %g\n%s",
             boundary, particles, TC, gravity_z, MU, RHO_F, drag_keys);
    cfg_t *cfg = cfg_load_string("test.ini", text, 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    cfg_free(cfg);
    return d;
}

static const char *PERIODIC = "[boundary]\nx_lo = periodic\nx_hi = periodic\ny_lo = periodic\ny_hi = periodic\n"
                              "z_lo = periodic\nz_hi = periodic\n";

/* Mean z velocity of the particles from their displacement over n steps
 * (the drift velocities: the stored full-step velocities carry half a kick
 * of gravity without its drag). */
static double mean_vz(dem_t *d, long n)
{
    const int np = dem_count(d);
    double *z0 = malloc((size_t)np * sizeof *z0);
    long *id0 = malloc((size_t)np * sizeof *id0);
    for (int i = 0; i < np; i++) id0[dem_ids(d)[i]] = i, z0[dem_ids(d)[i]] = dem_positions(d)[3 * i + 2];
    const double t0 = dem_time(d);
    double zs = 0;
    for (long k = 0; k < n; k++) assert_int_equal(dem_step(d), DEM_OK);
    /* unwrapped: no sphere moves more than half the box in n steps here */
    for (int i = 0; i < np; i++) {
        double dz = dem_positions(d)[3 * i + 2] - z0[dem_ids(d)[i]];
        dz -= 0.01 * nearbyint(dz / 0.01);
        zs += dz;
    }
    free(z0);
    free(id0);
    return zs / np / (dem_time(d) - t0);
}

static void test_isolated_sphere(void **state)
{
    (void)state;
    const double vt = (RHO_P - RHO_F) * G * D * D / (18 * MU), m = RHO_P * M_PI / 6 * D * D * D;
    const double tau = m / (3 * M_PI * MU * D);
    for (int closure = 0; closure < 2; closure++)
        for (int moving = 0; moving < 2; moving++) {
            char keys[256];
            snprintf(keys, sizeof keys, "closure = %s\nfluid_velocity = 0 0 %s\n", closure ? "richardson_zaki" : "stokes",
                     moving ? "0.002" : "0");
            dem_t *d = make("source = list\nparticle1 = center 0.005 0.005 0.005 diameter 0.001 density 2500 "
                            "omega 30 0 0",
                            keys, PERIODIC);
            assert_int_equal(dem_advance(d, 0.0), DEM_OK);
            const double dt = dem_dt(d), a = dt / tau;
            const long k1 = lround(tau / dt);
            /* the scheme's own transient: the first step kicks half Δt of gravity (velocity Verlet), the
             * next ones Δt; the buoyancy is applied with the drag over each drift */
            const double U = moving ? 0.002 : 0, gb = -G + RHO_F / RHO_P * G;
            double zsum = 0, vk = 0;
            for (long k = 1; k <= k1; k++) {
                vk = (vk + (k == 1 ? 0.5 * dt * -G + dt * (gb + G) : dt * gb) + a * U) / (1 + a);
                zsum += dt * vk;
            }
            const double z0 = dem_positions(d)[2];
            for (long k = 0; k < k1; k++) assert_int_equal(dem_step(d), DEM_OK);
            double dz = dem_positions(d)[2] - z0;
            const double e_scheme = fabs(dz - zsum) / fabs(zsum);
            /* the velocity of the k1-th drift against the exact transient at t = τ (first order in Δt/τ) */
            const double vx = (U - vt) * (1 - exp(-k1 * dt / tau));
            const double w1 = dem_omegas(d)[0];
            for (long k = 0; k < 39 * k1; k++) assert_int_equal(dem_step(d), DEM_OK);
            const double v = mean_vz(d, 100) - (moving ? 0.002 : 0);
            const double I = 0.1 * m * D * D, taur = I / (M_PI * MU * D * D * D);
            const double w_exp = 30 * pow(1 + dt / taur, -(double)k1);
            printf("# closure %s, U_f %s: terminal %.10g (Stokes %.10g, rel. %.1e); displacement to t = tau %.2e "
                   "from the scheme's; v(tau) %.6f of v_t (exact %.6f, dt/tau %.2e); spin after tau %.6g (scheme %.6g)\n",
                   closure ? "richardson_zaki" : "stokes", moving ? "0.002" : "0", -v, vt, fabs(-v - vt) / vt, e_scheme,
                   vk / (U - vt), vx / (U - vt), a, w1, w_exp);
            /* round-off: 4e4 steps of sums of ~1e-6 m displacements */
            assert_true(fabs(-v - vt) / vt < 1e-9);
            assert_true(e_scheme < 1e-9);
            assert_true(fabs(vk - vx) / fabs(U - vt) < a);
            assert_true(fabs(w1 - w_exp) < 1e-9 * 30);
            dem_free(d);
        }
}

/* Hindered settling at solid fraction phi: returns the mean settling velocity
 * over v_t, and the measured mean local fraction; checks the momentum balance. */
static double suspension(double phi, int seed, double *phi_mean, double *balance)
{
    char parts[256];
    snprintf(parts, sizeof parts, "source = insert\nvolume_fraction = %g\nradius = 0.0005\ndensity = 2500\nseed = %d\n",
             phi, seed);
    dem_t *d = make(parts, "closure = richardson_zaki\n", PERIODIC);
    const double vt = (RHO_P - RHO_F) * G * D * D / (18 * MU), m = RHO_P * M_PI / 6 * D * D * D;
    const double tau = m / (3 * M_PI * MU * D);
    assert_int_equal(dem_advance(d, 0.0), DEM_OK);
    const long nt = lround(tau / dem_dt(d));
    /* transient: the slowest relaxation is τ/K(φ) < τ; 15 τ */
    for (long k = 0; k < 15 * nt; k++) assert_int_equal(dem_step(d), DEM_OK);
    /* averages over 10 τ, in blocks of τ/4 */
    double v = 0, bal = 0, ph = 0;
    const int nb = 40;
    for (int b = 0; b < nb; b++) {
        v += mean_vz(d, nt / 4) / nb;
        const double *f = dem_drag_fraction(d), *fd = dem_drag_forces(d);
        double s = 0, p = 0;
        for (int i = 0; i < dem_count(d); i++) {
            const long id = dem_ids(d)[i];
            s += fd[3 * id + 2];
            p += f[id];
        }
        /* Σ F_drag,z = Σ 3π μ d K_i v_i: the drag carries the immersed weight on average */
        bal += s / dem_count(d) / ((RHO_P - RHO_F) * M_PI / 6 * D * D * D * G) / nb;
        ph += p / dem_count(d) / nb;
    }
    *phi_mean = ph;
    *balance = bal;
    dem_free(d);
    return -v / vt;
}

static void test_hindered_settling(void **state)
{
    (void)state;
    const double n = 4.65, phis[2] = {0.1, 0.2};
    for (int q = 0; q < 2; q++) {
        double pm, bal;
        const double phi = phis[q], u = suspension(phi, 7, &pm, &bal), rz = pow(1 - phi, n), rz_est = pow(1 - pm, n);
        /* the deficit of the estimate: hard spheres, Percus–Yevick S(0) = (1 − φ)^4/(1 + 2φ)^2, ball of 3 d */
        const double S0 = pow(1 - phi, 4) / pow(1 + 2 * phi, 2), vp = M_PI / 6, vb = 4.0 / 3.0 * M_PI * 27;
        const double deficit = vp * (1 - phi - S0) / (vb - vp);
        printf("# phi %.2f: settling %.4f v_t, Richardson-Zaki %.4f (rel. %+.3f), at the mean estimated fraction "
               "%.4f: %.4f (rel. %+.3f); estimated fraction %+.4f from phi (expected deficit %.4f); drag / immersed "
               "weight %.5f\n",
               phi, u, rz, u / rz - 1, pm, rz_est, u / rz_est - 1, pm - phi, deficit, bal);
        /* the momentum balance: 1 up to the fluctuation of the time average (measured within 2e-3) */
        assert_true(fabs(bal - 1) < 5e-3);
        /* the estimator: its mean within 0.005 of phi + the expected deficit (sampling noise of ~400 balls) */
        assert_true(fabs(pm - (phi - deficit)) < 0.005);
        /* Richardson-Zaki: within 4 % (measured below 2 %: the estimator's deficit and the spread of K over
         * the spheres, <K v> = v_t but <v> > v_t/<K>) */
        assert_true(fabs(u / rz - 1) < 0.04);
    }
}

/* fluid_velocity_from = grains: the drag acts on each grain's velocity relative to the mean of the
 * other grains in its ball, so a suspension translating as a whole (no gravity) keeps its velocity
 * (to round-off: the mean of equal velocities), where the prescribed fluid at rest stops it as
 * (1 + Δt/τ)^-k; a lone sphere (no neighbour in its ball) sees fluid_velocity and falls at Stokes's
 * terminal velocity. */
static void test_grains_frame(void **state)
{
    (void)state;
    const char *parts = "source = insert\nvolume_fraction = 0.2\nradius = 0.0005\ndensity = 2500\nseed = 3\n"
                        "velocity = 0.01 0.002 -0.003\n";
    gravity_z = 0;
    double worst[2] = {0, 0};
    for (int q = 0; q < 2; q++) {
        dem_t *d = make(parts, q ? "fluid_velocity_from = grains\nrotation = false\n" : "rotation = false\n", PERIODIC);
        assert_int_equal(dem_run_steps(d, 100), DEM_OK);
        const double U[3] = {0.01, 0.002, -0.003};
        for (int i = 0; i < dem_count(d); i++) {
            double v[3];
            dem_full_velocity(d, i, v);
            for (int a = 0; a < 3; a++) worst[q] = fmax(worst[q], fabs(v[a] - U[a]) / 0.01);
        }
        dem_free(d);
    }
    gravity_z = -G;
    printf("# a translating suspension after 100 steps: largest change %.3g (fluid at rest), %.3g (grains)\n",
           worst[0], worst[1]);
    assert_true(worst[1] < 1e-13); /* contacts none: inserted apart, moving together */
    assert_true(worst[0] > 0.1);   /* the fluid at rest stops it: Δt/τ = 0.15 per step here */
    /* a lone sphere: Stokes's terminal velocity (ρ_p − ρ_f) g d²/(18μ) */
    dem_t *d = make("source = list\nparticle1 = center 0.005 0.005 0.005 diameter 0.001 density 2500\n",
                    "fluid_velocity_from = grains\n", PERIODIC);
    assert_int_equal(dem_run_steps(d, 8000), DEM_OK); /* 28 relaxation times τ = m/(3πμd) */
    const double vt = (RHO_P - RHO_F) * G * D * D / (18 * MU), vz = mean_vz(d, 200);
    printf("# lone sphere with fluid_velocity_from = grains: %.12g v_t\n", vz / -vt);
    assert_true(fabs(vz / -vt - 1) < 1e-9);
    dem_free(d);
}

static void test_restart(void **state)
{
    (void)state;
    char dir[] = "/tmp/ibmdem_drag_XXXXXX";
    if (mpi_rank() == 0) assert_non_null(mkdtemp(dir));
    MPI_Bcast(dir, sizeof dir, MPI_CHAR, 0, MPI_COMM_WORLD);
    char path[512];
    snprintf(path, sizeof path, "%s/c.h5", dir);
    const char *parts = "source = insert\nvolume_fraction = 0.2\nradius = 0.0005\ndensity = 2500\nseed = 3\n";
    dem_t *a = make(parts, "fraction_every = 7\n", PERIODIC);
    assert_int_equal(dem_run_steps(a, 103), DEM_OK); /* between two updates of phi */
    dem_write_checkpoint(a, path);
    dem_t *b = make(parts, "fraction_every = 7\n", PERIODIC);
    dem_read_checkpoint(b, path);
    assert_int_equal(dem_run_steps(a, 200), DEM_OK);
    assert_int_equal(dem_run_steps(b, 200), DEM_OK);
    double diff = 0;
    for (int i = 0; i < 3 * dem_count(a); i++)
        diff = fmax(diff, fabs(dem_positions(a)[i] - dem_positions(b)[i]) + fabs(dem_velocities(a)[i] - dem_velocities(b)[i]));
    printf("# restart between two updates of the local fractions: largest difference %g\n", diff);
    assert_true(diff == 0);
    dem_free(a);
    dem_free(b);
    if (mpi_rank() == 0) {
        unlink(path);
        rmdir(dir);
    }
}

/* Volume of the intersection of balls of radii R and r whose centres are s
 * apart (the lens; written out here, independent of drag.c's). */
static double lens(double R, double r, double s)
{
    if (s >= R + r) return 0.0;
    if (s <= fabs(R - r)) return 4.0 / 3.0 * M_PI * pow(fmin(R, r), 3);
    const double d1 = (s * s - r * r + R * R) / (2 * s), d2 = s - d1; /* distances of the centres to the plane */
    const double h1 = R - d1, h2 = r - d2;                              /* cap heights */
    return M_PI * h1 * h1 * (3 * R - h1) / 3 + M_PI * h2 * h2 * (3 * r - h2) / 3;
}

static void test_local_fraction(void **state)
{
    (void)state;
    const double r = 0.5e-3, V = 4.0 / 3.0 * M_PI * r * r * r;
    dem_t *d = make("source = list\nparticle1 = center 0.005 0.005 0.005 radius 0.0005\n"
                    "particle2 = center 0.00605 0.005 0.005 radius 0.0005\n"
                    "particle3 = center 0.005 0.0063 0.005 radius 0.0005\n",
                    "", PERIODIC);
    double phi[3];
    dem_local_fraction(d, 1.5e-3, phi, NULL, NULL, NULL);
    const double ball15 = 4.0 / 3.0 * M_PI * pow(1.5e-3, 3);
    const double exA = (lens(1.5e-3, r, 1.05e-3) + lens(1.5e-3, r, 1.3e-3)) / (ball15 - V);
    const double sBC = sqrt(1.05e-3 * 1.05e-3 + 1.3e-3 * 1.3e-3);
    const double exB = (lens(1.5e-3, r, 1.05e-3) + lens(1.5e-3, r, sBC)) / (ball15 - V);
    printf("# local fraction, ball 1.5 mm: A %.6f (exact %.6f), B %.6f (exact %.6f)\n", phi[0], exA, phi[1], exB);
    assert_true(fabs(phi[0] - exA) < 1e-12 && fabs(phi[1] - exB) < 1e-12);
    dem_local_fraction(d, 1.6e-3, phi, NULL, NULL, NULL);
    const double ball16 = 4.0 / 3.0 * M_PI * pow(1.6e-3, 3);
    const double exB1 = (V + lens(1.6e-3, r, sBC)) / (ball16 - V); /* A whole inside B's ball */
    assert_true(fabs(phi[1] - exB1) < 1e-12);
    dem_free(d);
    /* a wall: the ball's cap below z_lo is not fluid */
    d = make("source = list\nparticle1 = center 0.005 0.005 0.0005 radius 0.0005\n"
             "particle2 = center 0.005 0.0061 0.0005 radius 0.0005\n",
             "", "[boundary]\nx_lo = periodic\nx_hi = periodic\ny_lo = periodic\ny_hi = periodic\nz_lo = noslip\n"
             "z_hi = noslip\n");
    dem_local_fraction(d, 1.5e-3, phi, NULL, NULL, NULL);
    const double hcap = 1.5e-3 - 0.5e-3;
    const double inbox = ball15 - M_PI * hcap * hcap * (3 * 1.5e-3 - hcap) / 3;
    const double exW = lens(1.5e-3, r, 1.1e-3) / (inbox - V);
    printf("# by a wall: %.6f (exact %.6f)\n", phi[0], exW);
    assert_true(fabs(phi[0] - exW) < 1e-12);
    dem_free(d);
    /* the coefficient of the hindered implicit drag */
    assert_true(coupling_drag_hindrance(4, 0.0) == 4.0);
    assert_true(fabs(coupling_drag_hindrance(4, 0.6) - pow(0.4, -4.65)) < 1e-12 * pow(0.4, -4.65));
    assert_true(fabs(coupling_drag_hindrance(1, 0.2) - pow(0.8, -4.65)) < 1e-15 * 10);
    assert_true(coupling_drag_hindrance(4, 0.2) == 4.0); /* 0.8^-4.65 = 2.82 < K */
    assert_true(coupling_drag_hindrance(4, 0.8) == coupling_drag_hindrance(4, 0.64)); /* capped at 0.64 */
    assert_true(fabs(coupling_drag_hindrance(4, 0.64) - pow(0.36, -4.65)) < 1e-12 * pow(0.36, -4.65));
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_isolated_sphere),
        cmocka_unit_test(test_hindered_settling),
        cmocka_unit_test(test_grains_frame),
        cmocka_unit_test(test_restart),
        cmocka_unit_test(test_local_fraction),
    };
    TEST_MPI_RUN("dem_drag", tests);
}
