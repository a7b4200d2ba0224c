/* test_avalanche.c — the measurements of a flow down an inclined plane
 * (src/coupling/avalanche.c, docs/theory.md §10).
 * RANKS: 1 2
 *
 * Exact results used:
 *  - A simple cubic lattice of touching spheres (diameter D, n_l layers, the
 *    first centred at D/2 above the bed plane): each sphere is cut exactly by
 *    the profile slabs, so the solid fraction summed over the slabs is the
 *    total solid volume, and its mean over any whole number of periods D
 *    inside the lattice is π/6.  The D-averaged solid fraction falls linearly
 *    from π/6 to 0 between n_l D − D/2 and n_l D + D/2, so the bed height
 *    (half the plateau) is n_l D, and the compacity between D/2 and
 *    h − D/2 (whole layers, centre to centre) is π/6.
 *  - The flow rate of grains moving at u_x = a + b z is Q = Σ V_p u_p / L,
 *    and the mean particle Stokes number ρ_p/(9η) ⟨|u| D⟩.
 *  - A fluid in simple shear u = γ z (no spheres): the (1 − α)-weighted mean
 *    of the slab of one cell is γ z_c, the fluctuations about it are zero,
 *    the solid fraction seen by the fluid is 0 (fluid fraction 1), and the
 *    viscous stress ν d⟨u⟩/dz is ν γ (the centred difference of a linear
 *    profile is exact); on 1 and 2 ranks.
 *  - The averaging window: steps whose middle lies outside it add nothing;
 *    the means are time averages weighted by the steps.
 */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "avalanche.h"
#include "dem.h"
#include "fluidtest.h"
#include "modules.h"
#include "testutil.h"

static const double D = 0.004, RHO_P = 2500, ETA = 0.1, RHO = 1000;
enum { NL = 4, NS = 4 }; /* layers, spheres per side */

static dem_t *lattice(double a, double b)
{
    char text[1024];
    snprintf(text, sizeof text,
             "[domain]\nlength = %.17g %.17g %.17g\n[boundary]\nz_lo = noslip\nz_hi = noslip\n"
             "[contact]\nrestitution = 0.5\ncontact_time = 1e-4\nfriction = 0.3\n[dem]\ngravity = 0 0 -9.81\n",
             NS * D, NS * D, 10 * D);
    cfg_t *cfg = cfg_load_string("test.ini", text, 0, NULL);
    assert_non_null(cfg);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    for (int k = 0; k < NL; k++)
        for (int j = 0; j < NS; j++)
            for (int i = 0; i < NS; i++) {
                const double z = (k + 0.5) * D;
                const double x[3] = {(i + 0.5) * D, (j + 0.5) * D, z}, v[3] = {a + b * z, 0, 0};
                dem_add_particle(d, x, v, 0.5 * D, RHO_P, 0);
            }
    assert_int_equal(dem_advance(d, 0.0), DEM_OK); /* lists and forces of the initial state */
    return d;
}

static void init(avalanche_t *av, const dem_t *d, double t1, double t2)
{
    const double L[3] = {NS * D, NS * D, 10 * D}, g[3] = {9.81 * sin(0.4), 0, -9.81 * cos(0.4)};
    avalanche_init(av, d, 2, 0.0, 10 * D, L, g, RHO, ETA, 0.0, t1, t2);
}

static void test_lattice(void **state)
{
    (void)state;
    const double a = 0.01, b = 3.0;
    dem_t *d = lattice(a, b);
    avalanche_t av;
    init(&av, d, 0.0, 1.0);
    assert_int_equal(av.as, 0);
    assert_true(fabs(av.sin_theta - sin(0.4)) < 1e-14);
    assert_true(fabs(av.D - D) < 1e-15);
    avalanche_sample_grains(&av, d, NULL, NULL, 0.5, 0.5);
    const double Vp = M_PI * D * D * D / 6, N = NL * NS * NS, L = NS * D;
    /* slab volumes sum to the solid volume; π/6 over whole periods */
    double vsum = 0, vlat = 0;
    for (int k = 0; k < av.nbin; k++) {
        vsum += av.grain[4 * k];
        if (k >= 5 && k < 5 * (NL - 1)) vlat += av.grain[4 * k];
    }
    assert_true(fabs(vsum / 0.5 - N * Vp) < 1e-12 * N * Vp);
    assert_true(fabs(vlat / (0.5 * L * L * (NL - 2) * D) - M_PI / 6) < 1e-12);
    /* flow rate, height, compacity, mean velocity, mean particle Stokes number */
    double Q = 0, st = 0;
    for (int k = 0; k < NL; k++) {
        const double u = a + b * (k + 0.5) * D;
        Q += NS * NS * Vp * u / L;
        st += NS * NS * fabs(u) * D;
    }
    st *= RHO_P / (9 * ETA * N);
    assert_true(fabs(av.now[AV_Q] - Q) < 1e-13 * Q);
    assert_true(fabs(av.now[AV_H] - NL * D) < 1e-12 * D);
    assert_true(fabs(av.now[AV_PHI] - M_PI / 6) < 1e-12);
    assert_true(fabs(av.now[AV_U] - Q * L / (N * Vp)) < 1e-13 * Q * L / (N * Vp));
    assert_true(fabs(av.now[AV_ST_MEAN] - st) < 1e-13 * st);
    /* the profile of the grains' velocity: the volume-weighted mean in the slab of a layer's centre */
    const int kc = 5 * 1 + 2; /* slab [1.4 D, 1.6 D] around the centre of layer 1 */
    assert_true(fabs(av.grain[4 * kc + 1] / av.grain[4 * kc] - (a + b * 1.5 * D)) < 1e-13);
    /* the flow time V_g / Q̄ and the window: a step outside adds nothing, means weight by the steps */
    /* V_g = L W h: the time the grains take to flow through the box, L/(phi U) */
    assert_true(fabs(avalanche_flow_time(&av) - L * L * NL * D / Q) < 1e-12 * avalanche_flow_time(&av));
    assert_true(fabs(avalanche_flow_time(&av) - L / (M_PI / 6 * av.now[AV_U])) < 1e-12 * avalanche_flow_time(&av));
    avalanche_sample_grains(&av, d, NULL, NULL, 2.0, 0.5); /* middle 1.75: outside [0, 1] */
    assert_true(fabs(av.tw - 0.5) < 1e-15);
    avalanche_free(&av);
    dem_free(d);
}

static void test_fluid_shear(void **state)
{
    (void)state;
    const int n[3] = {8, 6, 10};
    const double L[3] = {NS * D, NS * D, 10 * D}, gam = 7.0, nu = ETA / RHO;
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    bc.type[2][0] = bc.type[2][1] = BC_FREESLIP;
    grid_t *g = grid_create(GEOM_3D, n, L, NULL, &bc, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    fluid_params_t prm = ft_params(nu, 0);
    fluid_t *f = fluid_create(g, &prm);
    for (int i = -1; i <= g->nxl; i++)
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -g->gz; k < g->n[2] + g->gz; k++) f->u[0][G_IDX(g, i, j, k)] = gam * grid_zc(g, k);
    dem_t *d = lattice(0, 0);
    avalanche_t av;
    const double Lw[3] = {L[0], L[1], L[2]}, gv[3] = {9.81 * sin(0.4), 0, -9.81 * cos(0.4)};
    avalanche_init(&av, d, 2, 0.0, L[2], Lw, gv, RHO, ETA, D, 0.0, 1.0); /* one cell per slab */
    avalanche_sample_fluid(&av, f, NULL, 0.25, 0.25);
    avalanche_sample_fluid(&av, f, NULL, 0.75, 0.25);
    assert_int_equal(av.nbin, 10);
    double worst = 0;
    for (int k = 0; k < av.nbin; k++) {
        const double *s = av.fluid + 10 * k;
        const double W = s[0], Uf = s[1] / W, zc = (k + 0.5) * D;
        worst = fmax(worst, fabs(Uf - gam * zc) / (gam * D));
        worst = fmax(worst, fabs(s[4] / W - Uf * Uf) / (gam * gam * D * D)); /* <u'u'> */
        worst = fmax(worst, fabs(W / (0.5 * L[0] * L[1] * D) - 1.0));        /* fluid fraction 1 */
        worst = fmax(worst, fabs(s[2] / W) + fabs(s[3] / W));
    }
    assert_true(worst < 1e-12);
    /* the viscous stress column of the profiles */
    char path[] = "/tmp/ibmdem_test_avalanche_XXXXXX";
    int fd = -1;
    if (mpi_rank() == 0) fd = mkstemp(path);
    MPI_Bcast(path, sizeof path, MPI_CHAR, 0, MPI_COMM_WORLD);
    int bad = 0;
    if (mpi_rank() == 0) {
        bad = fd < 0 || avalanche_write_profiles(&av, path) != 0;
        FILE *in = bad ? NULL : fopen(path, "r");
        char line[1024];
        int rows = 0;
        while (in && fgets(line, sizeof line, in)) {
            if (line[0] == '#' || line[0] == 'z') continue;
            double v[17];
            char *p = line;
            for (int c = 0; c < 17; c++) {
                v[c] = strtod(p, &p);
                if (*p == ',') p++;
            }
            if (fabs(v[16] - nu * gam) > 1e-12 * nu * gam) bad = 1;
            rows++;
        }
        if (in) fclose(in);
        if (rows != 10) bad = 1;
        if (fd >= 0) close(fd);
        unlink(path);
    }
    MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
    assert_int_equal(bad, 0);
    avalanche_free(&av);
    dem_free(d);
    fluid_free(f);
    grid_free(g);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lattice),
        cmocka_unit_test(test_fluid_shear),
    };
    TEST_MPI_RUN("avalanche", tests);
}
