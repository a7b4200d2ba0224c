/* test_grid.c — grid geometry, halo exchange, and the consistency of the
 * discrete Laplacian of every variable location (poisson_apply).
 * RANKS: 1 2
 */
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "poisson.h"
#include "testutil.h"
#include "util.h"

/* Halo exchange on a triply periodic grid: each ghost must hold the value of
 * the periodic image, identified by a global code of (i, j, k). */
static void test_halo_periodic(void **state)
{
    int n[3] = {8, 6, 4};
    double L[3] = {1, 1, 1};
    grid_t *g = grid_create(GEOM_3D, n, L, NULL, NULL, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    double *f = field_alloc(g);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < 6; j++)
            for (int k = 0; k < 4; k++) f[G_IDX(g, i, j, k)] = 100 * (i + g->ix0) + 10 * j + k;
    grid_halo(g, f);
    int bad = 0;
    for (int i = -1; i <= g->nxl; i++)
        for (int j = -1; j <= 6; j++)
            for (int k = -1; k <= 4; k++) {
                int ig = ((i + g->ix0) % 8 + 8) % 8, jj = (j + 6) % 6, kk = (k + 4) % 4;
                if (f[G_IDX(g, i, j, k)] != 100 * ig + 10 * jj + kk) bad++;
            }
    bad = (int)grid_sum(g, bad);
    assert_int_equal(bad, 0);
    free(f);
    grid_free(g);
}

static void test_stretched_geometry(void **state)
{
    int n[3] = {32, 4, 1};
    double L[3] = {2.0, 1, 1};
    bc_t bc = {0};
    bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
    grid_t *g = grid_create(GEOM_2D, n, L, NULL, &bc, STRETCH_TANH_BOTH, 2.0, MPI_COMM_WORLD);
    double sum = 0;
    for (int i = 0; i < g->n[0]; i++) {
        assert_true(g->gdxf[i] > 0);
        sum += g->gdxf[i];
        assert_true(fabs(g->gxc[i] - 0.5 * (g->gxf[i] + g->gxf[i - 1])) < 1e-15);
    }
    assert_true(fabs(sum - 2.0) < 1e-13);
    /* clustering at both walls: the first cell is the smallest */
    assert_true(g->gdxf[0] < g->gdxf[16]);
    grid_free(g);
}

/* Manufactured field for the operator check.  Returns f and its exact
 * Laplacian (vector Laplacian for u_r in axisymmetric geometry).  The
 * functions satisfy the homogeneous BCs of the location. */
typedef struct {
    geom_t geom;
    var_loc_t loc;
    int noslip; /* walls in x and y (else periodic in y, walls in x) */
} case_t;

static double fx(const case_t *c, double x, double *d2)
{
    /* On [0,1]: cos(πx) has zero slope at both ends (Neumann); sin(πx)
     * vanishes at both ends (Dirichlet). */
    if (c->geom == GEOM_AXI) {
        /* axisymmetric, r in [0,1] */
        if (c->loc == VAR_U) {
            /* u_r = r(1−r)... choose f = sin(πr) r⁰: vector Laplacian f'' + f'/r − f/r² */
            double f = sin(M_PI * x);
            double fp = M_PI * cos(M_PI * x), fpp = -M_PI * M_PI * f;
            *d2 = fpp + fp / x - f / (x * x);
            return f;
        }
        /* scalar: f = cos(πr): f'' + f'/r */
        double f = cos(M_PI * x), fp = -M_PI * sin(M_PI * x), fpp = -M_PI * M_PI * f;
        *d2 = fpp + (x > 0 ? fp / x : -M_PI * M_PI);
        return f;
    }
    int dir = c->loc == VAR_U || (c->noslip && c->loc != VAR_P);
    double f = dir ? sin(M_PI * x) : cos(M_PI * x);
    *d2 = -M_PI * M_PI * f;
    return f;
}

static double max_trunc_error(const case_t *c, int N)
{
    int n[3] = {N, N, c->geom == GEOM_3D ? N : 1};
    double L[3] = {1, 1, 1};
    bc_t bc = {0};
    bc.type[0][0] = c->geom == GEOM_AXI ? BC_AXIS : BC_NOSLIP;
    bc.type[0][1] = BC_NOSLIP;
    if (!c->noslip) bc.type[0][1] = bc.type[0][0] == BC_AXIS ? BC_FREESLIP : BC_FREESLIP;
    if (!c->noslip && bc.type[0][0] == BC_NOSLIP) bc.type[0][0] = BC_FREESLIP;
    stretch_t st = c->geom == GEOM_AXI ? STRETCH_TANH_HIGH : STRETCH_TANH_BOTH;
    grid_t *g = grid_create(c->geom, n, L, NULL, &bc, st, 1.5, MPI_COMM_WORLD);
    poisson_opts_t o = {.method = POISSON_FFT};
    /* build the operator description only (the back-end is not used) */
    poisson_t *p = poisson_create(g, c->loc, &o);
    double *f = field_alloc(g), *lf = field_alloc(g), *ex = field_alloc(g);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                double x = c->loc == VAR_U ? g->xf[i] : g->xc[i];
                double y = c->loc == VAR_V ? grid_yf(g, j) : grid_yc(g, j);
                double d2x, gy = 2 * M_PI * y;
                double a = fx(c, x, &d2x);
                /* y: periodic cos(2πy) */
                double b = cos(gy), d2y = -4 * M_PI * M_PI * b;
                f[G_IDX(g, i, j, k)] = a * b;
                ex[G_IDX(g, i, j, k)] = d2x * b + a * d2y;
            }
    poisson_apply(p, 0.0, f, lf);
    double err = 0;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++)
                /* Boundary cells of a stretched grid have a first-order local
                 * truncation error (the wall flux is exact, the interior one
                 * is off by O(h²)): the solution is still second order
                 * (supraconvergence, measured by the Poisson tests), so the
                 * consistency check looks at the interior only. */
                if (poisson_is_unknown(p, i, j, k) && i + g->ix0 > 0 && i + g->ix0 < p->nu[0] - 1)
                    err = fmax(err, fabs(lf[G_IDX(g, i, j, k)] - ex[G_IDX(g, i, j, k)]));
    err = grid_max(g, err);
    free(f);
    free(lf);
    free(ex);
    p->impl = NULL; /* placeholder back-end owns nothing */
    poisson_free(p);
    grid_free(g);
    return err;
}

/* The operator is second order on stretched grids (smooth map) for every
 * location, including the axisymmetric metric: the interior truncation error
 * must converge at order > 1.8 (2 asymptotically; 1.8 leaves room for the
 * pre-asymptotic range at 64→128). */
/* uniform_arithmetic (Izard's bouncing-sphere grid): nu equal cells over lu,
 * then sizes h + k a with a constant increment a, ending exactly at L. */
static void test_uniform_arithmetic(void **state)
{
    (void)state;
    const int n[3] = {80, 8, 1}, nu = 50;
    const double L[3] = {10.4, 1, 1}, lu = 2.5;
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    bc.type[0][0] = BC_AXIS;
    bc.type[0][1] = BC_FREESLIP;
    bc.type[1][0] = bc.type[1][1] = BC_FREESLIP;
    grid_t *g = grid_create_uniform_arithmetic(GEOM_AXI, n, L, NULL, &bc, nu, lu, MPI_COMM_WORLD);
    const double h = lu / nu;
    double worst_u = 0, worst_a = 0;
    for (int i = 0; i < nu; i++) worst_u = fmax(worst_u, fabs(g->gdxf[i] - h));
    const double a = g->gdxf[nu + 1] - g->gdxf[nu];
    for (int i = nu; i < n[0]; i++) worst_a = fmax(worst_a, fabs(g->gdxf[i] - (h + (i - nu + 1) * a)));
    printf("uniform_arithmetic: uniform part error %.1e, increment %.5f, arithmetic error %.1e, last face %.15g\n",
           worst_u, a, worst_a, g->gxf[n[0] - 1]);
    /* round-off of sums of ~100 terms of size ~1 */
    assert_true(worst_u < 1e-13 && worst_a < 1e-13);
    assert_true(fabs(g->gxf[n[0] - 1] - L[0]) < 1e-13);
    assert_true(a > 0);
    /* the seed's numbers: 30 cells from 0.05 growing to 0.463 D (reference notes §2.6) */
    assert_true(fabs(g->gdxf[n[0] - 1] - (h + 30 * a)) < 1e-13 && fabs(h + 30 * a - 0.4628) < 1e-3);
    grid_free(g);
}

static void test_operator_consistency(void **state)
{
    case_t cases[] = {{GEOM_2D, VAR_P, 0}, {GEOM_2D, VAR_U, 0}, {GEOM_2D, VAR_V, 1},
                      {GEOM_AXI, VAR_P, 0}, {GEOM_AXI, VAR_U, 0}, {GEOM_AXI, VAR_V, 0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double e1 = max_trunc_error(&cases[c], 64), e2 = max_trunc_error(&cases[c], 128);
        double order = conv_order(e1, e2, 2.0);
        msg("  geom %d loc %d noslip %d: trunc err %.3e -> %.3e, order %.2f\n", cases[c].geom, cases[c].loc,
            cases[c].noslip, e1, e2, order);
        assert_true(order > 1.8);
    }
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_halo_periodic),
        cmocka_unit_test(test_stretched_geometry),
        cmocka_unit_test(test_operator_consistency),
        cmocka_unit_test(test_uniform_arithmetic),
    };
    TEST_MPI_RUN("grid", tests);
}
