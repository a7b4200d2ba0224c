/* test_poisson_mg.c — the geometric multigrid solver (src/poisson/multigrid.c)
 * against manufactured solutions of (L − λI)u = b (tests/mgcase.h) for every
 * variable location, boundary combination and geometry.
 * RANKS: 1 2
 */
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "mgcase.h"
#include "poisson.h"
#include "testutil.h"
#include "util.h"

typedef struct {
    const char *name;
    geom_t geom;
    int n[3];
    bc_type_t bc[3][2];
    var_loc_t loc;
    stretch_t stretch;
    double beta, lambda;
    double Ly; /* domain length in y (x and z: 1) */
} mgc_t;

#define PER {BC_PERIODIC, BC_PERIODIC}
#define NS {BC_NOSLIP, BC_NOSLIP}
#define FS {BC_FREESLIP, BC_FREESLIP}
#define NF {BC_NOSLIP, BC_FREESLIP}
#define AX {BC_AXIS, BC_NOSLIP}
#define AXF {BC_AXIS, BC_FREESLIP}
#define UNI STRETCH_UNIFORM, 0
#define TB STRETCH_TANH_BOTH, 1.5
#define TH STRETCH_TANH_HIGH, 1.5

typedef struct {
    int cycles, rc;
    double res, factor, err;
} mgr_t;

static const poisson_opts_t mg_opts = {
    .method = POISSON_MG, .mg_tol = 1e-10, .mg_max_cycles = 40, .mg_pre = 2, .mg_post = 2};

static grid_t *case_grid(const mgc_t *c, int scale, MPI_Comm comm)
{
    int n[3] = {c->n[0] * scale, c->n[1] * scale, c->geom == GEOM_3D ? c->n[2] * scale : 1};
    double L[3] = {1.0, c->Ly > 0 ? c->Ly : 1.0, 1.0};
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++) bc.type[d][s] = c->bc[d][s];
    return grid_create(c->geom, n, L, NULL, &bc, c->stretch, c->beta, comm);
}

/* Solve the manufactured problem of case c; keep the solution in *xout if
 * asked (caller frees it and the grid). */
static mgr_t run_case(const mgc_t *c, int scale, MPI_Comm comm, double **xout, grid_t **gout)
{
    grid_t *g = case_grid(c, scale, comm);
    poisson_t *p = poisson_create(g, c->loc, &mg_opts);
    double *u = field_alloc(g), *b = field_alloc(g), *x = field_alloc(g);
    mms_fill(p, c->lambda, u, b);
    mgr_t r;
    r.rc = poisson_solve(p, c->lambda, b, x);
    r.cycles = p->last_iterations;
    r.res = poisson_residual(p, c->lambda, b, x); /* measured independently of the solver */
    r.factor = pow(p->last_residual, 1.0 / r.cycles); /* mean reduction per V-cycle, from ||r_0|| = ||b|| */
    r.err = mms_error(p, c->lambda, x, u);
    free(u);
    free(b);
    poisson_free(p);
    if (xout) {
        *xout = x;
        *gout = g;
    } else {
        free(x);
        grid_free(g);
    }
    return r;
}

/* Every location, the boundary combinations (periodic, no-slip, free-slip,
 * mixed no-slip/free-slip, axis), stretched and uniform x, Poisson and
 * Helmholtz.  Sizes are the coarse resolution; each case also runs at 2×. */
static const mgc_t cases[] = {
    {"3d P periodic", GEOM_3D, {16, 16, 16}, {PER, PER, PER}, VAR_P, UNI, 0, 0},
    {"3d P closed box", GEOM_3D, {16, 16, 16}, {NS, NS, NS}, VAR_P, UNI, 0, 0},
    {"3d P channel (stretched)", GEOM_3D, {16, 16, 16}, {NS, FS, PER}, VAR_P, TB, 0, 0},
    {"3d U periodic", GEOM_3D, {16, 16, 16}, {PER, PER, PER}, VAR_U, UNI, 0, 0},
    {"3d U walls x,z (stretched)", GEOM_3D, {16, 16, 16}, {NS, PER, NS}, VAR_U, TB, 0, 0},
    {"3d V mixed walls", GEOM_3D, {16, 16, 16}, {NF, NS, FS}, VAR_V, UNI, 0, 0},
    {"3d W walls, Helmholtz (str.)", GEOM_3D, {16, 16, 16}, {NS, NF, NS}, VAR_W, TB, 1e3, 0},
    {"3d W periodic x, Helmholtz", GEOM_3D, {16, 16, 16}, {PER, NS, NF}, VAR_W, UNI, 30, 0},
    {"2d P cavity (stretched)", GEOM_2D, {32, 32, 1}, {NS, NS, PER}, VAR_P, TB, 0, 0},
    {"2d P channel", GEOM_2D, {32, 32, 1}, {NS, PER, PER}, VAR_P, UNI, 0, 0},
    {"2d U cavity (stretched)", GEOM_2D, {32, 32, 1}, {NS, NS, PER}, VAR_U, TB, 0, 0},
    {"2d U free-slip y", GEOM_2D, {32, 32, 1}, {NS, FS, PER}, VAR_U, UNI, 0, 0},
    {"2d V mixed x, walls y", GEOM_2D, {32, 32, 1}, {NF, NS, PER}, VAR_V, UNI, 0, 0},
    {"2d V channel, Helmholtz", GEOM_2D, {32, 32, 1}, {NF, PER, PER}, VAR_V, UNI, 10, 0},
    {"axi P pipe", GEOM_AXI, {32, 64, 1}, {AX, PER, PER}, VAR_P, UNI, 0, 2},
    {"axi P closed (stretched)", GEOM_AXI, {32, 64, 1}, {AX, NS, PER}, VAR_P, TH, 0, 2},
    {"axi U pipe (stretched)", GEOM_AXI, {32, 64, 1}, {AX, PER, PER}, VAR_U, TH, 0, 2},
    {"axi U closed, Helmholtz", GEOM_AXI, {32, 64, 1}, {AX, FS, PER}, VAR_U, UNI, 50, 2},
    {"axi V closed (stretched)", GEOM_AXI, {32, 64, 1}, {AXF, NS, PER}, VAR_V, TH, 0, 2},
    {"axi V pipe, Helmholtz", GEOM_AXI, {32, 64, 1}, {AX, PER, PER}, VAR_V, UNI, 1e4, 2},
};
#define NCASES (sizeof cases / sizeof cases[0])

static mgr_t results[NCASES][2];

static void compute_results(void)
{
    static int done = 0;
    if (done) return;
    for (size_t i = 0; i < NCASES; i++) {
        results[i][0] = run_case(&cases[i], 1, MPI_COMM_WORLD, NULL, NULL);
        results[i][1] = run_case(&cases[i], 2, MPI_COMM_WORLD, NULL, NULL);
        mgr_t *r = results[i];
        msg("  %-30s cycles %2d %2d  factor %.3f %.3f  residual %.1e  error %.2e %.2e  order %.2f\n", cases[i].name,
            r[0].cycles, r[1].cycles, r[0].factor, r[1].factor, r[1].res, r[0].err, r[1].err,
            conv_order(r[0].err, r[1].err, 2.0));
    }
    done = 1;
}

/* (1) The residual reaches mg_tol, with a convergence factor per V(2,2)-cycle
 * below 0.2 that does not grow with the resolution.  Measured factors are
 * 0.02–0.12 (point red-black Gauss–Seidel with full coarsening 0.05–0.12;
 * x-line relaxation with y/z coarsening on stretched x 0.02–0.10).  The bound
 * 0.2 is well below what a defective cycle gives here — divergence for a sign
 * error in the coarsest solve, 0.23–0.31 for a restriction not matched to the
 * smoother, 0.27 for point smoothing on the stretched axisymmetric grid (all
 * seen in development) — and a smoother alone would give 1 − O(h²).  Grid
 * independence: for the Poisson cases, twice the resolution costs at most two
 * more cycles.  (A Helmholtz problem gets harder as h shrinks, since λh² sets
 * its diagonal dominance: λ = 1e4 takes 2–3 cycles at h = 1/32, 5 at 1/64.)
 * The factor is (‖r‖/‖b‖)^(1/cycles), the residual being the one after the
 * pre-smoothing that follows the last cycle (where the solver tests it). */
static void test_mg_cycles_and_factor(void **state)
{
    compute_results();
    for (size_t i = 0; i < NCASES; i++)
        for (int s = 0; s < 2; s++) {
            mgr_t *r = &results[i][s];
            if (r->rc != 0 || r->res > 1.01 * mg_opts.mg_tol || r->factor > 0.2)
                msg("FAIL %s (scale %d): rc %d residual %.2e factor %.3f\n", cases[i].name, s + 1, r->rc, r->res,
                    r->factor);
            assert_int_equal(r->rc, 0);
            /* the solver's own estimate is checked against poisson_residual(),
             * which recomputes it with poisson_apply(); 1 % for the different
             * summation order */
            assert_true(r->res <= 1.01 * mg_opts.mg_tol);
            assert_true(r->factor < 0.2);
        }
    for (size_t i = 0; i < NCASES; i++)
        if (cases[i].lambda == 0.0) assert_true(results[i][1].cycles <= results[i][0].cycles + 2);
}

/* (2) The multigrid solution is the solution of the discrete operator, so it
 * converges to the exact solution at the operator's second order (solver
 * error 1e-10 ≪ discretisation error ~1e-4).  Measured 1.98–2.01 between
 * the two resolutions; 1.9 allows for the pre-asymptotic coarse grid. */
static void test_mg_second_order(void **state)
{
    compute_results();
    for (size_t i = 0; i < NCASES; i++) {
        double order = conv_order(results[i][0].err, results[i][1].err, 2.0);
        if (order < 1.9) msg("FAIL %s: order %.2f\n", cases[i].name, order);
        assert_true(order > 1.9);
    }
}

/* (3) Grids that are not powers of two: the hierarchy halves a direction
 * while it is even and stops at odd sizes (24 → 3, 40 → 5, 440 → 55, 28 → 7,
 * 30 → 15: the coarsest level is solved by conjugate gradients).  Each case runs
 * at two resolutions, both not powers of two, with the requirements of (1)
 * and (2).  Small grids (≤ 4096 cells, here 28×30 and 56×60) run below the fine
 * level on rank 0 alone (the gather path, in correction form). */
static void test_mg_non_power_of_two(void **state)
{
    static const mgc_t odd[] = {
        {"3d P 24^3 channel", GEOM_3D, {24, 24, 24}, {NS, PER, FS}, VAR_P, UNI, 0, 0},
        {"3d U 24x12x20 walls (str.)", GEOM_3D, {24, 12, 20}, {NS, NS, PER}, VAR_U, TB, 0, 0},
        {"axi P 40x440 closed", GEOM_AXI, {40, 440, 1}, {AX, NS, PER}, VAR_P, UNI, 0, 11},
        {"axi V 40x440 (stretched)", GEOM_AXI, {40, 440, 1}, {AXF, NS, PER}, VAR_V, TH, 0, 11},
        {"2d V 48x40 mixed", GEOM_2D, {48, 40, 1}, {NF, NS, PER}, VAR_V, UNI, 0, 0},
        {"2d P 28x30 periodic", GEOM_2D, {28, 30, 1}, {PER, PER, PER}, VAR_P, UNI, 0, 0},
    };
    for (size_t i = 0; i < sizeof odd / sizeof odd[0]; i++) {
        const mgc_t *c = &odd[i];
        mgr_t r[2] = {run_case(c, 1, MPI_COMM_WORLD, NULL, NULL), run_case(c, 2, MPI_COMM_WORLD, NULL, NULL)};
        double order = conv_order(r[0].err, r[1].err, 2.0);
        msg("  %-30s cycles %2d %2d  factor %.3f %.3f  residual %.1e  error %.2e %.2e  order %.2f\n", c->name,
            r[0].cycles, r[1].cycles, r[0].factor, r[1].factor, r[1].res, r[0].err, r[1].err, order);
        for (int s = 0; s < 2; s++) {
            assert_int_equal(r[s].rc, 0);
            assert_true(r[s].res <= 1.01 * mg_opts.mg_tol);
            assert_true(r[s].factor < 0.2);
        }
        assert_true(order > 1.9);
    }
}

/* Strong stretching: x-line relaxation keeps the factor bounded when the wall
 * cells are much thinner (β = 5: 15×) and the centre cells wider (2.5×)
 * than the y/z spacing — point smoothing measured 0.27 already at β = 1.5
 * in axisymmetric geometry. */
static void test_mg_strong_stretching(void **state)
{
    static const mgc_t st[] = {
        {"3d P channel beta 5", GEOM_3D, {32, 32, 32}, {NS, PER, FS}, VAR_P, STRETCH_TANH_BOTH, 5.0, 0, 0},
        {"axi U beta 3", GEOM_AXI, {64, 128, 1}, {AX, NS, PER}, VAR_U, STRETCH_TANH_HIGH, 3.0, 0, 2},
        {"2d V beta 4, Helmholtz", GEOM_2D, {64, 64, 1}, {NS, NS, PER}, VAR_V, STRETCH_TANH_LOW, 4.0, 100, 0},
    };
    for (size_t i = 0; i < sizeof st / sizeof st[0]; i++) {
        mgr_t r = run_case(&st[i], 1, MPI_COMM_WORLD, NULL, NULL);
        msg("  %-30s cycles %2d  factor %.3f  residual %.1e  error %.2e\n", st[i].name, r.cycles, r.factor, r.res,
            r.err);
        assert_int_equal(r.rc, 0);
        assert_true(r.res <= 1.01 * mg_opts.mg_tol);
        assert_true(r.factor < 0.2);
    }
}

/* Independence of the decomposition: the same problem solved on all ranks
 * and by each rank alone (MPI_COMM_SELF).  The smoothers and transfers are
 * pointwise or exact line solves, so only reductions (norms, means, the
 * coarsest CG) and the line solves' partition differ: same cycle count and
 * solutions equal to round-off amplified by the ~10 cycles (bound 1e-12 of
 * max|x|; the coarsest CG stops at a relative 1e-8 and any change there would
 * show at that level).  One case per smoother, both large enough for the
 * distributed coarse levels. */
static void test_mg_rank_independence(void **state)
{
    static const mgc_t ri[] = {
        {"3d P channel", GEOM_3D, {32, 32, 32}, {NS, PER, FS}, VAR_P, UNI, 0, 0},
        {"axi V closed (stretched)", GEOM_AXI, {64, 128, 1}, {AXF, NS, PER}, VAR_V, TH, 0, 2},
    };
    for (size_t i = 0; i < sizeof ri / sizeof ri[0]; i++) {
        double *xw, *xs;
        grid_t *gw, *gs;
        mgr_t rw = run_case(&ri[i], 1, MPI_COMM_WORLD, &xw, &gw);
        mgr_t rs = run_case(&ri[i], 1, MPI_COMM_SELF, &xs, &gs);
        double diff = 0.0, mx = 0.0;
        for (int il = 0; il < gw->nxl; il++)
            for (int j = 0; j < gw->n[1]; j++)
                for (int k = 0; k < gw->n[2]; k++) {
                    double a = xw[G_IDX(gw, il, j, k)], b = xs[G_IDX(gs, il + gw->ix0, j, k)];
                    diff = fmax(diff, fabs(a - b));
                    mx = fmax(mx, fabs(b));
                }
        diff = grid_max(gw, diff) / grid_max(gw, mx);
        int cyc_ok = (int)grid_min(gw, rs.cycles == rw.cycles);
        msg("  %-30s cycles %d (alone %d)  max difference / max|x| %.1e\n", ri[i].name, rw.cycles, rs.cycles, diff);
        assert_true(cyc_ok);
        assert_true(diff < 1e-12);
        free(xw);
        free(xs);
        grid_free(gw);
        grid_free(gs);
    }
}

/* The interface: x may alias b (same answer as separate fields, bit for bit);
 * the same solver object serves successive λ (the line factorisation is
 * renewed); too few cycles return −1 with the residual reached. */
static void test_mg_interface(void **state)
{
    const mgc_t c = {"axi U", GEOM_AXI, {32, 64, 1}, {AX, NS, PER}, VAR_U, TH, 0, 2};
    grid_t *g = case_grid(&c, 1, MPI_COMM_WORLD);
    poisson_opts_t o = mg_opts;
    poisson_t *p = poisson_create(g, VAR_U, &o);
    double *u = field_alloc(g), *b = field_alloc(g), *x = field_alloc(g), *bx = field_alloc(g);
    double lambdas[3] = {0.0, 400.0, 0.0};
    for (int t = 0; t < 3; t++) {
        double lam = lambdas[t];
        mms_fill(p, lam, u, b);
        assert_int_equal(poisson_solve(p, lam, b, x), 0);
        field_copy(g, bx, b);
        assert_int_equal(poisson_solve(p, lam, bx, bx), 0); /* in place */
        double d = 0.0;
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++)
                if (poisson_is_unknown(p, i, j, 0)) d = fmax(d, fabs(x[G_IDX(g, i, j, 0)] - bx[G_IDX(g, i, j, 0)]));
        assert_true(grid_max(g, d) == 0.0);
        assert_true(poisson_residual(p, lam, b, x) <= 1.01 * o.mg_tol);
        assert_true(mms_error(p, lam, x, u) < 5e-3); /* discretisation error 1.6e-3 at λ = 0 (test 1) */
    }
    poisson_free(p);
    o.mg_max_cycles = 2;
    p = poisson_create(g, VAR_U, &o);
    mms_fill(p, 0.0, u, b);
    assert_int_equal(poisson_solve(p, 0.0, b, x), -1);
    assert_int_equal(p->last_iterations, 2);
    assert_true(p->last_residual > o.mg_tol);
    assert_true(fabs(poisson_residual(p, 0.0, b, x) / p->last_residual - 1.0) < 0.01);
    poisson_free(p);
    free(u);
    free(b);
    free(x);
    free(bx);
    grid_free(g);
}

/* (4) Multigrid and the direct FFT solver (src/poisson/fft.c) solve the same
 * discrete problem: their solutions agree to the multigrid tolerance.  The
 * FFT residual is at round-off (≤ 1e-13), so x_mg − x_fft = A⁻¹ r_mg with
 * ‖r_mg‖₂ ≤ mg_tol ‖b‖₂.  For smooth residuals (Poisson) A⁻¹ scales the
 * residual like the solution, for a diagonally dominant Helmholtz problem
 * the error is r/λ pointwise: either way the relative difference is of the
 * order of the relative residual, up to the ratio of max to L2 norms of the
 * (concentrated) residual and the (spread) right-hand side.  Measured: up to
 * 8.7e-11 for mg_tol = 1e-10 (λ = 1e4 case, 1 rank), typically 1e-11;
 * asserted: max difference ≤ 10 mg_tol × max|x|. */
static void test_mg_agrees_with_fft(void **state)
{
    for (size_t i = 0; i < NCASES; i++) {
        const mgc_t *c = &cases[i];
        grid_t *g = case_grid(c, 1, MPI_COMM_WORLD);
        poisson_opts_t of = mg_opts;
        of.method = POISSON_FFT;
        poisson_t *pm = poisson_create(g, c->loc, &mg_opts), *pf = poisson_create(g, c->loc, &of);
        double *u = field_alloc(g), *b = field_alloc(g), *xm = field_alloc(g), *xf = field_alloc(g);
        mms_fill(pm, c->lambda, u, b);
        assert_int_equal(poisson_solve(pm, c->lambda, b, xm), 0);
        assert_int_equal(poisson_solve(pf, c->lambda, b, xf), 0);
        double d = 0.0, mx = 0.0;
        for (int il = 0; il < g->nxl; il++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    if (!poisson_is_unknown(pm, il, j, k)) continue;
                    long cc = G_IDX(g, il, j, k);
                    d = fmax(d, fabs(xm[cc] - xf[cc]));
                    mx = fmax(mx, fabs(xf[cc]));
                }
        d = grid_max(g, d) / grid_max(g, mx);
        msg("  %-30s max|x_mg - x_fft| / max|x_fft| = %.1e  (fft residual %.1e)\n", c->name, d,
            poisson_residual(pf, c->lambda, b, xf));
        assert_true(d <= 10.0 * mg_opts.mg_tol);
        poisson_free(pm);
        poisson_free(pf);
        free(u);
        free(b);
        free(xm);
        free(xf);
        grid_free(g);
    }
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mg_cycles_and_factor), cmocka_unit_test(test_mg_second_order),
        cmocka_unit_test(test_mg_non_power_of_two),  cmocka_unit_test(test_mg_strong_stretching),
        cmocka_unit_test(test_mg_rank_independence), cmocka_unit_test(test_mg_interface),
        cmocka_unit_test(test_mg_agrees_with_fft),
    };
    TEST_MPI_RUN("poisson_mg", tests);
}
