/* test_ibm_alpha.c — the smoothed solid fraction (decision 1) and its node
 * lists: the profile, the sphere volume it encloses (convergence order
 * measured), periodic images, walls, overlapping spheres and the slab
 * decomposition (the box lists against a brute-force evaluation at every
 * node), axisymmetric and 2-D geometry, and a cost independent of the grid
 * size.
 * RANKS: 1 2
 */
#include "../src/ibm/ibm_internal.h" /* the node lists: ibm_build_nodes and its separate passes */
#include "ibmtest.h"
#include "modules.h"
#include "testutil.h"

/* ---- the profile ------------------------------------------------------------------ */

static void test_profile(void **state)
{
    (void)state;
    double h = 0.1, band = ibm_band_halfwidth();
    double nx[3] = {1, 0, 0}, nd[3] = {1 / sqrt(3.0), 1 / sqrt(3.0), 1 / sqrt(3.0)};
    /* σ = 0.065(1 − λ²) + 0.39 > 0 for every normal (λ ≤ √3): with the
     * printed 0.039 it would be negative for λ > 1.265 */
    for (double lam = 1.0; lam <= sqrt(3.0) + 1e-12; lam += 0.01) assert_true(0.065 * (1 - lam * lam) + 0.39 > 0.25);
    /* α = ½ on the surface (the cut is symmetric) */
    assert_float_equal(ibm_alpha(0.0, nx, h), 0.5, 1e-15);
    assert_float_equal(ibm_alpha(0.0, nd, h), 0.5, 1e-15);
    /* along x (λ = 1, σλΔ = 0.39 √2 h) the tanh profile is 0.01 at
     * d = atanh(0.98) 0.39 √2 h = 1.267 h (reference notes §1.7 [derived]),
     * i.e. (0.01 − ε)/(1 − 2ε) after the cut */
    double d01 = atanh(0.98) * 0.39 * M_SQRT2 * h;
    assert_float_equal(ibm_alpha(d01, nx, h), (0.01 - IBM_ALPHA_CUT) / (1 - 2 * IBM_ALPHA_CUT), 1e-12);
    assert_float_equal(ibm_alpha(-d01, nx, h), (0.99 - IBM_ALPHA_CUT) / (1 - 2 * IBM_ALPHA_CUT), 1e-12);
    /* monotone, exactly 0 and 1 beyond the band, continuous at its edges
     * (no jump when a node enters the band) */
    double prev = 1.0;
    for (double d = -1.2 * band * h; d <= 1.2 * band * h; d += 1e-4 * h) {
        double a = ibm_alpha(d, nd, h);
        assert_true(a <= prev + 1e-15);
        assert_true(prev - a < 1e-3); /* steepest slope 1/(2σλΔ) ≈ 0.9/h: < 1e-3 per 1e-4 h */
        prev = a;
    }
    assert_true(ibm_alpha(band * h, nx, h) == 0.0 && ibm_alpha(band * h, nd, h) == 0.0);
    assert_true(ibm_alpha(-band * h, nx, h) == 1.0 && ibm_alpha(-band * h, nd, h) == 1.0);
    /* nearly isotropic thickness: σλ = 0.39 (λ = 1), 0.46 (√2), 0.45 (√3) */
    double n2[3] = {M_SQRT1_2, M_SQRT1_2, 0};
    double w1 = atanh(1 - 2 * ibm_alpha(0.3 * h, nx, h)), w2 = atanh(1 - 2 * ibm_alpha(0.3 * h, n2, h));
    assert_float_equal(w1 / w2, (0.065 * (1 - 2) + 0.39) * M_SQRT2 / 0.39, 0.02);
}

/* ---- the enclosed volume ----------------------------------------------------------- */

/* Σ α V over the unknowns of component c, all ranks. */
static double alpha_volume(const ibm_t *ibm, int c)
{
    const grid_t *g = ibm->g;
    double *a = field_alloc(g), s = 0.0;
    ibm_solid_fraction_face(ibm, c, a);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) s += a[G_IDX(g, i, j, k)] * fluid_cell_volume(ibm->f, c, i);
    free(a);
    s = grid_sum(g, s);
    return g->geom == GEOM_AXI ? 2 * M_PI * s : s;
}

/* A sphere of diameter 1 at D/Δx = dpd, off the grid's symmetry points, in
 * the geometry given; returns Σ α V / V_p − 1 for component c. */
static double volume_error_with(const char *geom, int dpd, int c, const char *extra)
{
    int n = 2 * dpd;
    double L = 2.0;
    char text[1024];
    if (!strcmp(geom, "axisymmetric"))
        snprintf(text, sizeof text,
                 "[domain]\ngeometry = axisymmetric\nnx = %d\nny = %d\nlength = %g %g 1\n"
                 "[boundary]\nx_lo = axis\nx_hi = freeslip\n[fluid]\nnu = 1\n"
                 "[ibm]\n%s\nsphere1 = fixed center 0 1.0123 0 diameter 1\n",
                 n, 2 * n, L, 2 * L, extra);
    else
        snprintf(text, sizeof text,
                 "[domain]\ngeometry = %s\nnx = %d\nny = %d\nnz = %d\nlength = %g %g %g\n[fluid]\nnu = 1\n"
                 "[ibm]\n%s\nsphere1 = fixed center 1.0123 0.9871 1.0311 diameter 1\n",
                 geom, n, n, strcmp(geom, "3d") ? 1 : n, L, L, L, extra);
    it_case_t tc = it_from_case(text);
    double V = ibm_volume(tc.ibm, 0), e = alpha_volume(tc.ibm, c) / V - 1.0;
    it_free(&tc);
    return e;
}

static double volume_error(const char *geom, int dpd, int c) { return volume_error_with(geom, dpd, c, ""); }

/* band_width = s scales the profile's width w by s: the volume excess
 * (π² w²/(4R²) above) by about s², a quarter at s = 0.5 — measured 0.21,
 * 0.21, 0.33 for u, v, w at D/Δx = 16 in 3-D, where the profile, 0.3 cell
 * wide, is sampled by the nodes with an error (±1e-3 of the volume) of the
 * size of the excess itself: bounds 0.15–0.4, and the excess positive.
 * (Not axisymmetric: there the discrete 2πr weights of the nodes add an
 * excess of their own, which the band does not set: ratio 0.51.) */
static void test_volume_band_width(void **state)
{
    (void)state;
    for (int c = 0; c < 3; c++) {
        double e1 = volume_error("3d", 16, c), e05 = volume_error_with("3d", 16, c, "band_width = 0.5");
        print_message("  3-D, component %c: volume excess %.4e (band_width 1), %.4e (0.5): ratio %.3f\n", "uvw"[c], e1,
                      e05, e05 / e1);
        assert_true(e05 > 0 && e05 / e1 > 0.15 && e05 / e1 < 0.4);
    }
}

/* The smoothed indicator encloses more than the sphere: integrating
 * α − H(−d) over shells 4π(R + d)² dd, ΔV/V = (6/R²) ∫ (α − H) d dd + O(w³),
 * and ∫ (α − H) d dd = π² w²/24 for a tanh profile ½(1 − tanh(d/w))
 * (∫₀^∞ x/(e^{2x} + 1) dx = π²/48), so ΔV/V ≈ π² w²/(4R²): second order in
 * h.  (2-D discs, shells 2π(R + d) dd: ΔA/A ≈ π² w²/(12R²).)  The order is measured between
 * D/Δx = 8 and 16; the magnitude is checked against the formula with the
 * direction average w ≈ 0.44 √2 h within 30 %. */
static void test_volume_3d(void **state)
{
    (void)state;
    for (int c = 0; c < 3; c++) {
        double e8 = volume_error("3d", 8, c), e16 = volume_error("3d", 16, c);
        double w = 0.44 * M_SQRT2 / 8, est = M_PI * M_PI * w * w / (4 * 0.25);
        print_message("  3-D, component %c: volume excess %.4e (D/dx = 8), %.4e (16), order %.2f; estimate %.4e\n",
                      "uvw"[c], e8, e16, conv_order(e8, e16, 2.0), est);
        assert_true(e8 > 0 && e16 > 0);
        assert_float_equal(conv_order(e8, e16, 2.0), 2.0, 0.2);
        assert_float_equal(e8 / est, 1.0, 0.3);
    }
}

static void test_volume_axi_2d(void **state)
{
    (void)state;
    /* axisymmetric: 2π r dr dz weights; both components */
    for (int c = 0; c < 2; c++) {
        double e8 = volume_error("axisymmetric", 8, c), e16 = volume_error("axisymmetric", 16, c);
        print_message("  axisymmetric, component %c: volume excess %.4e (8), %.4e (16), order %.2f\n", "uv"[c], e8, e16,
                      conv_order(e8, e16, 2.0));
        assert_true(e8 > 0 && e16 > 0);
        assert_float_equal(conv_order(e8, e16, 2.0), 2.0, 0.25);
    }
    for (int c = 0; c < 2; c++) {
        double e8 = volume_error("2d", 8, c), e16 = volume_error("2d", 16, c);
        double w = 0.44 * M_SQRT2 / 8, est = M_PI * M_PI * w * w / (12 * 0.25);
        print_message("  2-D disc, component %c: area excess %.4e (8), %.4e (16), order %.2f; estimate %.4e\n", "uv"[c],
                      e8, e16, conv_order(e8, e16, 2.0), est);
        assert_float_equal(conv_order(e8, e16, 2.0), 2.0, 0.25);
        assert_float_equal(e8 / est, 1.0, 0.3);
    }
}

/* ---- the node lists against brute force -------------------------------------------- */

/* min(1, Σ α) at every unknown of component c from scratch: every node,
 * every sphere, every periodic image. */
static double brute_force_diff(const it_case_t *tc, int c)
{
    const grid_t *g = tc->g;
    const ibm_t *ibm = tc->ibm;
    double *a = field_alloc(g), md = 0.0;
    ibm_solid_fraction_face(ibm, c, a);
    int nu[3];
    for (int d = 0; d < 3; d++) nu[d] = g->n[d] - (c == d && !g->periodic[d] ? 1 : 0);
    int iend = nu[0] - g->ix0 < g->nxl ? nu[0] - g->ix0 : g->nxl;
    for (int i = 0; i < iend; i++)
        for (int j = 0; j < nu[1]; j++)
            for (int k = 0; k < nu[2]; k++) {
                double x[3] = {c == 0 ? g->xf[i] : g->xc[i], c == 1 ? grid_yf(g, j) : grid_yc(g, j),
                               g->dim == 3 ? (c == 2 ? grid_zf(g, k) : grid_zc(g, k)) : 0.0};
                double hx = c == 0 ? g->dxc[i] : g->dxf[i];
                double h = g->dim == 3 ? cbrt(hx * g->dy * g->dz) : sqrt(hx * g->dy), sum = 0.0;
                for (int p = 0; p < ibm->n; p++)
                    for (int ix = -1; ix <= 1; ix++)
                        for (int iy = -1; iy <= 1; iy++)
                            for (int iz = -1; iz <= 1; iz++) {
                                int im[3] = {ix, iy, iz};
                                double r[3], rr = 0.0;
                                int skip = 0;
                                for (int d = 0; d < 3; d++) {
                                    if (im[d] && (!g->periodic[d] || d >= g->dim)) skip = 1;
                                    r[d] = d < g->dim ? x[d] + im[d] * g->L[d] - ibm->s[p].x[d] : 0.0;
                                    rr += r[d] * r[d];
                                }
                                if (skip) continue;
                                rr = sqrt(rr);
                                double n[3] = {r[0] / rr, r[1] / rr, r[2] / rr};
                                sum += ibm_alpha(rr - ibm->s[p].radius, n, h);
                            }
                md = fmax(md, fabs(fmin(sum, 1.0) - a[G_IDX(g, i, j, k)]));
            }
    free(a);
    return grid_max(g, md);
}

static void check_lists(const char *text, const char *what)
{
    it_case_t tc = it_from_case(text);
    for (int c = 0; c < tc.g->dim; c++) {
        double d = brute_force_diff(&tc, c);
        print_message("  %s, component %c: max |box lists - brute force| = %.1e\n", what, "uvw"[c], d);
        /* the same formula at the same points: only the node offsets may
         * differ in the last bit (image shift added before or after) */
        assert_true(d < 1e-12);
    }
    it_free(&tc);
}

static void test_lists_against_brute_force(void **state)
{
    (void)state;
    /* 3-D, periodic in x and y, no-slip walls in z, a stretched-free grid of
     * unequal spacings; spheres across the periodic x face (and the rank
     * boundary on 2 ranks), across y, two overlapping, one touching the
     * z wall, one at a corner of the periodic box */
    check_lists("[domain]\nnx = 24\nny = 20\nnz = 18\nlength = 2.4 2.0 1.5\n"
                "[boundary]\nz_lo = noslip\nz_hi = noslip\n[fluid]\nnu = 1\n"
                "[ibm]\nsphere1 = fixed center 0.05 1.0 0.7 radius 0.3\n"
                "sphere2 = fixed center 1.2 1.93 0.75 radius 0.25\n"
                "sphere3 = fixed center 1.1 0.6 0.5 radius 0.2\n"
                "sphere4 = fixed center 1.35 0.75 0.55 radius 0.22\n"
                "sphere5 = fixed center 1.7 0.4 0.12 radius 0.18\n"
                "sphere6 = fixed center 2.38 0.02 1.0 radius 0.2\n",
                "3-D periodic/walls/overlap");
    /* 2-D discs, periodic x, walls in y */
    check_lists("[domain]\ngeometry = 2d\nnx = 32\nny = 24\nlength = 2 1.5 1\n"
                "[boundary]\ny_lo = noslip\ny_hi = freeslip\n[fluid]\nnu = 1\n"
                "[ibm]\nsphere1 = fixed center 1.97 0.7 0 radius 0.3\nsphere2 = fixed center 1.0 0.1 0 radius 0.2\n",
                "2-D discs");
    /* axisymmetric, on the axis near the top wall */
    check_lists("[domain]\ngeometry = axisymmetric\nnx = 16\nny = 40\nlength = 1.6 4 1\n"
                "[boundary]\nx_lo = axis\nx_hi = freeslip\ny_lo = noslip\ny_hi = noslip\n[fluid]\nnu = 1\n"
                "[ibm]\nsphere1 = fixed center 0 3.8 0 radius 0.35\n",
                "axisymmetric");
}

/* ---- the build's sums against the separate passes ------------------------------------ */

/* The build fuses Σα (one loop over a plane's entries, with the count of
 * spheres per node), the targets and the momentum into one visit per grid
 * plane.  Each must give exactly what the plain definition gives, term by
 * term in storage order from +0: Σα run by run, the targets and the
 * momentum of the whole-list passes set_targets() and ibm_momentum() use.
 * Exact equality (memcmp): the same operations in the same order — any
 * reordering would show in the last bit somewhere among the ~10⁴ sums. */
static void check_build_sums(const char *text, const char *what)
{
    it_case_t tc = it_from_case(text);
    ibm_t *ibm = tc.ibm;
    ibm_priv_t *q = ibm_priv(ibm);
    const grid_t *g = tc.g;
    for (int c = 0; c < 3; c++)
        if (tc.f->u[c])
            for (long m = 0; m < g->nalloc; m++) tc.f->u[c][m] = sin(0.37 * m + c) + 0.1 * c; /* any field */
    size_t nsum = (size_t)ibm->n * IBM_NSUM;
    double *mom = xcalloc(nsum, sizeof *mom), *mom_pass = xcalloc(nsum, sizeof *mom_pass);
    ibm_build_nodes(ibm, mom, 1);
    long nn = q->nnodes;
    double *T = xcalloc((size_t)nn + 1, sizeof *T), *A = xcalloc((size_t)nn + 1, sizeof *A);
    int *cnt = xcalloc((size_t)nn + 1, sizeof *cnt);
    memcpy(T, q->node_target, (size_t)nn * sizeof *T);
    for (long ir = 0; ir < q->nruns; ir++)
        for (int k = 0; k < q->runs[ir].len; k++) {
            A[q->runs[ir].u0 + k] += q->alpha[q->runs[ir].a0 + k];
            cnt[q->runs[ir].u0 + k]++;
        }
    long shared = 0;
    for (long j = 0; j < nn; j++) shared += cnt[j] > 1 ? cnt[j] : 0;
    ibm_targets_of(ibm, 0, q->nruns, 0, nn);
    ibm_momentum(ibm, mom_pass);
    int same_a = nn == 0 || !memcmp(A, q->node_asum, (size_t)nn * sizeof *A);
    int same_t = nn == 0 || !memcmp(T, q->node_target, (size_t)nn * sizeof *T);
    int same_m = !memcmp(mom, mom_pass, nsum * sizeof *mom);
    print_message("  %s (rank %d): %ld forced nodes, %ld entries, %ld shared (%ld counted): Σα %s, targets %s, momentum %s\n",
                  what, g->rank, nn, q->nalpha, q->nshared, shared, same_a ? "identical" : "DIFFERENT",
                  same_t ? "identical" : "DIFFERENT", same_m ? "identical" : "DIFFERENT");
    assert_true(same_a && same_t && same_m);
    assert_int_equal(q->nshared, shared);
    assert_true(grid_sum(g, (double)shared) > 0); /* the scenes have overlapping spheres */
    free(T);
    free(A);
    free(cnt);
    free(mom);
    free(mom_pass);
    it_free(&tc);
}

static void test_build_sums_exact(void **state)
{
    (void)state;
    /* moving, rotating spheres: overlapping (three at some nodes), across
     * the periodic x and y faces, against the z wall; runs of up to 24
     * nodes (longer than the build's fixed-length loops) */
    check_build_sums("[domain]\nnx = 32\nny = 28\nnz = 26\nlength = 2.4 2.1 1.95\n"
                     "[boundary]\nz_lo = noslip\nz_hi = noslip\n[fluid]\nnu = 1\n"
                     "[ibm]\nsphere1 = prescribed center 0.05 1.0 0.7 radius 0.5 velocity 0.3 -0.2 0.1 omega 1 2 -3\n"
                     "sphere2 = prescribed center 1.2 2.05 0.75 radius 0.25 velocity -0.1 0.2 0.4 omega -2 1 0.5\n"
                     "sphere3 = prescribed center 1.1 0.6 0.5 radius 0.2 velocity 0.2 0.1 -0.3 omega 0.3 -1 2\n"
                     "sphere4 = prescribed center 1.32 0.72 0.55 radius 0.22 velocity 0 0.5 0 omega 1 1 1\n"
                     "sphere5 = prescribed center 1.25 0.55 0.68 radius 0.2 velocity 0.1 0 0 omega 0 0 1\n"
                     "sphere6 = prescribed center 1.7 0.4 0.12 radius 0.18 velocity 0.05 0.05 0.05 omega 2 0 0\n",
                     "3-D");
    check_build_sums("[domain]\ngeometry = 2d\nnx = 32\nny = 24\nlength = 2 1.5 1\n"
                     "[boundary]\ny_lo = noslip\ny_hi = freeslip\n[fluid]\nnu = 1\n"
                     "[ibm]\nsphere1 = prescribed center 1.97 0.7 0 radius 0.3 velocity 0.2 0.1 0 omega 0 0 2\n"
                     "sphere2 = prescribed center 1.7 0.6 0 radius 0.2 velocity -0.1 0.3 0 omega 0 0 -1\n",
                     "2-D discs");
}

/* ---- radius_correction = gaps: the neighbour lists against brute force -------------- */

typedef struct {
    double v[4];
} nb_entry_t;

static int by_entry(const void *a, const void *b)
{
    const double *x = ((const nb_entry_t *)a)->v, *y = ((const nb_entry_t *)b)->v;
    for (int q = 0; q < 4; q++)
        if (x[q] != y[q]) return x[q] < y[q] ? -1 : 1;
    return 0;
}

/* The cell-list neighbours of every sphere (offset of the neighbour's centre
 * and its radius) against every other sphere at every periodic image within
 * reach: the same entries, offsets within round-off.  n spheres of radius
 * 0.5 ± 10 % (seeded) in a box of L × L × H (periodic in x and y, walls in z)
 * at D/Δx = dpd; returns the number of entries. */
static long check_gap_lists(int n, double L, double H, int dpd, unsigned seed)
{
    char text[512];
    int nx = (int)lround(L * dpd), nz = (int)lround(H * dpd);
    snprintf(text, sizeof text,
             "[domain]\nnx = %d\nny = %d\nnz = %d\nlength = %g %g %g\n"
             "[boundary]\nz_lo = noslip\nz_hi = noslip\n[fluid]\nnu = 1\n"
             "[ibm]\nradius_correction = gaps\n",
             nx, nx, nz, L, L, H);
    ibm_sphere_t *sp = xcalloc((size_t)n, sizeof *sp);
    srand(seed);
    for (int p = 0; p < n; p++) {
        double u[4];
        for (int q = 0; q < 4; q++) u[q] = rand() / (RAND_MAX + 1.0);
        sp[p].kind = IBM_EXTERNAL;
        sp[p].radius = 0.45 + 0.1 * u[3];
        const double c[3] = {L * u[0], L * u[1], 0.7 + (H - 1.4) * u[2]};
        memcpy(sp[p].x, c, sizeof c);
        memcpy(sp[p].xa, c, sizeof c);
    }
    it_case_t tc;
    tc.cfg = cfg_load_string("test.ini", text, 0, NULL);
    tc.g = grid_create_from_config(tc.cfg, MPI_COMM_WORLD);
    fluid_params_t prm;
    fluid_params_from_config(tc.cfg, tc.g, &prm);
    tc.f = fluid_create(tc.g, &prm);
    fluid_init_from_config(tc.f, tc.cfg);
    tc.ibm = ibm_create_from_config_with(tc.cfg, tc.f, sp, n);
    free(sp);
    /* a moving bed's centres may sit a period away (the list wraps them): shift some by ±L */
    for (int p = 0; p < n; p += 3) tc.ibm->s[p].xa[p % 2] += (p % 4 ? L : -L);
    ibm_t *ibm = tc.ibm;
    const grid_t *g = tc.g;
    ibm_build_nodes(ibm, NULL, 0);
    const ibm_priv_t *q = ibm_priv(ibm);
    /* the reach of gap_neighbours: the sphere, its band, the largest thickening, 1.5 cells and the cutoff */
    double hmax = fmax(g->dy, g->dz);
    for (int i = 0; i < g->n[0]; i++) hmax = fmax(hmax, g->gdxf[i]);
    const double margin = (ibm_band_halfwidth() + IBM_GAP_MAX + 1.5) * hmax;
    nb_entry_t *ref = xcalloc(27 * 27 * (size_t)n, sizeof *ref), *got = NULL;
    long total = 0;
    double worst = 0.0;
    for (int p = 0; p < n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        const double reach = s->radius + margin + IBM_GAP_CUTOFF_D * 2.0 * s->radius;
        long nr = 0;
        const int ni = (int)ceil((reach + 0.55) / L) + 1; /* every image that may be within reach */
        for (int o = 0; o < n; o++)
            for (int i = -ni; i <= ni; i++)
                for (int j = -ni; j <= ni; j++) {
                    if (o == p && i == 0 && j == 0) continue;
                    double off[3] = {ibm->s[o].xa[0] - s->xa[0] + i * L, ibm->s[o].xa[1] - s->xa[1] + j * L,
                                     ibm->s[o].xa[2] - s->xa[2]};
                    if (sqrt(off[0] * off[0] + off[1] * off[1] + off[2] * off[2]) - ibm->s[o].radius >= reach) continue;
                    assert_true(nr < 27 * 27 * n);
                    ref[nr++] = (nb_entry_t){{off[0], off[1], off[2], ibm->s[o].radius}};
                }
        const long m = q->nb_head[p + 1] - q->nb_head[p];
        assert_int_equal(m, nr);
        got = realloc(got, (size_t)(m > 0 ? m : 1) * sizeof *got);
        for (long e = 0; e < m; e++) {
            const double *x = q->nb + IBM_NB_STRIDE * (q->nb_head[p] + e);
            memcpy(got[e].v, x, sizeof got[e].v);
            /* in increasing distance from p's centre to the neighbour's surface, which the entry carries */
            assert_true(fabs(x[4] - (sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - x[3])) < 1e-14);
            if (e > 0) assert_true(x[4] >= x[4 - IBM_NB_STRIDE]);
        }
        /* sorted by offset: neighbours the two sides place within round-off of each other stay paired
         * unless two entries share an x offset to ~1e-15 (not in these seeded scenes) */
        qsort(ref, (size_t)nr, sizeof *ref, by_entry);
        qsort(got, (size_t)m, sizeof *got, by_entry);
        for (long e = 0; e < m; e++)
            for (int c = 0; c < 4; c++) worst = fmax(worst, fabs(got[e].v[c] - ref[e].v[c]));
        total += m;
    }
    print_message("  gaps' neighbour lists, %d spheres in %g x %g x %g (D/dx %d): %ld entries, "
                  "largest offset difference from brute force %.1e\n",
                  n, L, L, H, dpd, total, worst);
    /* the same offsets up to the rounding of whole periods added to centre differences */
    assert_true(worst < 1e-12 * L);
    free(ref);
    free(got);
    it_free(&tc);
    return total;
}

static void test_gap_lists_against_brute_force(void **state)
{
    (void)state;
    /* a box narrower than the reach (~2.6 D): several images of every sphere, one cell per period */
    assert_true(check_gap_lists(12, 2.2, 4.0, 8, 7u) > 12 * 20);
    /* a wide box: several cells per period (the images across the faces from neighbouring cells) */
    assert_true(check_gap_lists(60, 12.0, 5.0, 4, 11u) > 60 * 5);
}

/* ---- cost ---------------------------------------------------------------------------- */

/* The same sphere at the same Δx in boxes of 24³ and 48³ cells has the
 * same node entries: the cost does not grow with the grid. */
static void test_cost_independent_of_grid(void **state)
{
    (void)state;
    long nn[2];
    for (int b = 0; b < 2; b++) {
        int n = 24 * (b + 1);
        char text[512];
        snprintf(text, sizeof text,
                 "[domain]\nnx = %d\nny = %d\nnz = %d\nlength = %g %g %g\n[fluid]\nnu = 1\n"
                 "[ibm]\nsphere1 = fixed center 0.61 0.53 0.57 diameter 0.5\n",
                 n, n, n, n * 0.05, n * 0.05, n * 0.05);
        it_case_t tc = it_from_case(text);
        nn[b] = (long)grid_sum(tc.g, (double)tc.ibm->nodes_forced);
        it_free(&tc);
    }
    print_message("  node entries of one sphere (D/dx = 10): %ld in 24^3, %ld in 48^3\n", nn[0], nn[1]);
    assert_int_equal(nn[0], nn[1]);
    /* about 3 (components) × the volume of the ball of the sphere and its band */
    double est = 3 * 4.0 / 3.0 * M_PI * pow(5.0 + ibm_band_halfwidth(), 3);
    assert_true(nn[0] < 1.1 * est && nn[0] > 0.8 * est);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_profile),
        cmocka_unit_test(test_volume_3d),
        cmocka_unit_test(test_volume_band_width),
        cmocka_unit_test(test_volume_axi_2d),
        cmocka_unit_test(test_lists_against_brute_force),
        cmocka_unit_test(test_build_sums_exact),
        cmocka_unit_test(test_gap_lists_against_brute_force),
        cmocka_unit_test(test_cost_independent_of_grid),
    };
    TEST_MPI_RUN("ibm_alpha", tests);
}
