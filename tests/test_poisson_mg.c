/* test_poisson_mg.c — geometric multigrid (src/poisson/multigrid.c).
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
    double lambda;
} mgc_t;

#define PER {BC_PERIODIC, BC_PERIODIC}
#define NS {BC_NOSLIP, BC_NOSLIP}
#define FS {BC_FREESLIP, BC_FREESLIP}
#define NF {BC_NOSLIP, BC_FREESLIP}
#define AX {BC_AXIS, BC_NOSLIP}
#define AXF {BC_AXIS, BC_FREESLIP}

typedef struct {
    int cycles, rc;
    double res, factor, err, time;
} mgr_t;

static mgr_t run_case(const mgc_t *c, int scale, MPI_Comm comm)
{
    int n[3] = {c->n[0] * scale, c->n[1] * scale, c->geom == GEOM_3D ? c->n[2] * scale : 1};
    double L[3] = {1.0, c->geom == GEOM_AXI ? 2.0 : 1.0, 1.0};
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++) bc.type[d][s] = c->bc[d][s];
    grid_t *g = grid_create(c->geom, n, L, NULL, &bc, c->stretch, 1.5, comm);
    poisson_opts_t o = {.method = POISSON_MG, .mg_tol = 1e-10, .mg_max_cycles = 60, .mg_pre = 2, .mg_post = 2};
    poisson_t *p = poisson_create(g, c->loc, &o);
    double *u = field_alloc(g), *b = field_alloc(g), *x = field_alloc(g);
    mms_fill(p, c->lambda, u, b);
    mgr_t r;
    MPI_Barrier(comm);
    double t0 = wtime();
    r.rc = poisson_solve(p, c->lambda, b, x);
    r.time = wtime() - t0;
    r.cycles = p->last_iterations;
    r.res = poisson_residual(p, c->lambda, b, x);
    r.factor = pow(p->last_residual, 1.0 / r.cycles);
    r.err = mms_error(p, c->lambda, x, u);
    free(u);
    free(b);
    free(x);
    poisson_free(p);
    grid_free(g);
    return r;
}

static const mgc_t cases[] = {
    {"2d P cavity (stretched) dbg", GEOM_2D, {8, 8, 1}, {NS, NS, PER}, VAR_P, STRETCH_TANH_BOTH, 0},
    {"2d V y-walls", GEOM_2D, {32, 32, 1}, {PER, NS, PER}, VAR_V, STRETCH_UNIFORM, 0},
    {"2d V x-noslip y-walls", GEOM_2D, {32, 32, 1}, {NS, NS, PER}, VAR_V, STRETCH_UNIFORM, 0},
    {"2d V x-freeslip y-walls", GEOM_2D, {32, 32, 1}, {FS, NS, PER}, VAR_V, STRETCH_UNIFORM, 0},
    {"2d U x-walls y-free", GEOM_2D, {32, 32, 1}, {NS, FS, PER}, VAR_U, STRETCH_UNIFORM, 0},
    {"2d P neumann", GEOM_2D, {32, 32, 1}, {NS, NS, PER}, VAR_P, STRETCH_UNIFORM, 0},
    {"2d P neumann per", GEOM_2D, {32, 32, 1}, {NS, PER, PER}, VAR_P, STRETCH_UNIFORM, 0},
    {"2d V x-freeslip y-per", GEOM_2D, {32, 32, 1}, {FS, PER, PER}, VAR_V, STRETCH_UNIFORM, 0},
    {"axi P pipe uniform", GEOM_AXI, {32, 64, 1}, {AX, NS, PER}, VAR_P, STRETCH_UNIFORM, 0},

    {"3d P periodic", GEOM_3D, {16, 16, 16}, {PER, PER, PER}, VAR_P, STRETCH_UNIFORM, 0},
    {"3d P walls x,y (stretched)", GEOM_3D, {16, 16, 16}, {NS, FS, PER}, VAR_P, STRETCH_TANH_BOTH, 0},
    {"3d P closed box", GEOM_3D, {16, 16, 16}, {NS, NS, NS}, VAR_P, STRETCH_UNIFORM, 0},
    {"3d U noslip x,z (stretched)", GEOM_3D, {16, 16, 16}, {NS, PER, NS}, VAR_U, STRETCH_TANH_BOTH, 0},
    {"3d V noslip/freeslip mix", GEOM_3D, {16, 16, 16}, {NF, NS, FS}, VAR_V, STRETCH_UNIFORM, 0},
    {"3d W walls, Helmholtz", GEOM_3D, {16, 16, 16}, {NS, NF, NS}, VAR_W, STRETCH_TANH_BOTH, 1e3},
    {"3d U periodic", GEOM_3D, {16, 16, 16}, {PER, PER, PER}, VAR_U, STRETCH_UNIFORM, 0},
    {"2d P cavity (stretched)", GEOM_2D, {32, 32, 1}, {NS, NS, PER}, VAR_P, STRETCH_TANH_BOTH, 0},
    {"2d U cavity", GEOM_2D, {32, 32, 1}, {NS, NS, PER}, VAR_U, STRETCH_TANH_BOTH, 0},
    {"2d V channel, Helmholtz", GEOM_2D, {32, 32, 1}, {NF, PER, PER}, VAR_V, STRETCH_UNIFORM, 10},
    {"axi P pipe (stretched)", GEOM_AXI, {32, 64, 1}, {AX, NS, PER}, VAR_P, STRETCH_TANH_HIGH, 0},
    {"axi U pipe", GEOM_AXI, {32, 64, 1}, {AX, PER, PER}, VAR_U, STRETCH_TANH_HIGH, 0},
    {"axi V closed (stretched)", GEOM_AXI, {32, 64, 1}, {AXF, NS, PER}, VAR_V, STRETCH_TANH_HIGH, 0},
    {"axi U closed, Helmholtz", GEOM_AXI, {32, 64, 1}, {AX, FS, PER}, VAR_U, STRETCH_UNIFORM, 50},
};
#define NCASES (sizeof cases / sizeof cases[0])

static void test_explore(void **state)
{
    for (size_t i = 0; i < NCASES; i++) {
        mgr_t a = run_case(&cases[i], 1, MPI_COMM_WORLD), b = run_case(&cases[i], 2, MPI_COMM_WORLD),
              c = run_case(&cases[i], 4, MPI_COMM_WORLD);
        msg("%-30s cycles %2d %2d %2d  factor %.3f %.3f %.3f  res %.1e  err %.2e %.2e %.2e  order %.2f %.2f  t %.3f\n",
            cases[i].name, a.cycles, b.cycles, c.cycles, a.factor, b.factor, c.factor, c.res, a.err, b.err, c.err,
            conv_order(a.err, b.err, 2), conv_order(b.err, c.err, 2), c.time);
    }
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_explore),
    };
    TEST_MPI_RUN("poisson_mg", tests);
}
