/* test_fluid_tgv.c — time-dependent exact solutions in periodic boxes:
 * 2-D Taylor–Green vortex (spatial order, kinetic-energy decay, RK3 temporal
 * order with the viscous term explicit and Crank–Nicolson), 3-D ABC
 * (Beltrami) flow (spatial order), and the kinetic energy of an inviscid run
 * (conserved up to the RK3 dissipation, measured order in Δt).
 * RANKS: 1 2
 */
#include "fluidtest.h"
#include "modules.h"
#include "testutil.h"

/* 2-D Taylor–Green vortex in [0, 2π]², optionally carried by a uniform
 * velocity U0 (Galilean invariance keeps it exact):
 *   u = U0x + sin(x − U0x t) cos(y − U0y t) e^{−2νt},
 *   v = U0y − cos(x − U0x t) sin(y − U0y t) e^{−2νt}. */
typedef struct {
    double nu, U0[2];
} tgv_t;

static double tgv_fn(int c, const double x[3], double t, const void *ctx)
{
    const tgv_t *p = ctx;
    double X = x[0] - p->U0[0] * t, Y = x[1] - p->U0[1] * t, e = exp(-2.0 * p->nu * t);
    return c == 0 ? p->U0[0] + sin(X) * cos(Y) * e : p->U0[1] - cos(X) * sin(Y) * e;
}

static const char *tgv_case = "[domain]\ngeometry = 2d\nnx = %d\nny = %d\nlength = 6.283185307179586 "
                              "6.283185307179586 1\n[fluid]\nnu = %g\ninit = taylor_green\nviscous = %s\n";

/* Error of the TGV at T on an N² grid, fixed Δt = cfl·h (U = 1), started from
 * the case file's init = taylor_green.  Also the relative error of the
 * kinetic energy against the exact ½∫|u|² = π² e^{−4νT}... (L² = 4π²). */
static void tgv_run(int N, double nu, int implicit, double T, double *erms, double *eke, double *div)
{
    char text[512];
    snprintf(text, sizeof text, tgv_case, N, N, nu, implicit ? "implicit" : "explicit");
    grid_t *g;
    fluid_t *f = ft_from_case(text, &g);
    tgv_t p = {nu, {0, 0}};
    double h = 2 * M_PI / N, dt = 0.25 * h;
    ft_run_to(f, T, dt);
    ft_velocity_error(f, tgv_fn, T, &p, NULL, erms);
    /* ½ ∫ (sin²x cos²y + cos²x sin²y) e^{−4νT} over [0,2π]² = π² e^{−4νT} */
    double ke_exact = M_PI * M_PI * exp(-4 * nu * T);
    *eke = fabs(fluid_kinetic_energy(f) - ke_exact) / ke_exact;
    *div = f->diag.div_max;
    /* the energy of the diagnostics (accumulated during the last projection)
     * is that of the field */
    assert_true(fabs(f->diag.ke - fluid_kinetic_energy(f)) < 1e-13 * f->diag.ke);
    fluid_free(f);
    grid_free(g);
}

/* Spatial order: Δt ∝ h with RK3 makes the time error O(h³), below the
 * O(h²) space error, so the RMS velocity error at T = 1 must fall by 4 per
 * halving of h: asserted order > 1.9 on 32 → 64 (the discrete Laplacian's
 * eigenvalue error (h²/12)k² and the advection's truncation are both pure
 * O(h²) for this smooth periodic flow; 1.9 allows the O(h⁴) terms at 32).
 * The kinetic energy must follow the exact decay π² e^{−4νt}: relative
 * error below 1e-3 at 64² and second order.  The projected field is
 * divergence-free to round-off (< 1e-12 relative). */
static void test_tgv2d_space(void **state)
{
    double nu = 0.05, T = 1.0;
    for (int impl = 0; impl < 2; impl++) {
        int Ns[3] = {16, 32, 64};
        double e[3], k[3], d[3];
        for (int r = 0; r < 3; r++) tgv_run(Ns[r], nu, impl, T, &e[r], &k[r], &d[r]);
        double o1 = conv_order(e[0], e[1], 2), o2 = conv_order(e[1], e[2], 2);
        double ok = conv_order(k[1], k[2], 2);
        msg("  TGV 2-D (%s): rms error %.3e %.3e %.3e, orders %.3f %.3f; KE rel. error %.2e %.2e %.2e (order "
            "%.2f); div %.1e\n",
            impl ? "Crank-Nicolson" : "explicit", e[0], e[1], e[2], o1, o2, k[0], k[1], k[2], ok, d[2]);
        assert_true(o2 > 1.9);
        assert_true(o1 > 1.8);
        assert_true(k[2] < 1e-3);
        assert_true(ok > 1.8);
        for (int r = 0; r < 3; r++) assert_true(d[r] < 1e-12);
    }
}

/* Temporal order: the translating TGV (U0 = (1, 0.5)) on a 32² grid, error
 * against a run with Δt/8 of the finest step on the same grid (isolates the
 * time error; the reference's own error is 8³ = 512 times smaller for RK3).
 * Explicit viscous term: the scheme is RK3 applied to du/dt = P F(u) (the
 * projection at every stage removes G p exactly), so order 3: asserted
 * > 2.8.  Crank–Nicolson: second order in the viscous part: asserted > 1.9. */
static void run_translating(double nu, int implicit, double T, double dt, fluid_t **keep, grid_t *g)
{
    fluid_params_t prm = ft_params(nu, implicit);
    fluid_t *f = fluid_create(g, &prm);
    tgv_t p = {nu, {1.0, 0.5}};
    ft_set_velocity(f, tgv_fn, 0.0, &p);
    ft_run_to(f, T, dt);
    *keep = f;
}

static void test_tgv2d_time(void **state)
{
    int N = 32;
    double nu = 0.1, T = 1.0;
    int n[3] = {N, N, 1};
    double L[3] = {2 * M_PI, 2 * M_PI, 1};
    grid_t *g = grid_create(GEOM_2D, n, L, NULL, NULL, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    for (int impl = 0; impl < 2; impl++) {
        double dts[3] = {0.08, 0.04, 0.02}, e[3];
        fluid_t *ref, *f;
        run_translating(nu, impl, T, dts[2] / 8, &ref, g);
        for (int r = 0; r < 3; r++) {
            run_translating(nu, impl, T, dts[r], &f, g);
            e[r] = ft_velocity_diff(f, ref);
            fluid_free(f);
        }
        fluid_free(ref);
        double o1 = conv_order(e[0], e[1], 2), o2 = conv_order(e[1], e[2], 2);
        msg("  translating TGV, RK3 (%s): Δt = 0.08, 0.04, 0.02: error %.3e %.3e %.3e, orders %.3f %.3f\n",
            impl ? "Crank-Nicolson" : "explicit", e[0], e[1], e[2], o1, o2);
        assert_true(o2 > (impl ? 1.9 : 2.8));
    }
    grid_free(g);
}

/* ABC (Beltrami) flow in [0, 2π]³ with A = B = C = 1: exact, decaying as
 * e^{−νt} (k = 1), the nonlinear term a pure gradient.  Spatial order of the
 * RMS velocity error at T = 0.5 (Δt ∝ h) on 12³, 24³, 48³: asserted > 1.9
 * on the finest pair, for the same reasons as the 2-D TGV. */
typedef struct {
    double nu;
} abc_t;

static double abc_fn(int c, const double x[3], double t, const void *ctx)
{
    const abc_t *p = ctx;
    double e = exp(-p->nu * t);
    switch (c) {
    case 0: return (sin(x[2]) + cos(x[1])) * e;
    case 1: return (sin(x[0]) + cos(x[2])) * e;
    default: return (sin(x[1]) + cos(x[0])) * e;
    }
}

static void test_abc3d_space(void **state)
{
    double nu = 0.1, T = 0.5;
    int Ns[3] = {12, 24, 48};
    for (int impl = 0; impl < 2; impl++) {
        double e[3];
        for (int r = 0; r < 3; r++) {
            char text[512];
            snprintf(text, sizeof text,
                     "[domain]\ngeometry = 3d\nnx = %d\nny = %d\nnz = %d\nlength = 6.283185307179586 "
                     "6.283185307179586 6.283185307179586\n[fluid]\nnu = %g\ninit = abc\nviscous = %s\n",
                     Ns[r], Ns[r], Ns[r], nu, impl ? "implicit" : "explicit");
            grid_t *g;
            fluid_t *f = ft_from_case(text, &g);
            abc_t p = {nu};
            ft_run_to(f, T, 0.15 * 2 * M_PI / Ns[r]);
            ft_velocity_error(f, abc_fn, T, &p, NULL, &e[r]);
            assert_true(f->diag.div_max < 1e-12);
            fluid_free(f);
            grid_free(g);
        }
        double o1 = conv_order(e[0], e[1], 2), o2 = conv_order(e[1], e[2], 2);
        msg("  ABC 3-D (%s): rms error %.3e %.3e %.3e, orders %.3f %.3f\n", impl ? "Crank-Nicolson" : "explicit", e[0],
            e[1], e[2], o1, o2);
        assert_true(o2 > 1.9);
    }
}

/* Inviscid periodic flow (ν = 0): the semi-discrete system conserves
 * E = ½ Σ V u² exactly (skew-symmetric advection, projection orthogonal in
 * the same inner product).  RK3 applied to a skew-symmetric system damps
 * each mode by |R(iωΔt)|² = 1 − (ωΔt)⁴/72 + O(Δt⁶) per step, so the energy
 * lost by T falls as Δt³: measured order asserted > 2.8, and the loss must be
 * negative (dissipation, never production). */
static double multi_mode(int c, const double x[3], double t, const void *ctx)
{
    (void)t;
    (void)ctx;
    /* streamfunction ψ = sin x sin y + 0.5 cos(2x + 0.3) sin(y) + 0.3 sin(x) cos(3y + 1): u = ∂yψ, v = −∂xψ */
    if (c == 0) return sin(x[0]) * cos(x[1]) + 0.5 * cos(2 * x[0] + 0.3) * cos(x[1]) - 0.9 * sin(x[0]) * sin(3 * x[1] + 1);
    return -(cos(x[0]) * sin(x[1]) - sin(2 * x[0] + 0.3) * sin(x[1]) + 0.3 * cos(x[0]) * cos(3 * x[1] + 1));
}

static void inviscid_energy(const char *name, const bc_t *bc, stretch_t st)
{
    int n[3] = {32, 32, 1};
    double L[3] = {2 * M_PI, 2 * M_PI, 1}, T = 2.0;
    grid_t *g = grid_create(GEOM_2D, n, L, NULL, bc, st, 1.2, MPI_COMM_WORLD);
    double dts[3] = {0.1, 0.05, 0.025}, loss[3], e0 = 0;
    for (int r = 0; r < 3; r++) {
        fluid_params_t prm = ft_params(0.0, 0);
        fluid_t *f = fluid_create(g, &prm);
        ft_set_velocity(f, multi_mode, 0, NULL);
        fluid_project(f);
        e0 = fluid_kinetic_energy(f);
        ft_run_to(f, T, dts[r]);
        loss[r] = (fluid_kinetic_energy(f) - e0) / e0;
        fluid_free(f);
    }
    double o1 = conv_order(fabs(loss[0]), fabs(loss[1]), 2), o2 = conv_order(fabs(loss[1]), fabs(loss[2]), 2);
    msg("  inviscid 2-D %s, E0 = %.4f: relative energy change at T = %g: %.3e %.3e %.3e (Δt = 0.1, 0.05, "
        "0.025), orders %.2f %.2f\n",
        name, e0, T, loss[0], loss[1], loss[2], o1, o2);
    for (int r = 0; r < 3; r++) assert_true(loss[r] < 0);
    assert_true(o2 > 2.8);
    grid_free(g);
}

/* Periodic, and a closed box (stretched no-slip x walls, free-slip y walls):
 * the walls have zero normal flux, so the semi-discrete energy balance is the
 * same (the tangential ghosts do not enter an inviscid run). */
static void test_inviscid_energy(void **state)
{
    inviscid_energy("periodic", NULL, STRETCH_UNIFORM);
    bc_t bc = {0};
    bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
    bc.type[1][0] = bc.type[1][1] = BC_FREESLIP;
    inviscid_energy("closed box", &bc, STRETCH_TANH_BOTH);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tgv2d_space),
        cmocka_unit_test(test_tgv2d_time),
        cmocka_unit_test(test_abc3d_space),
        cmocka_unit_test(test_inviscid_energy),
    };
    TEST_MPI_RUN("fluid_tgv", tests);
}
