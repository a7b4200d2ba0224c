/* test_probes.c — values of the fluid fields at points (probes.h): exact for
 * linear fields, the same on 1 and 2 ranks (points on the slab boundary
 * included), the periodic wrap, the wall half-cell and points outside.
 * RANKS: 1 2
 */
#include <stdlib.h>

#include "grid.h"
#include "probes.h"
#include "testutil.h"
#include "util.h"

static double lin(const double x[3]) { return 1.5 + 2.0 * x[0] - 3.0 * x[1] + 0.5 * x[2]; }

/* A stretched 3-D grid with walls in x and z, periodic in y (as the column
 * collapse): the interpolation of p = a + b·x is exact (to round-off) at
 * every point between the outermost cell centres, whatever the rank owning
 * its cells, and so is the velocity from face values of a linear field
 * (the mean of two faces of a linear field is its value at the centre). */
static void test_linear_exact(void **state)
{
    int n[3] = {16, 6, 8};
    double L[3] = {2.0, 1.0, 1.0}, x0[3] = {-0.5, 0.0, 0.25};
    bc_t bc = {0};
    for (int s = 0; s < 2; s++) bc.type[0][s] = bc.type[2][s] = BC_NOSLIP;
    grid_t *g = grid_create(GEOM_3D, n, L, x0, &bc, STRETCH_TANH_BOTH, 1.5, MPI_COMM_WORLD);
    double *p = field_alloc(g), *u[3];
    for (int c = 0; c < 3; c++) u[c] = field_alloc(g);
    /* every local cell and face (ghost faces included: the low face of cell 0) */
    for (int i = -1; i < g->nxl; i++)
        for (int j = -1; j <= n[1]; j++)
            for (int k = -1; k <= n[2]; k++) {
                const long m = G_IDX(g, i, j, k);
                const double xc = g->xc[i], yc = grid_yc(g, j), zc = grid_zc(g, k);
                const double pc[3] = {xc, yc, zc}, pu[3] = {g->xf[i], yc, zc}, pv[3] = {xc, grid_yf(g, j), zc},
                             pw[3] = {xc, yc, grid_zf(g, k)};
                p[m] = lin(pc);
                u[0][m] = lin(pu);
                u[1][m] = 2.0 * lin(pv);
                u[2][m] = -lin(pw);
            }
    /* points: general ones, on the boundary between the two slabs (x = the
     * face of global cell 7), on a cell centre, on the periodic seam */
    const double xs = g->gxf[7], xc3 = g->gxc[3];
    const double pts[] = {0.1, 0.3, 0.6, xs, 0.5, 0.5, xc3, grid_yc(g, 2), 0.9, 1.2, 0.77, 1.0,
                          0.5 * (xs + g->gxc[8]), 0.41, 0.42};
    const int np = sizeof pts / sizeof pts[0] / 3;
    int bad = -1;
    probes_t *pr = probes_create(g, np, pts, &bad);
    assert_non_null(pr);
    double val[8], vel[24], err = 0, errv = 0;
    probes_eval_cell(pr, p, val);
    probes_eval_velocity(pr, u, vel);
    for (int i = 0; i < np; i++) {
        const double e = lin(pts + 3 * i);
        err = fmax(err, fabs(val[i] - e));
        errv = fmax(errv, fabs(vel[3 * i] - e));
        errv = fmax(errv, fabs(vel[3 * i + 1] - 2.0 * e));
        errv = fmax(errv, fabs(vel[3 * i + 2] + e));
    }
    msg("  linear field: max |error| p %.2e, velocity %.2e\n", err, errv);
    /* round-off of O(1) values: a few ulp times the 8 terms */
    assert_true(err < 1e-13 && errv < 1e-13);
    probes_free(pr);

    /* between a wall and the first cell centre: the centre's value (zero
     * normal gradient), here at z and x below the first centres */
    const double pw[3] = {g->gxc[5], 0.5, x0[2]};
    pr = probes_create(g, 1, pw, &bad);
    probes_eval_cell(pr, p, val);
    const double pe[3] = {g->gxc[5], 0.5, grid_zc(g, 0)};
    assert_true(fabs(val[0] - lin(pe)) < 1e-13);
    probes_free(pr);

    /* outside: x below the domain, then z above it */
    const double out[] = {0.0, 0.5, 0.5, x0[0] - 1e-9, 0.5, 0.5, 0.0, 0.5, x0[2] + L[2] + 1e-6};
    bad = -1;
    assert_null(probes_create(g, 3, out, &bad));
    assert_int_equal(bad, 1);
    /* on the faces: inside */
    const double on[] = {x0[0], 0.0, 0.5, x0[0] + L[0], 1.0, x0[2] + L[2]};
    pr = probes_create(g, 2, on, &bad);
    assert_non_null(pr);
    probes_free(pr);
    for (int c = 0; c < 3; c++) free(u[c]);
    free(p);
    grid_free(g);
}

/* The periodic seam: between the last cell centre and the face y = L the
 * value is the linear interpolation between the last and the first cells. */
static void test_periodic_wrap(void **state)
{
    int n[3] = {8, 8, 1};
    double L[3] = {1.0, 2.0, 1.0};
    grid_t *g = grid_create(GEOM_2D, n, L, NULL, NULL, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    double *p = field_alloc(g);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < n[1]; j++) p[G_IDX(g, i, j, 0)] = 10.0 * (i + g->ix0) + j;
    /* y = L − dy/4: a quarter of a cell beyond the last centre (j = 7),
     * weight 1/4 on the first (j = 0); x = 1/32: below the first centre in x,
     * periodic too: weights 1/4 on i = 7, 3/4 on i = 0 */
    const double pt[3] = {1.0 / 32.0, 2.0 - 0.25 * 0.25, 0.0};
    int bad = -1;
    probes_t *pr = probes_create(g, 1, pt, &bad);
    double v;
    probes_eval_cell(pr, p, &v);
    const double ey = 0.75 * 7 + 0.25 * 0, ex = 0.25 * 70 + 0.75 * 0;
    msg("  periodic seam: %.15g, expected %.15g\n", v, ex + ey);
    assert_true(fabs(v - (ex + ey)) < 1e-12);
    probes_free(pr);
    free(p);
    grid_free(g);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_linear_exact),
        cmocka_unit_test(test_periodic_wrap),
    };
    TEST_MPI_RUN("probes", tests);
}
