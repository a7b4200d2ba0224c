/* test_porenet_perm.c — the pore network on fixed packings (permeameters):
 * exact identities (mass conservation, force balance, partition of the void
 * and of the solid surface), the simple cubic array against Zick & Homsy and
 * the reference prototype, random packings against the prototype on the same
 * packings (catalano_pfv.md §5.4 tests 1, 4, 11 and §6); the YADE wall
 * model against YADE's FlowEngine on the same packing.
 * RANKS: 1 2
 */
#include <stdlib.h>
#include <string.h>

#include "porenet.h"
#include "porenet_packings.h"
#include "testutil.h"
#include "util.h"

#ifndef PN_DATA
#define PN_DATA "tests/data/porenet"
#endif

typedef struct {
    pn_tri_t tri;
    pn_net_t net;
    pn_solver_t *sol;
    double *p, *f, *fp, *fv;
    int n;
} pn_case_t;

static void case_build_model(pn_case_t *c, const pn_domain_t *dom, int n, const double *x, const double *r,
                             double margin, pn_solver_kind_t kind, pn_wall_model_t wall_model)
{
    char err[512] = "";
    pn_params_t prm = {0.5, 1.0, wall_model};
    memset(c, 0, sizeof *c);
    c->n = n;
    int rc = pn_triangulate(dom, n, x, r, margin, &c->tri, err, sizeof err);
    if (rc) fprintf(stderr, "triangulate: %s\n", err);
    assert_int_equal(rc, 0);
    rc = pn_network_build(dom, &prm, &c->tri, x, r, n, &c->net, err, sizeof err);
    if (rc) fprintf(stderr, "network: %s\n", err);
    assert_int_equal(rc, 0);
    c->sol = pn_solver_create(dom, &c->net, kind, 1e-12, err, sizeof err);
    if (!c->sol) fprintf(stderr, "solver: %s\n", err);
    assert_non_null(c->sol);
    c->p = malloc((size_t)c->net.npore * sizeof *c->p);
    assert_int_equal(pn_solve(c->sol, dom, &c->net, NULL, c->p), 0);
    c->f = malloc(3 * (size_t)n * sizeof *c->f);
    c->fp = malloc(3 * (size_t)n * sizeof *c->fp);
    c->fv = malloc(3 * (size_t)n * sizeof *c->fv);
    pn_forces(dom, &c->tri, &c->net, c->p, n, c->f, c->fp, c->fv);
}

static void case_build(pn_case_t *c, const pn_domain_t *dom, int n, const double *x, const double *r, double margin,
                       pn_solver_kind_t kind)
{
    case_build_model(c, dom, n, x, r, margin, kind, PN_WALL_MIRROR);
}

static void case_free(pn_case_t *c)
{
    pn_solver_free(c->sol);
    pn_network_free(&c->net);
    pn_tri_free(&c->tri);
    free(c->p);
    free(c->f);
    free(c->fp);
    free(c->fv);
}

static double mean_diameter(int n, const double *r)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += 2 * r[i];
    return s / n;
}

/* Periodic permeability κ_z = μ ⟨U_z⟩/(−∂p/∂z) with ∂p/∂z = −1, μ = 1. */
static double periodic_kappa(const double *x, const double *r, int n, double L, double margin, double *fsum_rel)
{
    pn_domain_t dom = pk_domain(L, 1, 1, 1);
    dom.grad[2] = -1.0;
    pn_case_t c;
    case_build(&c, &dom, n, x, r, margin, PN_SOLVER_CHOLMOD);
    double U[3];
    pn_mean_velocity(&dom, &c.net, c.p, U);
    /* Σ forces = −V ∇p exactly (forces.c): here V e_z */
    double fs[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) fs[a] += c.f[3 * i + a];
    double V = L * L * L;
    if (fsum_rel) *fsum_rel = fmax(fabs(fs[2] / V - 1), fmax(fabs(fs[0]), fabs(fs[1])) / V);
    case_free(&c);
    return U[2];
}

/* ---- simple cubic array ---------------------------------------------------- */

/* Touching spheres, exactly co-spherical cubes (merged into one pore each) and
 * two jittered versions (two different splits of every cube): κ/d² within 5 %
 * of the prototype's 2.44e-3 and 10 % of Zick & Homsy's 2.52e-3 (§5.4.11; the
 * model is not exact Stokes, the 10 % is the note's target); the splits agree
 * within 1 % (§5.4.2). */
static void test_cubic_periodic(void **state)
{
    (void)state;
    int m = 4, n = m * m * m;
    double x[3 * 64], r[64];
    double kap[3];
    const double jit[3] = {0, 1e-3, 1e-5};
    for (int s = 0; s < 3; s++) {
        pk_cubic(m, 0.999999, jit[s], 7 + s, x, r);
        double frel;
        kap[s] = periodic_kappa(x, r, n, 2.0 * m, 0, &frel) / (4 * 0.999999 * 0.999999);
        printf("  SC periodic, jitter %g: kappa/d^2 = %.6e  (force balance rel. error %.2e)\n", jit[s], kap[s], frel);
        assert_true(frel < 1e-10);
        assert_true(fabs(kap[s] / 2.44e-3 - 1) < 0.05);
        assert_true(fabs(kap[s] / 2.52e-3 - 1) < 0.10);
    }
    assert_true(fabs(kap[1] / kap[0] - 1) < 0.01);
    assert_true(fabs(kap[2] / kap[0] - 1) < 0.01);
}

/* Bounded permeameter along z: slip walls on x and y, p = 1 at z = 0, 0 at
 * z = L.  Returns κ = μ Q L/(ΔP S) from the inlet flux; checks the exact
 * identities on the way. */
typedef struct {
    double kappa, qrel, frel, fbal, area_rel, void_part, surf_part, kappa_pcg;
    int npore, nthroat;
} perm_result_t;

static perm_result_t walled_permeameter(const double *x, const double *r, int n, double L, int noslip)
{
    pn_domain_t dom = pk_domain(L, 0, 0, 0);
    dom.bc[4] = dom.bc[5] = PN_BC_PRESSURE;
    dom.bc_value[4] = 1.0;
    dom.bc_value[5] = 0.0;
    for (int f = 0; f < 4; f++) dom.noslip[f] = noslip;
    perm_result_t res;
    pn_case_t c;
    case_build(&c, &dom, n, x, r, 0, PN_SOLVER_CHOLMOD);
    double q[6], F[6][3];
    pn_face_fluxes(&dom, &c.net, c.p, q);
    pn_face_forces(&dom, &c.net, c.p, F);
    double S = L * L, dP = 1.0;
    res.kappa = q[4] * L / (dP * S);
    res.qrel = fabs(q[4] + q[5]) / fabs(q[4]);
    double fs[3] = {0, 0, 0}, fw[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) fs[a] += c.f[3 * i + a];
    for (int f = 0; f < 6; f++)
        for (int a = 0; a < 3; a++) fw[a] += F[f][a];
    /* spheres + lateral walls along the flow: ΔP S */
    double fz = fs[2] + F[0][2] + F[1][2] + F[2][2] + F[3][2];
    res.frel = fabs(fz / (dP * S) - 1);
    /* spheres + every face (the reservoirs too): 0 in every component */
    res.fbal = fmax(fabs(fs[0] + fw[0]), fmax(fabs(fs[1] + fw[1]), fabs(fs[2] + fw[2]))) / (dP * S);
    double ain = 0;
    for (int i = 0; i < c.net.npore; i++)
        if (c.net.dirichlet[i] == 4) ain += fabs(c.net.sect[3 * i + 2]);
    res.area_rel = fabs(ain / S - 1);
    res.void_part = c.net.void_sum / (c.net.box_volume - c.net.solid_volume);
    double surf = 0;
    for (int i = 0; i < n; i++) surf += 4 * M_PI * r[i] * r[i];
    res.surf_part = c.net.solid_area_sum / surf;
    res.npore = c.net.npore;
    res.nthroat = c.net.nthroat;
    case_free(&c);
    case_build(&c, &dom, n, x, r, 0, PN_SOLVER_PCG);
    pn_face_fluxes(&dom, &c.net, c.p, q);
    res.kappa_pcg = q[4] * L / (dP * S);
    case_free(&c);
    return res;
}

/* The cubic array between slip walls at half a spacing from the spheres: the
 * mirror images rebuild the periodic lattice, so κ must be the periodic one
 * (to round-off: the pores on the walls are halves of the same cubes). */
static void test_cubic_walled(void **state)
{
    (void)state;
    double x[3 * 64], r[64];
    int n = pk_cubic(4, 0.999999, 0, 1, x, r);
    double kp = periodic_kappa(x, r, n, 8.0, 0, NULL);
    perm_result_t w = walled_permeameter(x, r, n, 8.0, 0);
    printf("  SC walled: kappa/d^2 = %.10e, periodic %.10e; |Qin+Qout|/Qin = %.1e, force %.1e, balance %.1e\n",
           w.kappa / 4, kp / 4, w.qrel, w.frel, w.fbal);
    assert_true(fabs(w.kappa / kp - 1) < 1e-10);
    assert_true(w.qrel < 1e-10);
    assert_true(w.frel < 1e-8);
}

/* A random packing of 300 spheres (radii ±20 %, φ = 0.55) relaxed in a box
 * with walls: the identities of §5.4.1 with the direct solver — Q_in = Q_out to
 * 1e-10 (the residual of the back-substitution, ~1e-15 × condition number),
 * Σ forces on spheres and lateral walls = ΔP S along the flow to 1e-8, the
 * full balance with the reservoir faces, the inlet sections tiling the inlet;
 * the partition of the void and of the solid surface by the throats within
 * 2.5 % (the throat volumes are unsigned, as in the thesis and the prototype,
 * so a power centre outside its tetrahedron counts some volume twice or not at
 * all: note §6 measured 0.992–0.997 / 1.002–1.007 on periodic packings at
 * φ = 0.55–0.60, which this code reproduces; this looser packing with walls
 * measures 0.981 / 1.015); PCG at tol 1e-12 agreeing with CHOLMOD to 1e-9. */
static void test_random_walled_identities(void **state)
{
    (void)state;
    int n = 300;
    double *x = malloc(3 * (size_t)n * sizeof *x), *r = malloc((size_t)n * sizeof *r);
    double L = pk_random_walled(n, 0.55, 0.2, 12345, x, r);
    for (int ns = 0; ns < 2; ns++) {
        perm_result_t w = walled_permeameter(x, r, n, L, ns);
        double d = mean_diameter(n, r);
        printf("  random walled (%s): %d pores (%.2f/sphere), %d throats; kappa/d^2 = %.6e (PCG %.6e)\n"
               "    |Qin+Qout|/Qin = %.1e, force %.1e, balance %.1e, inlet area %.1e, void %.5f, surface %.5f\n",
               ns ? "no-slip" : "slip", w.npore, (double)w.npore / n, w.nthroat, w.kappa / (d * d),
               w.kappa_pcg / (d * d), w.qrel, w.frel, w.fbal, w.area_rel, w.void_part, w.surf_part);
        assert_true(w.qrel < 1e-10);
        assert_true(w.frel < 1e-8);
        assert_true(w.fbal < 1e-8);
        assert_true(w.area_rel < 1e-10);
        assert_true(fabs(w.void_part - 1) < 0.025);
        assert_true(fabs(w.surf_part - 1) < 0.025);
        assert_true(fabs(w.kappa_pcg / w.kappa - 1) < 1e-9);
    }
    free(x);
    free(r);
}

/* The prototype's packings (catalano_pfv.md §6 table, written by
 * scripts/porenet_proto_packings.py): the same algorithm on the same packing
 * must give the same κ within 3 % (§5.4.4). */
static void test_prototype_packings(void **state)
{
    (void)state;
    const char *names[] = {"proto_N1000_phi0.55_pd0.05.txt", "proto_N1000_phi0.58_pd0.05.txt",
                           "proto_N1000_phi0.60_pd0.05.txt", "proto_N1000_phi0.62_pd0.05.txt",
                           "proto_N200_phi0.60_pd0.05.txt"};
    /* The table's sixth packing (N = 500, r_min/r_max = 0.5, file
     * proto_N500_phi0.60_pd0.5.txt) is not asserted: the prototype stops on
     * it here (singular power-centre solve of a flat cell), so there is no
     * re-run value on the same packing; this code gives 1.644e-3 against the
     * table's 1.316e-3 (docs/validation.md, open). */
    int nmax = 1000;
    double *x = malloc(3 * (size_t)nmax * sizeof *x), *r = malloc((size_t)nmax * sizeof *r);
    for (size_t c = 0; c < sizeof names / sizeof names[0]; c++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", PN_DATA, names[c]);
        double L = 0, kproto = 0;
        int n = pk_read_proto(path, nmax, x, r, &L, &kproto);
        if (n <= 0) fprintf(stderr, "cannot read %s\n", path);
        assert_true(n > 0);
        double frel;
        double d = mean_diameter(n, r);
        double k = periodic_kappa(x, r, n, L, 0, &frel) / (d * d);
        printf("  %s: kappa/d^2 = %.6e, prototype %.6e, ratio %.5f; force balance %.1e\n", names[c], k, kproto,
               k / kproto, frel);
        assert_true(fabs(k / kproto - 1) < 0.03);
        assert_true(frel < 1e-10);
    }
    free(x);
    free(r);
}

/* porenet.wall_throats = yade against YADE 2023.02a's FlowEngine (Debian
 * package, bench/porenet_yade.py) on the permeameter case's packing (300
 * spheres, radii 1 ± 20 %, φ = 0.55, walled box): p = 1 / 0 on z = 0 / L,
 * slip lateral walls, μ = 1, boundaries on the box faces, conductance
 * clamping off (clampKValues = False; with YADE's default clamping 8.63529e-3).
 * YADE measured κ = 8.64250e-3 (the mirror model gives 1.0897e-2: the
 * wall-plane throats differ, docs/theory.md).  Interior throats use the same
 * formula in both codes; the residual differences are YADE's approximations of
 * the walls by spheres of radius 5e4 L (power centres off the plane by
 * ~r²/(5e4 L), directions to the far centres off by ~1e-5 rad): measured
 * 2e-5 relative here and on N = 5000 (bench), asserted at 1e-3. */
static void test_yade_walls(void **state)
{
    (void)state;
    const int nmax = 300;
    double *x = malloc(3 * (size_t)nmax * sizeof *x), *r = malloc((size_t)nmax * sizeof *r);
    double L = 0, unused = 0;
    int n = pk_read_proto("cases/permeameter/packing_walled_300.txt", nmax, x, r, &L, &unused);
    assert_int_equal(n, 300);
    pn_domain_t dom = pk_domain(L, 0, 0, 0);
    dom.bc[4] = dom.bc[5] = PN_BC_PRESSURE;
    dom.bc_value[4] = 1;
    double kappa[2];
    for (int wm = 0; wm < 2; wm++) {
        pn_case_t c;
        case_build_model(&c, &dom, n, x, r, 0, PN_SOLVER_CHOLMOD, wm ? PN_WALL_YADE : PN_WALL_MIRROR);
        double q[6];
        pn_face_fluxes(&dom, &c.net, c.p, q);
        kappa[wm] = 0.5 * (q[4] - q[5]) * L / (1.0 * L * L); /* μ Q L/(ΔP S), μ = ΔP = 1 */
        case_free(&c);
    }
    const double kappa_yade = 8.6424989127e-3;
    printf("  permeameter packing: kappa = %.6e (wall_throats = yade), YADE FlowEngine %.6e, ratio %.6f; "
           "mirror %.6e (ratio %.4f)\n",
           kappa[1], kappa_yade, kappa[1] / kappa_yade, kappa[0], kappa[0] / kappa_yade);
    assert_true(fabs(kappa[1] / kappa_yade - 1) < 1e-3);
    free(x);
    free(r);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cubic_periodic),
        cmocka_unit_test(test_cubic_walled),
        cmocka_unit_test(test_random_walled_identities),
        cmocka_unit_test(test_prototype_packings),
        cmocka_unit_test(test_yade_walls),
    };
    TEST_MPI_RUN("porenet_perm", tests);
}
