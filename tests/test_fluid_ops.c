/* test_fluid_ops.c — the fluid's spatial operators, without time stepping:
 * boundary ghosts, energy conservation of the advection term, consistency
 * (measured order) of advection and viscous term, the viscous term against
 * the Laplacian of poisson.c, the [fluid] input checks, and the deferred
 * correction of the time step against the plain one.
 * RANKS: 1 2
 */
#include "../src/fluid/fluid_internal.h" /* fluid_rhs, the fused right-hand side */
#include "fluidtest.h"
#include "modules.h"
#include "testutil.h"

/* ---- boundary ghosts -------------------------------------------------- */

static double ramp(int c, const double x[3], double t, const void *ctx)
{
    (void)t;
    (void)ctx;
    return 1.0 + 0.5 * c + x[0] - 2.0 * x[1] + 0.25 * x[2];
}

/* After fluid_apply_bc: the normal component is 0 on wall and axis faces;
 * the mean of a tangential ghost and its interior neighbour is the wall
 * velocity at a no-slip wall (moving walls on every face kind); free-slip
 * and axis ghosts equal the interior; periodic ghosts hold the image. */
static void check_ghosts(geom_t geom, const bc_t *bc, stretch_t st)
{
    int n[3] = {8, 6, geom == GEOM_3D ? 4 : 1};
    double L[3] = {1.0, 1.5, 0.75};
    grid_t *g = grid_create(geom, n, L, NULL, bc, st, 1.5, MPI_COMM_WORLD);
    fluid_params_t prm = ft_params(0.1, 0);
    fluid_t *f = fluid_create(g, &prm);
    ft_set_velocity(f, ramp, 0.0, NULL);
    int bad = 0;
    int nxl = g->nxl, ny = g->n[1], nz = g->n[2];
    for (int c = 0; c < g->dim; c++) {
        const double *u = f->u[c];
        /* x faces */
        for (int s = 0; s < 2 && !g->periodic[0]; s++) {
            if ((s == 0 && g->left != MPI_PROC_NULL) || (s == 1 && g->right != MPI_PROC_NULL)) continue;
            for (int j = 0; j < ft_nu(g, c, 1); j++)
                for (int k = 0; k < ft_nu(g, c, 2); k++) {
                    if (c == 0) {
                        if (u[G_IDX(g, s == 0 ? -1 : nxl - 1, j, k)] != 0.0) bad++;
                        continue;
                    }
                    double gh = u[G_IDX(g, s == 0 ? -1 : nxl, j, k)], in = u[G_IDX(g, s == 0 ? 0 : nxl - 1, j, k)];
                    if (bc->type[0][s] == BC_NOSLIP && fabs(0.5 * (gh + in) - bc->vel[0][s][c]) > 1e-15) bad++;
                    if (bc->type[0][s] != BC_NOSLIP && gh != in) bad++;
                }
        }
        /* y faces */
        for (int s = 0; s < 2 && !g->periodic[1]; s++)
            for (int i = 0; i < ft_iend(g, c); i++)
                for (int k = 0; k < ft_nu(g, c, 2); k++) {
                    if (c == 1) {
                        if (u[G_IDX(g, i, s == 0 ? -1 : ny - 1, k)] != 0.0) bad++;
                        continue;
                    }
                    double gh = u[G_IDX(g, i, s == 0 ? -1 : ny, k)], in = u[G_IDX(g, i, s == 0 ? 0 : ny - 1, k)];
                    if (bc->type[1][s] == BC_NOSLIP && fabs(0.5 * (gh + in) - bc->vel[1][s][c]) > 1e-15) bad++;
                    if (bc->type[1][s] != BC_NOSLIP && gh != in) bad++;
                }
        /* periodic z (3-D) and the x halo between ranks: images */
        if (g->dim == 3 && g->periodic[2])
            for (int i = 0; i < nxl; i++)
                for (int j = 0; j < ny; j++)
                    if (u[G_IDX(g, i, j, -1)] != u[G_IDX(g, i, j, nz - 1)] || u[G_IDX(g, i, j, nz)] != u[G_IDX(g, i, j, 0)])
                        bad++;
        if (g->left != MPI_PROC_NULL)
            for (int j = 0; j < ft_nu(g, c, 1); j++) {
                double x[3];
                ft_pos(g, c, -1, j, 0, x);
                if (g->ix0 > 0) /* a neighbour rank's value, not a periodic image */
                    if (fabs(u[G_IDX(g, -1, j, 0)] - ramp(c, x, 0, NULL)) > 1e-14) bad++;
            }
    }
    bad = (int)grid_sum(g, bad);
    msg("  ghosts geom %d: %d bad values\n", geom, bad);
    assert_int_equal(bad, 0);
    fluid_free(f);
    grid_free(g);
}

static void test_ghosts(void **state)
{
    bc_t bc = {0};
    /* 2-D: moving no-slip walls in x and y */
    bc.type[0][0] = bc.type[0][1] = bc.type[1][0] = bc.type[1][1] = BC_NOSLIP;
    bc.vel[0][0][1] = 0.3;
    bc.vel[0][1][1] = -0.7;
    bc.vel[1][0][0] = 0.2;
    bc.vel[1][1][0] = 1.0;
    check_ghosts(GEOM_2D, &bc, STRETCH_TANH_BOTH);
    /* 3-D: free slip in x, moving no-slip in y, periodic z */
    memset(&bc, 0, sizeof bc);
    bc.type[0][0] = bc.type[0][1] = BC_FREESLIP;
    bc.type[1][0] = bc.type[1][1] = BC_NOSLIP;
    bc.vel[1][1][0] = 1.0;
    bc.vel[1][1][2] = -0.5;
    bc.vel[1][0][2] = 0.25;
    check_ghosts(GEOM_3D, &bc, STRETCH_UNIFORM);
    /* axisymmetric: axis, moving pipe wall (axial velocity), free slip in y */
    memset(&bc, 0, sizeof bc);
    bc.type[0][0] = BC_AXIS;
    bc.type[0][1] = BC_NOSLIP;
    bc.vel[0][1][1] = 0.4;
    bc.type[1][0] = bc.type[1][1] = BC_FREESLIP;
    check_ghosts(GEOM_AXI, &bc, STRETCH_TANH_HIGH);
}

/* ---- the deferred correction of the time step ---------------------------- */

static double swirl(int c, const double x[3], double t, const void *ctx)
{
    (void)t;
    (void)ctx;
    return c == 0 ? sin(2.0 * x[1]) * cos(x[2]) + 0.3 * x[0] : c == 1 ? cos(3.0 * x[0]) * sin(x[2]) - 0.2 * x[1] : sin(x[0] + x[1]);
}

static void noop_stage_end(fluid_t *f, int stage, double dt_stage, void *ctx)
{
    (void)f;
    (void)stage;
    (void)dt_stage;
    (void)ctx;
}

/* fluid_step defers the correction of RK3 stages 1 and 2 into the next
 * predictor sweep when no stage-end hook reads u^k (theory §1, step 1.5); a
 * no-op hook turns that off.  With walls in y or z on one rank it also
 * takes the forward transforms of the pressure solve inside the predictor
 * sweep (step 1.1c); fluid_params_t.unfused turns every fusion off.  The
 * paths make the same operations on the same values, so after several steps
 * u and p must be bit-identical (any plane corrected late or with stale
 * ghosts, or a plane transformed before its divergence is complete, would
 * differ at O(Δt)). */
static long values_differing(const grid_t *g, fluid_t *a, fluid_t *b, long *compared)
{
    long differ = 0, n = 0;
    for (int c = 0; c <= 3; c++) {
        const double *x = c < 3 ? a->u[c] : a->p, *y = c < 3 ? b->u[c] : b->p;
        for (int i = -1; i <= g->nxl; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -1; k <= g->n[2]; k++, n++) differ += x[G_IDX(g, i, j, k)] != y[G_IDX(g, i, j, k)];
    }
    *compared = (long)grid_sum(g, (double)n);
    return (long)grid_sum(g, (double)differ);
}

static void check_deferred(const bc_t *bc, stretch_t st)
{
    int n[3] = {12, 10, 8};
    double L[3] = {1.0, 1.5, 0.75};
    fluid_t *f[3];
    grid_t *g = grid_create(GEOM_3D, n, L, NULL, bc, st, 1.5, MPI_COMM_WORLD);
    for (int v = 0; v < 3; v++) {
        fluid_params_t prm = ft_params(0.05, 0);
        f[v] = fluid_create(g, &prm);
        if (v == 1) f[v]->stage_end_hook = noop_stage_end;
        if (v == 2) f[v]->prm.unfused = 1;
        ft_set_velocity(f[v], swirl, 0.0, NULL);
        fluid_project(f[v]);
        for (int s = 0; s < 4; s++) fluid_step(f[v], 0.01);
    }
    long compared, differ = values_differing(g, f[0], f[1], &compared);
    long compared2, differ2 = values_differing(g, f[0], f[2], &compared2);
    double kin = 0.0;
    for (int i = 0; i < g->nxl; i++) kin += fabs(f[0]->u[0][G_IDX(g, i, 1, 1)]);
    msg("  deferred vs immediate correction: %ld of %ld values (u, v, w, p with ghosts) differ; fused vs unfused: "
        "%ld of %ld; |u| sample %.3f\n",
        differ, compared, differ2, compared2, kin);
    assert_true(kin > 0.0); /* the flow is not trivial */
    assert_int_equal(differ, 0);
    assert_int_equal(differ2, 0);
    for (int v = 0; v < 3; v++) fluid_free(f[v]);
    grid_free(g);
}

static void test_deferred_correction(void **state)
{
    (void)state;
    bc_t bc = {0};
    /* x: no-slip walls (stretched), y periodic, z: no-slip with a moving lid */
    bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
    bc.type[2][0] = bc.type[2][1] = BC_NOSLIP;
    bc.vel[2][1][0] = 1.0;
    check_deferred(&bc, STRETCH_TANH_BOTH);
    /* x periodic, y free slip and no slip, z periodic */
    memset(&bc, 0, sizeof bc);
    bc.type[1][0] = BC_FREESLIP;
    bc.type[1][1] = BC_NOSLIP;
    bc.vel[1][1][2] = 0.5;
    check_deferred(&bc, STRETCH_UNIFORM);
    /* walls on every face (the benchmark's box), a moving lid in y */
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < 3; d++) bc.type[d][0] = bc.type[d][1] = BC_NOSLIP;
    bc.vel[1][1][0] = 1.0;
    bc.vel[1][1][2] = 0.3;
    check_deferred(&bc, STRETCH_UNIFORM);
    /* y and z periodic (the plane-by-plane transforms without reordering):
     * x no-slip walls (stretched), then triply periodic */
    memset(&bc, 0, sizeof bc);
    bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
    bc.vel[0][1][1] = 0.7;
    check_deferred(&bc, STRETCH_TANH_BOTH);
    memset(&bc, 0, sizeof bc);
    check_deferred(&bc, STRETCH_UNIFORM);
}

/* ---- divergence-free test fields ---------------------------------------- */

/* A smooth scalar with a few modes, periodic on the box, multiplied by an
 * envelope that vanishes on every non-periodic face (squared when `clamp`,
 * so that its gradient vanishes too). */
typedef struct {
    const grid_t *g;
    int clamp;
    int comp; /* which potential component: changes the coefficients */
} pot_t;

static double potential(const pot_t *P, const double x[3])
{
    const grid_t *g = P->g;
    static const double amp[3][3] = {{1.0, 0.4, -0.3}, {-0.6, 0.8, 0.25}, {0.5, -0.35, 0.7}};
    static const int mx[3] = {1, 2, 1}, my[3] = {1, 1, 2}, mz[3] = {2, 1, 1};
    double s = 0.0;
    for (int m = 0; m < 3; m++) {
        double ph = 0.3 * m + 0.7 * P->comp;
        /* axisymmetric: a function of r² (smooth across the axis) */
        double xr = g->geom == GEOM_AXI ? x[0] * x[0] / g->L[0] : x[0] - g->x0[0];
        double t = amp[P->comp][m] * cos(2 * M_PI * mx[m] * xr / g->L[0] + ph) *
                   cos(2 * M_PI * my[m] * (x[1] - g->x0[1]) / g->L[1] + 0.5 * ph);
        if (g->dim == 3) t *= cos(2 * M_PI * mz[m] * (x[2] - g->x0[2]) / g->L[2] + 0.2 * ph);
        s += t;
    }
    double env = 1.0;
    for (int d = 0; d < g->dim; d++)
        if (!g->periodic[d]) {
            double e = g->geom == GEOM_AXI && d == 0 ? 1.0 - x[0] * x[0] / (g->L[0] * g->L[0])
                                                      : sin(M_PI * (x[d] - g->x0[d]) / g->L[d]);
            env *= P->clamp ? e * e : e;
        }
    if (g->geom == GEOM_AXI) env *= x[0] * x[0]; /* ψ ~ r² at the axis: u_z regular */
    return s * env;
}

/* Discrete curl of a potential on the edges: exactly D u = 0 in every cell.
 * 3-D: u = curl_h A; 2-D and axisymmetric: a_f u = −δ_y ψ/Δy,
 * a_c v = δ_x ψ/Δx_f with ψ on the cell corners. */
static void set_discrete_curl(fluid_t *f, int clamp)
{
    const grid_t *g = f->g;
    pot_t P[3] = {{g, clamp, 0}, {g, clamp, 1}, {g, clamp, 2}};
    int axi = g->geom == GEOM_AXI;
    for (int c = 0; c < g->dim; c++) field_zero(g, f->u[c]);
    if (g->dim == 2) {
        FT_FOR_UNKNOWNS(g, 0, i, j, k)
        {
            double a[3] = {g->xf[i], grid_yf(g, j), 0}, b[3] = {g->xf[i], grid_yf(g, j - 1), 0};
            f->u[0][G_IDX(g, i, j, k)] = -(potential(&P[2], a) - potential(&P[2], b)) / (g->dy * (axi ? g->xf[i] : 1));
        }
        FT_FOR_UNKNOWNS(g, 1, i, j, k)
        {
            double a[3] = {g->xf[i], grid_yf(g, j), 0}, b[3] = {g->xf[i - 1], grid_yf(g, j), 0};
            f->u[1][G_IDX(g, i, j, k)] =
                (potential(&P[2], a) - potential(&P[2], b)) / (g->dxf[i] * (axi ? g->xc[i] : 1));
        }
    } else {
        /* A_x on (x_c, y_f, z_f), A_y on (x_f, y_c, z_f), A_z on (x_f, y_f, z_c) */
#define AX(i, j, k) potential(&P[0], (double[3]){g->xc[i], grid_yf(g, j), grid_zf(g, k)})
#define AY(i, j, k) potential(&P[1], (double[3]){g->xf[i], grid_yc(g, j), grid_zf(g, k)})
#define AZ(i, j, k) potential(&P[2], (double[3]){g->xf[i], grid_yf(g, j), grid_zc(g, k)})
        FT_FOR_UNKNOWNS(g, 0, i, j, k)
        f->u[0][G_IDX(g, i, j, k)] = (AZ(i, j, k) - AZ(i, j - 1, k)) / g->dy - (AY(i, j, k) - AY(i, j, k - 1)) / g->dz;
        FT_FOR_UNKNOWNS(g, 1, i, j, k)
        f->u[1][G_IDX(g, i, j, k)] =
            (AX(i, j, k) - AX(i, j, k - 1)) / g->dz - (AZ(i, j, k) - AZ(i - 1, j, k)) / g->dxf[i];
        FT_FOR_UNKNOWNS(g, 2, i, j, k)
        f->u[2][G_IDX(g, i, j, k)] =
            (AY(i, j, k) - AY(i - 1, j, k)) / g->dxf[i] - (AX(i, j, k) - AX(i, j - 1, k)) / g->dy;
#undef AX
#undef AY
#undef AZ
    }
    fluid_apply_bc(f);
}

/* Σ_c Σ V_c u_c N_c and its scale Σ |V u N|. */
static void energy_production(const fluid_t *f, double *const N[3], double *sum, double *scale)
{
    const grid_t *g = f->g;
    double s = 0, a = 0;
    for (int c = 0; c < g->dim; c++) FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            long m = G_IDX(g, i, j, k);
            double t = fluid_cell_volume(f, c, i) * f->u[c][m] * N[c][m];
            s += t;
            a += fabs(t);
        }
    *sum = grid_sum(g, s);
    *scale = grid_sum(g, a);
}

/* The advection term conserves the discrete kinetic energy: for a
 * discretely divergence-free field, Σ V u·N(u) = 0 up to round-off (the
 * scheme is skew-symmetric, advection.c).  Round-off: a sum of ~10⁴ terms of
 * relative accuracy 1e-16 cancels to ≲ 1e-13 of Σ|V u N|; a scheme that is
 * only second-order consistent without the symmetry leaves O(h²) ≈ 1e-3. */
static void test_advection_energy(void **state)
{
    struct {
        const char *name;
        geom_t geom;
        int n[3];
        bc_type_t bx, by, bz;
        stretch_t st;
    } cases[] = {
        {"3-D triply periodic", GEOM_3D, {16, 12, 8}, BC_PERIODIC, BC_PERIODIC, BC_PERIODIC, STRETCH_UNIFORM},
        {"3-D stretched no-slip x, free-slip y, no-slip z", GEOM_3D, {16, 12, 10}, BC_NOSLIP, BC_FREESLIP, BC_NOSLIP,
         STRETCH_TANH_BOTH},
        {"2-D periodic", GEOM_2D, {16, 24, 1}, BC_PERIODIC, BC_PERIODIC, BC_PERIODIC, STRETCH_UNIFORM},
        {"2-D stretched box, no-slip", GEOM_2D, {32, 24, 1}, BC_NOSLIP, BC_NOSLIP, BC_PERIODIC, STRETCH_TANH_LOW},
        {"axisymmetric pipe, stretched, periodic z", GEOM_AXI, {24, 32, 1}, BC_AXIS, BC_PERIODIC, BC_PERIODIC,
         STRETCH_TANH_HIGH},
        {"axisymmetric closed cylinder", GEOM_AXI, {16, 24, 1}, BC_AXIS, BC_NOSLIP, BC_PERIODIC, STRETCH_UNIFORM},
    };
    for (size_t t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        bc_t bc = {0};
        bc.type[0][0] = cases[t].bx;
        bc.type[0][1] = cases[t].bx == BC_AXIS ? BC_NOSLIP : cases[t].bx;
        bc.type[1][0] = bc.type[1][1] = cases[t].by;
        bc.type[2][0] = bc.type[2][1] = cases[t].geom == GEOM_3D ? cases[t].bz : BC_PERIODIC;
        double L[3] = {1.0, 1.3, 0.8};
        grid_t *g = grid_create(cases[t].geom, cases[t].n, L, NULL, &bc, cases[t].st, 1.8, MPI_COMM_WORLD);
        fluid_params_t prm = ft_params(0.01, 0);
        fluid_t *f = fluid_create(g, &prm);
        set_discrete_curl(f, 0);
        double *N[3] = {field_alloc(g), field_alloc(g), g->dim == 3 ? field_alloc(g) : NULL};
        fluid_advection(f, N);
        double sum, scale;
        energy_production(f, N, &sum, &scale);
        double div = fluid_max_divergence(f);
        msg("  %-48s Σ V u·N = %.2e of Σ|V u N| = %.3e; max|D u| = %.1e\n", cases[t].name, sum / scale, scale, div);
        assert_true(div < 1e-11);
        assert_true(fabs(sum) < 1e-13 * scale);
        for (int c = 0; c < 3; c++) free(N[c]);
        fluid_free(f);
        grid_free(g);
    }
}

/* ---- consistency of the advection term --------------------------------- */

/* Analytic divergence-free fields with zero velocity on the walls:
 * 2-D planar box [0,1]²: ψ = (x(1−x) y(1−y))² (1 + x + 0.5 sin 2πy)... via
 * the potential above with clamp = 1; axisymmetric: u from ψ(r, z) with
 * r u_r = −∂zψ, r u_z = ∂rψ.  The exact ∇·(u⊗u) = u·∇u is evaluated by
 * fourth-order central differences of the analytic velocity (step 1e-3:
 * error ~1e-11, far below the discretisation error measured). */
typedef struct {
    pot_t P;
} afield_t;

static double fd4(double (*fn)(const afield_t *, int, const double *), const afield_t *a, int c, const double x[3],
                  int d, double h)
{
    double y[3] = {x[0], x[1], x[2]}, s = 0;
    static const double w[4] = {1, -8, 8, -1}, o[4] = {-2, -1, 1, 2};
    for (int m = 0; m < 4; m++) {
        y[d] = x[d] + o[m] * h;
        s += w[m] * fn(a, c, y);
    }
    return s / (12 * h);
}

static double psi_fn(const afield_t *a, int c, const double *x)
{
    (void)c;
    return potential(&a->P, x);
}

static double vel_fn(const afield_t *a, int c, const double *x)
{
    double r = a->P.g->geom == GEOM_AXI ? x[0] : 1.0;
    if (c == 0) return -fd4(psi_fn, a, 0, x, 1, 1e-3) / r;
    return fd4(psi_fn, a, 0, x, 0, 1e-3) / r;
}

static double advection_error(geom_t geom, stretch_t st, int N, bc_type_t by)
{
    int n[3] = {N, N, 1};
    double L[3] = {1, 1, 1};
    bc_t bc = {0};
    bc.type[0][0] = geom == GEOM_AXI ? BC_AXIS : BC_NOSLIP;
    bc.type[0][1] = BC_NOSLIP;
    bc.type[1][0] = bc.type[1][1] = by;
    grid_t *g = grid_create(geom, n, L, NULL, &bc, st, 1.5, MPI_COMM_WORLD);
    fluid_params_t prm = ft_params(0.01, 0);
    fluid_t *f = fluid_create(g, &prm);
    afield_t a = {{g, 1, 2}};
    double x[3];
    for (int c = 0; c < 2; c++) FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            ft_pos(g, c, i, j, k, x);
            f->u[c][G_IDX(g, i, j, k)] = vel_fn(&a, c, x);
        }
    fluid_apply_bc(f);
    double *Nh[3] = {field_alloc(g), field_alloc(g), NULL};
    fluid_advection(f, Nh);
    double e = 0;
    for (int c = 0; c < 2; c++) FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            ft_pos(g, c, i, j, k, x);
            double ex = vel_fn(&a, 0, x) * fd4(vel_fn, &a, c, x, 0, 1e-3) + vel_fn(&a, 1, x) * fd4(vel_fn, &a, c, x, 1, 1e-3);
            e = fmax(e, fabs(Nh[c][G_IDX(g, i, j, k)] - ex));
        }
    e = grid_max(g, e);
    free(Nh[0]);
    free(Nh[1]);
    fluid_free(f);
    grid_free(g);
    return e;
}

/* The advection term is a second-order approximation of u·∇u for a
 * divergence-free field with zero wall velocity, everywhere including the
 * cells next to the walls and the axis, on stretched grids (smooth tanh map)
 * and with the axisymmetric metric.  Measured max-norm order between 32 and
 * 64 cells must exceed 1.8 (2 asymptotically; the margin covers the
 * pre-asymptotic range of the max norm on the stretched grids). */
static void test_advection_order(void **state)
{
    struct {
        const char *name;
        geom_t geom;
        stretch_t st;
        bc_type_t by;
    } cases[] = {{"2-D no-slip box, stretched x", GEOM_2D, STRETCH_TANH_BOTH, BC_NOSLIP},
                 {"2-D channel, periodic y", GEOM_2D, STRETCH_UNIFORM, BC_PERIODIC},
                 {"axisymmetric pipe, stretched r", GEOM_AXI, STRETCH_TANH_HIGH, BC_PERIODIC},
                 {"axisymmetric closed cylinder", GEOM_AXI, STRETCH_UNIFORM, BC_NOSLIP}};
    for (size_t t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        double e1 = advection_error(cases[t].geom, cases[t].st, 32, cases[t].by);
        double e2 = advection_error(cases[t].geom, cases[t].st, 64, cases[t].by);
        double o = conv_order(e1, e2, 2.0);
        msg("  advection %-34s max error %.3e -> %.3e, order %.2f\n", cases[t].name, e1, e2, o);
        assert_true(o > 1.8);
    }
}

/* ---- viscous term ------------------------------------------------------- */

/* A linear (Couette) profile between moving walls is harmonic, and the
 * ghost 2U − u is exact for it: the viscous term must vanish in every cell,
 * including those next to the walls, on a stretched grid.  Two channels:
 * walls in x (stretched, v linear in x) and walls in y (u linear in y).
 * Round-off: ν|u|/Δ²_min · 1e-15 ≈ 1e-12 of the scale ν/Δ²_min. */
static double couette_fn(int c, const double x[3], double t, const void *ctx)
{
    (void)t;
    const double *U = ctx; /* U[0]: wall-normal direction; U[1], U[2]: tangential velocity at the walls */
    int dw = (int)U[0];
    return c == dw ? 0.0 : U[1] + (U[2] - U[1]) * x[dw];
}

static void test_viscous_couette(void **state)
{
    int n[3] = {32, 16, 1};
    double L[3] = {1, 1, 1};
    for (int dw = 0; dw < 2; dw++)
        for (int impl = 0; impl < 2; impl++) {
            double U[3] = {dw, 0.3, -0.7};
            bc_t bc = {0};
            bc.type[dw][0] = bc.type[dw][1] = BC_NOSLIP;
            bc.vel[dw][0][1 - dw] = U[1];
            bc.vel[dw][1][1 - dw] = U[2];
            grid_t *g = grid_create(GEOM_2D, n, L, NULL, &bc, dw == 0 ? STRETCH_TANH_BOTH : STRETCH_UNIFORM, 2.0,
                                    MPI_COMM_WORLD);
            fluid_params_t prm = ft_params(0.5, impl);
            fluid_t *f = fluid_create(g, &prm);
            ft_set_velocity(f, couette_fn, 0, U);
            double *V[3] = {field_alloc(g), field_alloc(g), NULL};
            fluid_viscous(f, V);
            double m = 0;
            for (int c = 0; c < 2; c++) FT_FOR_UNKNOWNS(g, c, i, j, k) m = fmax(m, fabs(V[c][G_IDX(g, i, j, k)]));
            m = grid_max(g, m);
            double dmin = fmin(g->gdxf[0], g->dy);
            msg("  viscous term of a Couette profile, walls in %c (%s): max %.2e (scale ν/Δ²_min = %.1e)\n",
                "xy"[dw], impl ? "implicit solvers" : "explicit", m, prm.nu / (dmin * dmin));
            assert_true(m < 1e-12 * prm.nu / (dmin * dmin));
            free(V[0]);
            free(V[1]);
            fluid_free(f);
            grid_free(g);
        }
}

/* The viscous term is ν times THE Laplacian of poisson.c: equal to
 * poisson_apply (homogeneous BCs) plus the moving-wall terms 2U·c_wall
 * (c_wall = 1/Δy² or 1/Δz² at a y or z wall, 1/(Δx_c Δx_f) at an x wall), to
 * round-off; and the fused right-hand side of the time step (fluid_rhs) has
 * the same viscous part.  2-D: moving walls on all sides, stretched x; 3-D:
 * moving no-slip x walls (stretched), free-slip y, moving no-slip z. */
static double smooth_fn(int c, const double x[3], double t, const void *ctx)
{
    (void)t;
    (void)ctx;
    if (c == 0) return sin(2.1 * x[0] + 0.3) * cos(1.7 * x[1]) * cos(x[2]) + x[1];
    if (c == 1) return cos(1.3 * x[0]) * sin(2.5 * x[1] + 0.2) * sin(x[2] + 1) - x[0];
    return cos(0.7 * x[0] + x[1]) * sin(1.9 * x[2]);
}

static void check_viscous_identity(geom_t geom, const bc_t *bc, wall_ghost_t wg)
{
    int n[3] = {16, 12, geom == GEOM_3D ? 10 : 1};
    double L[3] = {1, 1.2, 0.9};
    grid_t *g = grid_create(geom, n, L, NULL, bc, STRETCH_TANH_BOTH, 2.0, MPI_COMM_WORLD);
    double nu = 0.37;
    fluid_params_t prm = ft_params(nu, 0);
    prm.wall_ghost = wg;
    fluid_t *f = fluid_create(g, &prm);
    ft_set_velocity(f, smooth_fn, 0, NULL);
    double *V[3] = {field_alloc(g), field_alloc(g), field_alloc(g)}, *R[3] = {field_alloc(g), field_alloc(g), field_alloc(g)};
    fluid_viscous(f, V);
    fluid_rhs(f, 0.0, nu, R);
    double m = 0, mr = 0, s = 0;
    for (int c = 0; c < g->dim; c++) {
        poisson_t *p = poisson_create_operator(g, (var_loc_t)c);
        double *x = field_alloc(g), *y = field_alloc(g);
        field_copy(g, x, f->u[c]);
        poisson_apply(p, 0.0, x, y);
        FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            int idx[3] = {i + g->ix0, j, k};
            double w = 0;
            for (int d = 0; d < g->dim; d++) {
                if (d == c) continue;
                int nd = g->n[d];
                double clo = d == 0 ? 1 / (g->gdxc[-1] * g->gdxf[0]) : d == 1 ? 1 / (g->dy * g->dy) : 1 / (g->dz * g->dz);
                double chi = d == 0 ? 1 / (g->gdxc[nd - 1] * g->gdxf[nd - 1]) : clo;
                if (idx[d] == 0 && bc->type[d][0] == BC_NOSLIP) w += 2 * bc->vel[d][0][c] * clo;
                if (idx[d] == nd - 1 && bc->type[d][1] == BC_NOSLIP) w += 2 * bc->vel[d][1][c] * chi;
            }
            long q = G_IDX(g, i, j, k);
            m = fmax(m, fabs(V[c][q] - nu * (y[q] + w)));
            mr = fmax(mr, fabs(V[c][q] - R[c][q]));
            s = fmax(s, fabs(V[c][q]));
        }
        free(x);
        free(y);
        poisson_free(p);
    }
    m = grid_max(g, m);
    mr = grid_max(g, mr);
    s = grid_max(g, s);
    if (wg == WALL_GHOST_LINEAR) {
        msg("  %d-D viscous term vs ν(poisson_apply + wall terms): max difference %.2e; vs the fused right-hand side "
            "%.2e; of max %.2e\n",
            g->dim, m, mr, s);
        assert_true(m < 1e-13 * s);
    } else
        msg("  %d-D viscous term with the quadratic wall ghost vs the fused right-hand side: max difference %.2e of "
            "max %.2e\n",
            g->dim, mr, s);
    assert_true(mr < 1e-13 * s);
    for (int c = 0; c < 3; c++) {
        free(V[c]);
        free(R[c]);
    }
    fluid_free(f);
    grid_free(g);
}

static void test_viscous_is_poisson_operator(void **state)
{
    bc_t bc = {0};
    bc.type[0][0] = bc.type[0][1] = bc.type[1][0] = bc.type[1][1] = BC_NOSLIP;
    bc.vel[1][0][0] = 0.2;
    bc.vel[1][1][0] = 1.0;
    bc.vel[0][0][1] = 0.3;
    bc.vel[0][1][1] = -0.7;
    check_viscous_identity(GEOM_2D, &bc, WALL_GHOST_LINEAR);
    check_viscous_identity(GEOM_2D, &bc, WALL_GHOST_QUADRATIC);
    memset(&bc, 0, sizeof bc);
    bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
    bc.type[1][0] = bc.type[1][1] = BC_FREESLIP;
    bc.type[2][0] = bc.type[2][1] = BC_NOSLIP;
    bc.vel[0][0][1] = 0.3;
    bc.vel[0][1][2] = -0.4;
    bc.vel[2][1][0] = 1.0;
    bc.vel[2][0][1] = 0.5;
    check_viscous_identity(GEOM_3D, &bc, WALL_GHOST_LINEAR);
    check_viscous_identity(GEOM_3D, &bc, WALL_GHOST_QUADRATIC);
}

/* The quadratic wall ghost (docs/theory.md §4.3).  (a) On a uniform grid the
 * viscous operator with it is exact for a Couette–Poiseuille profile
 * u = U_0 + (U_1 − U_0) s/H + c s(H − s) between no-slip walls (L u = −2c at
 * every unknown, walls in x, y or z) and for the pipe profile
 * u_z = U + b(R² − r²) (L u = −4b); with the linear ghost the wall cells are
 * off by exactly ν u''/4 (ghost 2U − u_0 = u(−h/2) − u''h²/4, times 1/h²).
 * (b) On a stretched x grid the quadratic ghost is the parabola's value at
 * the ghost centre: the quadratic and linear operators differ at the wall
 * cell by c_wall (p(x_g) − (2U − u_0)) with c_wall = 1/(Δx_c,−1 Δx_f,0).
 * Tolerance: 1e-12 of ν max|u|/Δ², the scale of the terms that cancel. */
typedef struct {
    int dw, axi;
    double H, U0, U1, c;
} poly_t;

static double poly_fn(int comp, const double x[3], double t, const void *ctx)
{
    (void)t;
    const poly_t *p = ctx;
    if (comp == p->dw) return 0.0;
    double s = x[p->dw], U0 = p->U0 + 0.1 * comp, U1 = p->U1 - 0.2 * comp;
    if (p->axi) return U1 + p->c * (p->H * p->H - s * s);
    return U0 + (U1 - U0) * s / p->H + p->c * s * (p->H - s);
}

/* max |ν L u − expected| over the tangential unknowns, and (linear ghost)
 * the same over the cells off the walls */
static void check_poly(geom_t geom, int dw, stretch_t st, wall_ghost_t wg, const poly_t *pl, double *err,
                       double *err_wall, double *scale, double *V[3], fluid_t **fp, grid_t **gp)
{
    int n[3] = {16, 12, geom == GEOM_3D ? 10 : 1};
    double L[3] = {1, 1, 1};
    bc_t bc = {0};
    bc.type[dw][0] = geom == GEOM_AXI ? BC_AXIS : BC_NOSLIP;
    bc.type[dw][1] = BC_NOSLIP;
    for (int c = 0; c < 3; c++)
        if (c != dw) {
            bc.vel[dw][0][c] = geom == GEOM_AXI ? 0.0 : pl->U0 + 0.1 * c;
            bc.vel[dw][1][c] = pl->U1 - 0.2 * c;
        }
    grid_t *g = grid_create(geom, n, L, NULL, &bc, st, 1.5, MPI_COMM_WORLD);
    double nu = 0.37;
    fluid_params_t prm = ft_params(nu, 0);
    prm.wall_ghost = wg;
    fluid_t *f = fluid_create(g, &prm);
    ft_set_velocity(f, poly_fn, 0, pl);
    for (int c = 0; c < g->dim; c++) V[c] = field_alloc(g);
    fluid_viscous(f, V);
    double expect = nu * (pl->axi ? -4.0 * pl->c : -2.0 * pl->c), m = 0, mw = 0, um = 0;
    for (int c = 0; c < g->dim; c++) {
        if (c == dw) continue;
        FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            int idx[3] = {i + g->ix0, j, k};
            double e = fabs(V[c][G_IDX(g, i, j, k)] - expect);
            if (idx[dw] == g->n[dw] - 1 || (idx[dw] == 0 && !pl->axi)) mw = fmax(mw, e);
            else m = fmax(m, e);
            um = fmax(um, fabs(f->u[c][G_IDX(g, i, j, k)]));
        }
    }
    double h = dw == 0 ? fmin(g->gdxf[0], g->gdxf[g->n[0] - 1]) : dw == 1 ? g->dy : g->dz;
    *err = grid_max(g, m);
    *err_wall = grid_max(g, mw);
    *scale = nu * grid_max(g, um) / (h * h);
    *fp = f;
    *gp = g;
}

static void free_poly(double *V[3], fluid_t *f, grid_t *g)
{
    for (int c = 0; c < g->dim; c++) free(V[c]);
    fluid_free(f);
    grid_free(g);
}

static void test_viscous_quadratic_ghost(void **state)
{
    /* (a) uniform grids */
    static const struct {
        geom_t geom;
        int dw;
    } cs[4] = {{GEOM_2D, 0}, {GEOM_2D, 1}, {GEOM_3D, 2}, {GEOM_AXI, 0}};
    for (int q = 0; q < 4; q++) {
        poly_t pl = {.dw = cs[q].dw, .axi = cs[q].geom == GEOM_AXI, .H = 1, .U0 = 0.3, .U1 = -0.7, .c = 1.3};
        double e[2], ew[2], sc;
        for (int wg = 0; wg < 2; wg++) {
            double *V[3];
            fluid_t *f;
            grid_t *g;
            check_poly(cs[q].geom, cs[q].dw, STRETCH_UNIFORM, (wall_ghost_t)wg, &pl, &e[wg], &ew[wg], &sc, V, &f, &g);
            free_poly(V, f, g);
        }
        /* |u''| = 2c (planar), 2b (pipe: ∂²u/∂r² = −2b), times the wall
         * coefficient × h² (pipe: r_wall/r_c of the last cell, 32/31) */
        double off = 0.37 * 2.0 * pl.c / 4.0 * (pl.axi ? 1.0 / (1.0 - 0.5 / 16) : 1.0);
        msg("  quadratic profile, walls normal to %c (%s): |L u − u''| off the walls %.1e / %.1e, at the wall cells "
            "%.1e (quadratic ghost) and %.4e (linear; ν|u''|/4 = %.4e); scale %.1e\n",
            "xyz"[cs[q].dw], cs[q].geom == GEOM_AXI ? "pipe" : cs[q].geom == GEOM_3D ? "3-D" : "2-D", e[1], e[0], ew[1],
            ew[0], off, sc);
        assert_true(e[0] < 1e-12 * sc && e[1] < 1e-12 * sc && ew[1] < 1e-12 * sc);
        assert_true(fabs(ew[0] - off) < 1e-12 * sc);
    }
    /* (b) stretched x walls: the wall-cell difference quadratic − linear */
    poly_t pl = {.dw = 0, .H = 1, .U0 = 0.3, .U1 = -0.7, .c = 1.3};
    double *V[2][3], e, ew, sc;
    fluid_t *f[2];
    grid_t *g[2];
    for (int wg = 0; wg < 2; wg++)
        check_poly(GEOM_2D, 0, STRETCH_TANH_BOTH, (wall_ghost_t)wg, &pl, &e, &ew, &sc, V[wg], &f[wg], &g[wg]);
    const grid_t *gg = g[0];
    double m = 0, dmax = 0;
    int nx = gg->n[0];
    for (int s = 0; s < 2; s++) {
        int ig = s == 0 ? 0 : nx - 1, i = ig - gg->ix0, gc = s == 0 ? -1 : nx;
        if (i < 0 || i >= gg->nxl) continue;
        double xg[3] = {gg->gxc[gc], 0, 0}, U = s == 0 ? pl.U0 + 0.1 : pl.U1 - 0.2;
        double cwall = 1.0 / (gg->gdxc[s == 0 ? -1 : nx - 1] * gg->gdxf[ig]);
        for (int j = 0; j < gg->n[1]; j++) {
            long idx = G_IDX(gg, i, j, 0);
            double d = V[1][1][idx] - V[0][1][idx];
            double want = 0.37 * cwall * (poly_fn(1, xg, 0, &pl) - (2 * U - f[0]->u[1][idx]));
            m = fmax(m, fabs(d - want));
            dmax = fmax(dmax, fabs(d));
        }
    }
    m = grid_max(gg, m);
    dmax = grid_max(gg, dmax);
    msg("  stretched x walls: (L_quad − L_lin) u at the wall cells = ν c_wall (p(x_g) − 2U + u_0) to %.1e (the "
        "difference is %.3e; scale %.1e)\n",
        m, dmax, sc);
    assert_true(m < 1e-12 * sc);
    assert_true(dmax > 1e-3 * sc); /* not trivially zero */
    for (int wg = 0; wg < 2; wg++) free_poly(V[wg], f[wg], g[wg]);
}

/* ---- bad input -------------------------------------------------------- */

static jmp_buf jb;
static char last_msg[1024];
static int parsing;
/* The parser reports its errors and returns NULL (the hook may return); any
 * later check stops through cfg_fail, whose hook must not return. */
static void hook(const char *m)
{
    if (!last_msg[0]) snprintf(last_msg, sizeof last_msg, "%s", m);
    if (!parsing) longjmp(jb, 1);
}

static const char *base_case = "[domain]\ngeometry = %s\nnx = 8\nny = 8\nnz = %d\nlength = 1 1 1\n"
                               "[boundary]\n%s\n[fluid]\n%s\n";

/* Load a case, build the grid and the fluid and set the initial condition;
 * returns the error message, or "" when everything was accepted. */
static const char *try_text(const char *text)
{
    static cfg_t *cfg;
    static grid_t *g;
    static fluid_t *f;
    cfg = NULL;
    g = NULL;
    f = NULL;
    last_msg[0] = 0;
    cfg_set_error_hook(hook);
    if (!setjmp(jb)) {
        parsing = 1;
        cfg = cfg_load_string("case.ini", text, 0, NULL);
        parsing = 0;
        if (cfg) {
            g = grid_create_from_config(cfg, MPI_COMM_WORLD);
            fluid_params_t prm;
            fluid_params_from_config(cfg, g, &prm);
            f = fluid_create(g, &prm);
            fluid_init_from_config(f, cfg);
        }
    }
    cfg_set_error_hook(NULL);
    fluid_free(f);
    grid_free(g);
    if (cfg) cfg_free(cfg);
    return last_msg;
}

static const char *try_case(const char *geom, const char *boundary, const char *fluid)
{
    char text[2048];
    snprintf(text, sizeof text, base_case, geom, strcmp(geom, "3d") ? 1 : 8, boundary, fluid);
    return try_text(text);
}

static void expect_error(const char *geom, const char *boundary, const char *fluid, const char *needle)
{
    const char *m = try_case(geom, boundary, fluid);
    msg("  [%s] -> %s\n", needle, m[0] ? m : "(accepted)");
    assert_non_null(strstr(m, needle));
}

static void test_bad_input(void **state)
{
    const char *per = "";
    const char *chan = "y_lo = noslip\ny_hi = noslip";
    /* accepted */
    assert_string_equal(try_case("2d", chan, "nu = 0.1\ninit = laminar\nbody_force = 1 0 0"), "");
    assert_string_equal(try_case("3d", per, "nu = 0.1\ninit = abc"), "");
    assert_string_equal(try_case("3d", "y_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip",
                                 "nu = 0.1\ninit = laminar\nbody_force = 1 0 0"), "");
    /* missing, out of range, wrong type: the parser and the getters */
    expect_error("2d", per, "rho = 2", "fluid.nu: missing key");
    expect_error("2d", per, "nu = -1", "case.ini:10: fluid.nu: -1 is out of range");
    expect_error("2d", per, "nu = 0.1\nviscous = semi", "case.ini:11: fluid.viscous:");
    expect_error("2d", per, "nu = 0.1\ncfl = 2", "case.ini:11: fluid.cfl: 2 is out of range");
    /* cross-field consistency */
    expect_error("2d", per, "nu = 0.1\nbody_force = 0 0 1", "case.ini:11: fluid.body_force: a 2-D grid");
    expect_error("axisymmetric", "x_lo = axis\nx_hi = noslip", "nu = 0.1\nbody_force = 1 0 0",
                 "fluid.body_force: an axisymmetric body force must be axial");
    expect_error("2d", per, "nu = 0.1\ndt = 0.5\ndt_max = 0.1", "fluid.dt: the fixed step");
    expect_error("2d", chan, "nu = 0.1\ninit = taylor_green", "fluid.init: taylor_green needs periodic");
    expect_error("axisymmetric", "x_lo = axis\nx_hi = noslip", "nu = 0.1\ninit = taylor_green",
                 "fluid.init: taylor_green needs a Cartesian");
    expect_error("2d", per, "nu = 0.1\ninit = abc", "fluid.init: abc needs a triply periodic 3d grid");
    expect_error("2d", per, "nu = 0.1\ninit = laminar", "fluid.init: laminar needs one wall-bounded direction");
    expect_error("2d", "x_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip", "nu = 0.1\ninit = laminar",
                 "fluid.init: laminar needs one wall-bounded direction, or two in a 3d duct");
    const char *duct = "y_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip";
    expect_error("3d", "x_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip",
                 "nu = 0.1\ninit = laminar", "fluid.init: laminar needs one wall-bounded direction, or two in a 3d duct");
    expect_error("3d", "y_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = freeslip", "nu = 0.1\ninit = laminar",
                 "fluid.init: laminar in a duct needs no-slip walls on both z faces");
    expect_error("3d", "y_lo = noslip\ny_hi = noslip\ny_hi_velocity = 1 0 0\nz_lo = noslip\nz_hi = noslip",
                 "nu = 0.1\ninit = laminar", "boundary.y_hi_velocity: laminar in a duct needs walls at rest");
    expect_error("3d", duct, "nu = 0.1\nbody_force = 1 0 1\ninit = laminar",
                 "fluid.body_force: laminar in a duct needs the body force along the duct (x) only");
    expect_error("2d", "y_lo = noslip\ny_hi = freeslip", "nu = 0.1\ninit = laminar",
                 "fluid.init: laminar needs no-slip walls");
    expect_error("2d", chan, "nu = 0.1\nwall_ghost = cubic", "case.ini:12: fluid.wall_ghost: 'cubic' is not one of");
    const char *one = "[domain]\ngeometry = 2d\nnx = 8\nny = 1\nlength = 1 1 1\n[boundary]\ny_lo = noslip\n"
                      "y_hi = noslip\n[fluid]\nnu = 0.1\nwall_ghost = quadratic\n";
    const char *m = try_text(one);
    msg("  [one cell between walls] -> %s\n", m[0] ? m : "(accepted)");
    assert_non_null(strstr(m, "case.ini:4: domain.ny: at least 2 cells between walls"));
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ghosts),
        cmocka_unit_test(test_advection_energy),
        cmocka_unit_test(test_advection_order),
        cmocka_unit_test(test_viscous_couette),
        cmocka_unit_test(test_viscous_is_poisson_operator),
        cmocka_unit_test(test_viscous_quadratic_ghost),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_deferred_correction),
    };
    TEST_MPI_RUN("fluid_ops", tests);
}
