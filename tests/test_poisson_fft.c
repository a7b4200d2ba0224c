/* test_poisson_fft.c — the direct (FFT eigen-expansion) Poisson/Helmholtz
 * solver against manufactured solutions, for every boundary combination,
 * variable location and geometry.
 * RANKS: 1 2
 *
 * For each case the exact solution f is a product of one-dimensional
 * functions, each satisfying the homogeneous BC pair of its direction for
 * that location (see factor()).  b = (∇² − λ) f is evaluated exactly at the
 * unknowns; the solver's x must
 *   (1) satisfy the discrete equations to round-off: poisson_residual() is
 *       small (bound justified at RESID_TOL), for this b and for a random b
 *       that excites every mode, and
 *   (2) converge to f at second order (measured on two resolutions).
 */
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "poisson.h"
#include "testutil.h"
#include "util.h"

/* Relative residual bound.  A direct solve is backward stable: the residual
 * is about c·ε·‖A‖‖x‖/‖b‖ ≤ c·ε·κ(A), c a modest factor from the O(log n)
 * transform stages.  On the convergence grids (≤ 48 cells per direction,
 * tanh-stretched x with β = 1.5, smallest Δx ≈ L/100) κ(A) ≈ (4/Δx²_min)/π²
 * ≲ 5e3, i.e. ≲ 1e-12; measured: ≤ 1e-13.  The most anisotropic special
 * grid (Δz = 0.7/1024, Δx = 1/8) reaches 9e-13.  1e-11 leaves a factor 10
 * and is still 6 orders below what a wrong eigenvalue does: a relative error
 * δ in one eigenvalue leaves a residual of order δ in that mode (the tests
 * fail for a shift of 1e-4 in a wave number, measured). */
#define RESID_TOL 1e-11
/* Second order: the error ratio between N and 2N must give order > 1.8 (2
 * asymptotically; the 0.2 margin covers the pre-asymptotic range of the
 * coarse grid; measured orders are 1.88-2.03). */
#define ORDER_MIN 1.8

enum { O_PER, O_NS, O_FS, O_NS_FS, O_FS_NS, O_COUNT };
static const char *opt_name[O_COUNT] = {"per", "ns", "fs", "ns/fs", "fs/ns"};

typedef struct {
    geom_t geom;
    int bc[3];       /* O_* per direction (x: for GEOM_AXI only the high face, O_NS or O_FS) */
    var_loc_t loc;
    double lambda;
    int stretch;     /* tanh stretching of a non-periodic x */
    int nbase[3];    /* cells at the coarse level */
    double L[3];
} pcase_t;

static void set_faces(bc_t *bc, int d, int opt)
{
    static const bc_type_t lo[O_COUNT] = {BC_PERIODIC, BC_NOSLIP, BC_FREESLIP, BC_NOSLIP, BC_FREESLIP};
    static const bc_type_t hi[O_COUNT] = {BC_PERIODIC, BC_NOSLIP, BC_FREESLIP, BC_FREESLIP, BC_NOSLIP};
    bc->type[d][0] = lo[opt];
    bc->type[d][1] = hi[opt];
}

/* One-dimensional factor of the exact solution for the BC pair (lo, hi) of a
 * direction of length L starting at x0: value, first and second derivative.
 * f = A·E: A is the lowest eigenfunction of the pair (cos for Neumann, sin
 * for Dirichlet, quarter waves for a mixed pair, a shifted cos if periodic)
 * and E = exp(ε cos(πs)) (periodic: exp(ε sin(2πs + 0.7))), s = (x − x0)/L,
 * which keeps the symmetry of A about both ends (so A·E satisfies the same
 * BCs, with vanishing odd derivatives at a Neumann end and even ones at a
 * Dirichlet end) while spreading the solution over many transform modes:
 * a single eigenfunction would only test one mode of each direction. */
static void factor(ebc_t lo, ebc_t hi, double L, double x0, double x, double *f, double *fp, double *fpp)
{
    double s = (x - x0) / L, k, ph = 0.0, eps = lo == EBC_PERIODIC ? 0.25 : 0.5;
    int use_sin;
    if (lo == EBC_PERIODIC) {
        k = 2 * M_PI;
        ph = 0.3; /* no symmetry about the grid */
        use_sin = 0;
    } else if (lo == EBC_NEUMANN && hi == EBC_NEUMANN) {
        k = M_PI;
        use_sin = 0;
    } else if (lo == EBC_NEUMANN) { /* Dirichlet high: quarter wave */
        k = M_PI / 2;
        use_sin = 0;
    } else if (hi == EBC_NEUMANN) { /* Dirichlet low, Neumann high */
        k = M_PI / 2;
        use_sin = 1;
    } else {                        /* Dirichlet both */
        k = M_PI;
        use_sin = 1;
    }
    double a = k * s + ph, A, A1, A2;
    if (use_sin) {
        A = sin(a);
        A1 = k * cos(a);
    } else {
        A = cos(a);
        A1 = -k * sin(a);
    }
    A2 = -k * k * A;
    double g, g1, g2; /* E = exp(g) */
    if (lo == EBC_PERIODIC) {
        g = eps * sin(2 * M_PI * s + 0.7);
        g1 = eps * 2 * M_PI * cos(2 * M_PI * s + 0.7);
        g2 = -4 * M_PI * M_PI * g;
    } else {
        g = eps * cos(M_PI * s);
        g1 = -eps * M_PI * sin(M_PI * s);
        g2 = -M_PI * M_PI * g;
    }
    double E = exp(g), E1 = g1 * E, E2 = (g2 + g1 * g1) * E;
    /* d/dx = (1/L) d/ds */
    *f = A * E;
    *fp = (A1 * E + A * E1) / L;
    *fpp = (A2 * E + 2 * A1 * E1 + A * E2) / (L * L);
}

/* Deterministic pseudo-random right-hand side (white spectrum: every mode
 * of every direction is excited), from the global index so that any rank
 * count sees the same values. */
static void random_rhs(const poisson_t *p, double *b)
{
    const grid_t *g = p->g;
    field_zero(g, b);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                if (!poisson_is_unknown(p, i, j, k)) continue;
                uint64_t h = ((uint64_t)(i + g->ix0) * 73856093u) ^ ((uint64_t)j * 19349663u) ^ ((uint64_t)k * 83492791u);
                h = h * 6364136223846793005ULL + 1442695040888963407ULL;
                h ^= h >> 29;
                h *= 0xbf58476d1ce4e5b9ULL;
                h ^= h >> 32;
                b[G_IDX(g, i, j, k)] = (double)(h >> 11) / 9007199254740992.0 - 0.5;
            }
}

static grid_t *case_grid(const pcase_t *c, int scale, MPI_Comm comm)
{
    int n[3] = {c->nbase[0] * scale, c->nbase[1] * scale, c->geom == GEOM_3D ? c->nbase[2] * scale : 1};
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < (c->geom == GEOM_3D ? 3 : 2); d++) set_faces(&bc, d, c->bc[d]);
    if (c->geom == GEOM_AXI) {
        bc.type[0][0] = BC_AXIS;
        bc.type[0][1] = c->bc[0] == O_NS ? BC_NOSLIP : BC_FREESLIP;
    }
    stretch_t st = STRETCH_UNIFORM;
    if (c->stretch && c->bc[0] != O_PER) st = c->geom == GEOM_AXI ? STRETCH_TANH_HIGH : STRETCH_TANH_BOTH;
    double x0[3] = {0.0, -0.2, 0.1};
    return grid_create(c->geom, n, c->L, x0, &bc, st, 1.5, comm);
}

/* Exact solution and right-hand side at the unknowns; other points 0. */
static void manufacture(const poisson_t *p, double lambda, double *f, double *b)
{
    const grid_t *g = p->g;
    int axi = g->geom == GEOM_AXI;
    field_zero(g, f);
    field_zero(g, b);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                if (!poisson_is_unknown(p, i, j, k)) continue;
                double pos[3] = {p->loc == VAR_U ? g->xf[i] : g->xc[i],
                                 p->loc == VAR_V ? grid_yf(g, j) : grid_yc(g, j),
                                 p->loc == VAR_W ? grid_zf(g, k) : grid_zc(g, k)};
                double v[3] = {1, 1, 1}, d1[3] = {0, 0, 0}, d2[3] = {0, 0, 0};
                for (int d = 0; d < g->dim; d++)
                    factor(p->ebc[d][0], p->ebc[d][1], g->L[d], g->x0[d], pos[d], &v[d], &d1[d], &d2[d]);
                /* radial part of the Laplacian: f'' + f'/r, and − f/r² for u_r */
                double lx = d2[0];
                if (axi) lx += d1[0] / pos[0] - (p->loc == VAR_U ? v[0] / (pos[0] * pos[0]) : 0.0);
                long c = G_IDX(g, i, j, k);
                f[c] = v[0] * v[1] * v[2];
                b[c] = lx * v[1] * v[2] + v[0] * d2[1] * v[2] + v[0] * v[1] * d2[2] - lambda * f[c];
            }
}

/* Max-norm error of x against f over the unknowns, after removing the mean
 * difference when the problem is singular (its solution is defined up to a
 * constant). */
static double max_error(const poisson_t *p, double lambda, const double *x, const double *f)
{
    const grid_t *g = p->g;
    double shift = 0.0;
    if (p->singular && lambda == 0.0) {
        double s = 0.0, cnt = 0.0;
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++)
                    if (poisson_is_unknown(p, i, j, k)) {
                        s += x[G_IDX(g, i, j, k)] - f[G_IDX(g, i, j, k)];
                        cnt += 1.0;
                    }
        shift = grid_sum(g, s) / grid_sum(g, cnt);
    }
    double e = 0.0;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                if (poisson_is_unknown(p, i, j, k))
                    e = fmax(e, fabs(x[G_IDX(g, i, j, k)] - f[G_IDX(g, i, j, k)] - shift));
    return grid_max(g, e);
}

/* Solve one case at one resolution (in place: x starts as a copy of b, which
 * also checks that x may alias b).  Returns the max error; *res gets the
 * relative residual of this solve and, on the fine grid, the larger of it
 * and that of a solve with a random right-hand side. */
static double solve_case(const pcase_t *c, int scale, double *res)
{
    grid_t *g = case_grid(c, scale, MPI_COMM_WORLD);
    poisson_opts_t o = {.method = POISSON_FFT};
    poisson_t *p = poisson_create(g, c->loc, &o);
    double *f = field_alloc(g), *b = field_alloc(g), *x = field_alloc(g);
    manufacture(p, c->lambda, f, b);
    field_copy(g, x, b);
    int rc = poisson_solve(p, c->lambda, x, x);
    assert_int_equal(rc, 0);
    double err = max_error(p, c->lambda, x, f);
    *res = poisson_residual(p, c->lambda, b, x);
    if (scale > 1) {
        random_rhs(p, b);
        rc = poisson_solve(p, c->lambda, b, x);
        assert_int_equal(rc, 0);
        *res = fmax(*res, poisson_residual(p, c->lambda, b, x));
    }
    free(f);
    free(b);
    free(x);
    poisson_free(p);
    grid_free(g);
    return err;
}

typedef struct {
    int n, bad;
    double worst_res, min_order, max_order;
} tally_t;

static void tally(tally_t *t, double res, double order, int bad)
{
    t->n++;
    t->bad += bad;
    t->worst_res = fmax(t->worst_res, res);
    if (t->n == 1 || order < t->min_order) t->min_order = order;
    if (t->n == 1 || order > t->max_order) t->max_order = order;
}

static void run_case(const pcase_t *c, tally_t *t, int verbose)
{
    double r1, r2;
    double e1 = solve_case(c, 1, &r1), e2 = solve_case(c, 2, &r2);
    double order = conv_order(e1, e2, 2.0), res = fmax(r1, r2);
    int bad = !(res < RESID_TOL) || !(order > ORDER_MIN);
    if (bad || verbose)
        msg("  %s geom %d x:%s y:%s z:%s loc %2d λ=%g%s: err %.3e -> %.3e order %.3f resid %.1e\n",
            bad ? "FAIL" : "    ", c->geom, c->geom == GEOM_AXI ? (c->bc[0] == O_NS ? "axis/ns" : "axis/fs")
                                                                 : opt_name[c->bc[0]],
            opt_name[c->bc[1]], c->geom == GEOM_3D ? opt_name[c->bc[2]] : "-", (int)c->loc, c->lambda,
            c->stretch && c->bc[0] != O_PER ? " stretched" : "", e1, e2, order, res);
    tally(&t[0], res, order, bad);
    tally(&t[2 + (int)c->loc], res, order, bad);
}

/* t[0]: all cases; t[1 + l]: location l = loc + 1 (p, u, v, w) */
static void report(const char *what, const tally_t *t)
{
    static const char *ln[4] = {"p", "u", "v", "w"};
    msg("  %s: %d cases, order %.3f..%.3f, worst relative residual %.2e, failures %d\n", what, t[0].n,
        t[0].min_order, t[0].max_order, t[0].worst_res, t[0].bad);
    for (int l = 0; l < 4; l++)
        if (t[1 + l].n)
            msg("    %s %s: %d cases, order %.3f..%.3f, worst relative residual %.2e\n", what, ln[l], t[1 + l].n,
                t[1 + l].min_order, t[1 + l].max_order, t[1 + l].worst_res);
}

/* 3-D: every combination of periodic / no-slip / free-slip / mixed pairs in
 * the three directions, every location, Poisson and Helmholtz; non-periodic
 * x is tanh-stretched.  The sizes differ per direction (and the y count of
 * a normal component is odd, 11, so 2 ranks split the y modes unevenly). */
static void test_3d_all_combinations(void **state)
{
    tally_t t[5] = {{0}};
    var_loc_t locs[4] = {VAR_P, VAR_U, VAR_V, VAR_W};
    for (int bx = 0; bx < O_COUNT; bx++)
        for (int by = 0; by < O_COUNT; by++)
            for (int bz = 0; bz < O_COUNT; bz++)
                for (int l = 0; l < 4; l++)
                    for (int h = 0; h < 2; h++) {
                        pcase_t c = {GEOM_3D, {bx, by, bz}, locs[l], h ? 50.0 : 0.0, 1, {16, 12, 10}, {1.0, 1.3, 0.7}};
                        run_case(&c, t, 0);
                    }
    report("3-D", t);
    assert_int_equal(t[0].bad, 0);
}

/* 2-D planar: every pair of x/y options, locations P, U, V, uniform and
 * stretched x, Poisson and Helmholtz. */
static void test_2d_all_combinations(void **state)
{
    tally_t t[5] = {{0}};
    var_loc_t locs[3] = {VAR_P, VAR_U, VAR_V};
    for (int bx = 0; bx < O_COUNT; bx++)
        for (int by = 0; by < O_COUNT; by++)
            for (int l = 0; l < 3; l++)
                for (int st = 0; st < 2; st++)
                    for (int h = 0; h < 2; h++) {
                        if (st && bx == O_PER) continue;
                        pcase_t c = {GEOM_2D, {bx, by, 0}, locs[l], h ? 50.0 : 0.0, st, {16, 20, 1}, {1.0, 1.7, 1}};
                        run_case(&c, t, 0);
                    }
    report("2-D", t);
    assert_int_equal(t[0].bad, 0);
}

/* Axisymmetric (x = r with the axis at r = 0): outer wall no-slip or free
 * slip, every y option, locations P, U (= u_r, vector Laplacian), V, uniform
 * and tanh_high-stretched r, Poisson and Helmholtz. */
static void test_axisymmetric(void **state)
{
    tally_t t[5] = {{0}};
    var_loc_t locs[3] = {VAR_P, VAR_U, VAR_V};
    for (int bx = O_NS; bx <= O_FS; bx++)
        for (int by = 0; by < O_COUNT; by++)
            for (int l = 0; l < 3; l++)
                for (int st = 0; st < 2; st++)
                    for (int h = 0; h < 2; h++) {
                        pcase_t c = {GEOM_AXI, {bx, by, 0}, locs[l], h ? 50.0 : 0.0, st, {16, 24, 1}, {0.8, 2.0, 1}};
                        run_case(&c, t, 0);
                    }
    report("axisymmetric", t);
    assert_int_equal(t[0].bad, 0);
}

/* Sizes that take the other branches of the solver: row chunks of the
 * z transforms with a remainder (nz = 1024 gives chunks of 8 rows, ny = 10),
 * an odd periodic y with a Neumann z and the reverse (odd counts are fine
 * for a periodic direction of the fast path), an odd Neumann count (general
 * r2r path), odd periodic sizes; x periodic and walled, Poisson and
 * Helmholtz.  Only the residual is checked (random right-hand side, every
 * mode excited), against the same bound as above. */
static void test_special_sizes(void **state)
{
    struct {
        int n[3], bc[3];
    } grids[] = {{{8, 10, 1024}, {O_NS, O_FS, O_NS}},  {{8, 9, 8}, {O_NS, O_PER, O_FS}},
                 {{8, 8, 9}, {O_NS, O_FS, O_PER}},     {{8, 9, 10}, {O_NS, O_FS, O_FS}},
                 {{8, 7, 9}, {O_NS, O_PER, O_PER}},    {{8, 9, 8}, {O_PER, O_PER, O_NS}},
                 {{8, 8, 9}, {O_PER, O_NS, O_PER}},    {{8, 12, 8}, {O_PER, O_NS, O_FS}}};
    double worst = 0.0;
    for (size_t ig = 0; ig < sizeof grids / sizeof grids[0]; ig++)
        for (int l = 0; l < 4; l++)
            for (int h = 0; h < 2; h++) {
                pcase_t c = {GEOM_3D, {grids[ig].bc[0], grids[ig].bc[1], grids[ig].bc[2]}, (var_loc_t)(l - 1),
                             h ? 7.0 : 0.0, 0, {grids[ig].n[0], grids[ig].n[1], grids[ig].n[2]}, {1.0, 1.3, 0.7}};
                grid_t *g = case_grid(&c, 1, MPI_COMM_WORLD);
                poisson_t *p = poisson_create(g, c.loc, NULL);
                double *b = field_alloc(g), *x = field_alloc(g);
                random_rhs(p, b);
                poisson_solve(p, c.lambda, b, x);
                double r = poisson_residual(p, c.lambda, b, x);
                if (!(r < RESID_TOL))
                    msg("  FAIL grid %zu loc %d λ=%g: residual %.2e\n", ig, (int)c.loc, c.lambda, r);
                worst = fmax(worst, r);
                free(b);
                free(x);
                poisson_free(p);
                grid_free(g);
            }
    msg("  special sizes: worst relative residual %.2e\n", worst);
    assert_true(worst < RESID_TOL);
}

/* The distributed solve equals a serial solve of the same problem (every
 * rank solves the whole problem on MPI_COMM_SELF and compares its slab) to
 * round-off: the operations per mode are the same, only the FFTW algorithms
 * for the differently strided layouts may differ, so the difference is a few
 * ulps of the solution (bound 1e-13 relative to max |x|).  On one rank this
 * checks run-to-run determinism (bitwise). */
static void test_matches_serial(void **state)
{
    pcase_t cases[] = {{GEOM_3D, {O_NS_FS, O_NS, O_PER}, VAR_V, 0.0, 1, {16, 13, 10}, {1.0, 1.3, 0.7}},
                       {GEOM_3D, {O_PER, O_FS, O_NS}, VAR_P, 0.0, 0, {16, 15, 6}, {1.0, 1.3, 0.7}},
                       {GEOM_3D, {O_PER, O_PER, O_FS_NS}, VAR_U, 3.0, 0, {16, 7, 9}, {1.0, 1.3, 0.7}},
                       {GEOM_AXI, {O_NS, O_PER, 0}, VAR_U, 0.0, 1, {16, 9, 1}, {1.0, 1.3, 1}}};
    double worst = 0.0;
    for (size_t ic = 0; ic < sizeof cases / sizeof cases[0]; ic++) {
        const pcase_t *c = &cases[ic];
        grid_t *g = case_grid(c, 2, MPI_COMM_WORLD), *gs = case_grid(c, 2, MPI_COMM_SELF);
        poisson_t *p = poisson_create(g, c->loc, NULL), *ps = poisson_create(gs, c->loc, NULL);
        double *f = field_alloc(g), *b = field_alloc(g), *x = field_alloc(g);
        double *fs = field_alloc(gs), *bs = field_alloc(gs), *xs = field_alloc(gs);
        manufacture(p, c->lambda, f, b);
        manufacture(ps, c->lambda, fs, bs);
        poisson_solve(p, c->lambda, b, x);
        poisson_solve(ps, c->lambda, bs, xs);
        double d = 0.0, m = 0.0;
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    double a = x[G_IDX(g, i, j, k)], s = xs[G_IDX(gs, i + g->ix0, j, k)];
                    d = fmax(d, fabs(a - s));
                    m = fmax(m, fabs(s));
                }
        d = grid_max(g, d) / grid_max(g, m);
        msg("  case %zu: max |x_distributed − x_serial| / max|x| = %.2e\n", ic, d);
        worst = fmax(worst, d);
        free(f);
        free(b);
        free(x);
        free(fs);
        free(bs);
        free(xs);
        poisson_free(p);
        poisson_free(ps);
        grid_free(g);
        grid_free(gs);
    }
    assert_true(worst < 1e-13);
    if (mpi_size() == 1) assert_true(worst == 0.0);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_3d_all_combinations),
        cmocka_unit_test(test_2d_all_combinations),
        cmocka_unit_test(test_axisymmetric),
        cmocka_unit_test(test_special_sizes),
        cmocka_unit_test(test_matches_serial),
    };
    TEST_MPI_RUN("poisson_fft", tests);
}
