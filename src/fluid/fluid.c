/* fluid.c — the [fluid] keys, the solver's parameters, creation and
 * destruction, and the initial conditions. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fluid_internal.h"
#include "util.h"

static const cfg_key_t fluid_keys[] = {
    {"fluid", "nu", CFG_DOUBLE, NULL, 1e-300, 1e300, NULL, "kinematic viscosity ν = η/ρ (> 0); or give mu", CFG_CONDITIONAL},
    {"fluid", "mu", CFG_DOUBLE, NULL, 1e-300, 1e300, NULL,
     "dynamic viscosity η (Pa s), instead of nu (ν = η/ρ)", CFG_CONDITIONAL},
    {"fluid", "rho", CFG_DOUBLE, "1", 1e-300, 1e300, NULL,
     "fluid density (the solver uses the kinematic pressure p/ρ; ρ scales forces and output)"},
    {"fluid", "body_force", CFG_VEC3, "0 0 0", -1e300, 1e300, NULL,
     "uniform body acceleration (e.g. a mean pressure gradient −(dP/dx)/ρ) on the whole box, the inside of "
     "immersed solids included (as a mean pressure gradient acts on a bed); NOT gravity: the pressure is "
     "relative to hydrostatic"},
    {"fluid", "viscous", CFG_ENUM, "auto", 1, 0, "explicit|implicit|auto",
     "viscous term: explicit in the RK3 stages, Crank–Nicolson per stage (Helmholtz solves, same method "
     "as [poisson]), or auto: per step, explicit where its stability limit (fourier) allows the step the other "
     "limits set, implicit where they allow more than viscous_auto_ratio times it (reported in the log and "
     "summary.json)"},
    {"fluid", "viscous_auto_ratio", CFG_DOUBLE, "2", 1, 1e6, NULL,
     "viscous = auto: an implicit step is taken when the other limits allow a step more than this many times "
     "the explicit viscous limit (below, the explicit limit sets the step: an implicit step costs 1.5-3 explicit "
     "ones)"},
    {"fluid", "wall_ghost", CFG_ENUM, "linear", 1, 0, "linear|quadratic",
     "ghost of the wall-tangential velocity at a no-slip wall in the viscous term: linear 2U − u₀ (exact for "
     "Couette flow), or quadratic through U, u₀, u₁ (exact for plane and pipe Poiseuille flow on a uniform grid; "
     "costs: the explicit viscous step limit is up to 25 % smaller, Crank–Nicolson does two Helmholtz solves per "
     "stage)"},
    {"fluid", "cfl", CFG_DOUBLE, "0.5", 1e-6, 1.7, NULL,
     "adaptive step: Δt·max Σ_d |u_d|/Δ_d (RK3 with central advection is stable up to √3)"},
    {"fluid", "fourier", CFG_DOUBLE, "0.5", 1e-6, 0.62, NULL,
     "adaptive step, explicit viscous term: Δt·ν·max Σ_d 1/Δ_d² (RK3 is stable up to 2.51/4 = 0.628)"},
    {"fluid", "dt", CFG_DOUBLE, "0", 0, 1e300, NULL, "fixed time step; 0 = adaptive (cfl, fourier, dt_max)"},
    {"fluid", "dt_max", CFG_DOUBLE, "0", 0, 1e300, NULL, "upper bound of the adaptive step; 0 = none"},
    {"fluid", "init", CFG_ENUM, "rest", 1, 0, "rest|taylor_green|abc|laminar",
     "initial velocity: rest; taylor_green (periodic 2d/3d); abc (Beltrami flow, triply periodic cube); "
     "laminar (exact Couette–Poiseuille profile between the walls of the one wall-bounded direction, "
     "Hagen–Poiseuille in an axisymmetric pipe, or the rectangular duct's series solution when two directions of a "
     "3d grid have walls at rest)"},
    {"fluid", "init_velocity", CFG_DOUBLE, "1", -1e300, 1e300, NULL, "amplitude U of init = taylor_green"},
    {"fluid", "reynolds_length", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "length ℓ of the Reynolds number Re = |U| ℓ/ν of a flow periodic in some direction, U the superficial "
     "velocity (the box mean of u, solid included) along the periodic directions: column reynolds of series.csv "
     "and fluid.reynolds of summary.json; 0: none"},
    {"fluid", "flow_rate_direction", CFG_ENUM, "none", 1, 0, "none|x|y|z",
     "hold the flow rate of a periodic flow along this periodic direction: after every step the superficial "
     "velocity (the box mean of that component, solid included) is set to the target (superficial_velocity or "
     "reynolds) by a uniform correction, and the body force along it becomes the one that drives the flow "
     "(body_force is its initial value; series.csv body_force_x …, summary.json fluid.body_force_x …); none: the "
     "body force is held"},
    {"fluid", "superficial_velocity", CFG_DOUBLE, NULL, -1e300, 1e300, NULL,
     "optional; flow_rate_direction: the target superficial velocity U (m/s; or give reynolds)", CFG_OPTIONAL},
    {"fluid", "reynolds", CFG_DOUBLE, NULL, -1e300, 1e300, NULL,
     "optional; flow_rate_direction: the target Reynolds number U ℓ/ν, ℓ = reynolds_length (instead of "
     "superficial_velocity)", CFG_OPTIONAL},
    {"fluid", "init_abc", CFG_VEC3, "1 1 1", -1e300, 1e300, NULL, "coefficients A B C of init = abc"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void fluid_register_keys(void) { cfg_schema_add(fluid_keys); }

double fluid_nu_from_config(cfg_t *cfg)
{
    if (!cfg_has(cfg, "fluid", "mu")) return cfg_double(cfg, "fluid", "nu");
    if (cfg_has(cfg, "fluid", "nu")) cfg_fail(cfg, "fluid", "mu", "give nu or mu, not both");
    return cfg_double(cfg, "fluid", "mu") / cfg_double(cfg, "fluid", "rho");
}

void fluid_params_from_config(cfg_t *cfg, const grid_t *g, fluid_params_t *prm)
{
    memset(prm, 0, sizeof *prm);
    prm->nu = fluid_nu_from_config(cfg);
    prm->rho = cfg_double(cfg, "fluid", "rho");
    cfg_vec3(cfg, "fluid", "body_force", prm->body_force);
    static const int viscous[3] = {FLUID_VISCOUS_EXPLICIT, FLUID_VISCOUS_IMPLICIT, FLUID_VISCOUS_AUTO};
    prm->implicit_viscous = viscous[cfg_enum(cfg, "fluid", "viscous")];
    prm->viscous_auto_ratio = cfg_double(cfg, "fluid", "viscous_auto_ratio");
    prm->wall_ghost = cfg_enum(cfg, "fluid", "wall_ghost") == 1 ? WALL_GHOST_QUADRATIC : WALL_GHOST_LINEAR;
    prm->cfl = cfg_double(cfg, "fluid", "cfl");
    prm->fourier = cfg_double(cfg, "fluid", "fourier");
    prm->dt_fixed = cfg_double(cfg, "fluid", "dt");
    prm->dt_max = cfg_double(cfg, "fluid", "dt_max");
    poisson_opts_from_config(cfg, &prm->poisson);
    prm->hold_dir = cfg_enum(cfg, "fluid", "flow_rate_direction") - 1;
    prm->hold_flow = prm->hold_dir >= 0;
    if (prm->hold_flow) {
        const int d = prm->hold_dir, sv = cfg_has(cfg, "fluid", "superficial_velocity"),
                  re = cfg_has(cfg, "fluid", "reynolds");
        if (d >= g->dim || !g->periodic[d])
            cfg_fail(cfg, "fluid", "flow_rate_direction",
                     "the flow rate is held along a periodic direction: %c is not periodic", "xyz"[d]);
        if (sv == re)
            cfg_fail(cfg, "fluid", "flow_rate_direction",
                     sv ? "give superficial_velocity or reynolds, not both" : "needs superficial_velocity or reynolds");
        if (sv)
            prm->hold_velocity = cfg_double(cfg, "fluid", "superficial_velocity");
        else {
            const double ell = cfg_double(cfg, "fluid", "reynolds_length");
            if (!(ell > 0)) cfg_fail(cfg, "fluid", "reynolds", "a target Reynolds number needs reynolds_length > 0");
            prm->hold_velocity = cfg_double(cfg, "fluid", "reynolds") * prm->nu / ell;
        }
    } else {
        if (cfg_has(cfg, "fluid", "superficial_velocity"))
            cfg_fail(cfg, "fluid", "superficial_velocity", "needs flow_rate_direction (x, y or z)");
        if (cfg_has(cfg, "fluid", "reynolds")) cfg_fail(cfg, "fluid", "reynolds", "needs flow_rate_direction (x, y or z)");
    }

    if (g->dim == 2 && prm->body_force[2] != 0.0)
        cfg_fail(cfg, "fluid", "body_force", "a 2-D grid has no z direction: the z component must be 0");
    if (g->geom == GEOM_AXI && prm->body_force[0] != 0.0)
        cfg_fail(cfg, "fluid", "body_force",
                 "an axisymmetric body force must be axial (y): a uniform radial component is not meaningful");
    if (prm->wall_ghost == WALL_GHOST_QUADRATIC)
        for (int d = 0; d < g->dim; d++)
            if (g->n[d] < 2 && (g->bc.type[d][0] == BC_NOSLIP || g->bc.type[d][1] == BC_NOSLIP))
                cfg_fail(cfg, "fluid", "wall_ghost",
                         "quadratic needs at least 2 cells normal to the no-slip walls of %c (n%c = %d)", "xyz"[d],
                         "xyz"[d], g->n[d]);
    if (prm->dt_fixed > 0 && prm->dt_max > 0 && prm->dt_fixed > prm->dt_max)
        cfg_fail(cfg, "fluid", "dt", "the fixed step %g exceeds dt_max = %g", prm->dt_fixed, prm->dt_max);
}

fluid_t *fluid_create(grid_t *g, const fluid_params_t *prm)
{
    /* ν = 0 (inviscid) is allowed through the API for the energy tests; the
     * case file requires ν > 0 */
    if (!(prm->nu >= 0) || (prm->implicit_viscous == FLUID_VISCOUS_IMPLICIT && !(prm->nu > 0)))
        die("fluid_create: nu must be > 0 (got %g)", prm->nu);
    fluid_t *f = xcalloc(1, sizeof *f);
    fluid_priv_t *q = xcalloc(1, sizeof *q);
    f->g = g;
    f->prm = *prm;
    if (!(f->prm.cfl > 0)) f->prm.cfl = 0.5;
    if (!(f->prm.fourier > 0)) f->prm.fourier = 0.5;
    if (!(f->prm.rho > 0)) f->prm.rho = 1.0;
    f->priv = q;
    int nc = fluid_ncomp(g);
    for (int c = 0; c < nc; c++) {
        f->u[c] = field_alloc(g);
        q->h[c] = field_alloc(g);
        q->spare[c] = field_alloc(g);
        q->pv[c] = prm->implicit_viscous == FLUID_VISCOUS_IMPLICIT ? poisson_create(g, (var_loc_t)c, &prm->poisson)
                                                                   : poisson_create_operator(g, (var_loc_t)c);
    }
    f->p = field_alloc(g);
    q->work = field_alloc(g);
    q->halo_buf = xcalloc((size_t)6 * g->sx, sizeof(double));
    q->pp = poisson_create(g, VAR_P, &prm->poisson);

    int nxl = g->nxl;
    q->af = xcalloc((size_t)nxl + 2, sizeof(double));
    q->ac = xcalloc((size_t)nxl + 2, sizeof(double));
    q->af++;
    q->ac++;
    for (int i = -1; i <= nxl; i++) {
        q->af[i] = g->geom == GEOM_AXI ? g->xf[i] : 1.0;
        q->ac[i] = g->geom == GEOM_AXI ? g->xc[i] : 1.0;
    }
    fluid_viscous_setup(f);
    f->dt_viscous = fluid_viscous_limit(f);
    f->implicit_step = prm->implicit_viscous == FLUID_VISCOUS_IMPLICIT;
    if (prm->implicit_viscous == FLUID_VISCOUS_AUTO && fluid_auto_may_be_implicit(f))
        for (int c = 0; c < nc; c++) poisson_add_solver(q->pv[c], &prm->poisson);
    fluid_apply_bc(f);
    return f;
}

void fluid_free(fluid_t *f)
{
    if (!f) return;
    fluid_priv_t *q = fluid_priv(f);
    for (int c = 0; c < 3; c++) {
        free(f->u[c]);
        free(q->h[c]);
        free(q->spare[c]);
        poisson_free(q->pv[c]);
    }
    free(f->p);
    free(q->work);
    free(q->halo_buf);
    poisson_free(q->pp);
    free(q->af - 1);
    free(q->ac - 1);
    free(q);
    free(f);
}

/* ---- initial conditions ------------------------------------------------- */

/* Position of the unknown (i,j,k) of component c (c = −1: cell centre). */
static void position(const grid_t *g, int c, int i, int j, int k, double x[3])
{
    x[0] = c == 0 ? g->xf[i] : g->xc[i];
    x[1] = c == 1 ? grid_yf(g, j) : grid_yc(g, j);
    x[2] = g->dim == 3 ? (c == 2 ? grid_zf(g, k) : grid_zc(g, k)) : 0.0;
}

typedef double (*field_fn_t)(int c, const double x[3], const void *ctx);

/* u[c] = fn(c, x) at every unknown; p = fn(−1, x) at the cells. */
static void set_fields(fluid_t *f, field_fn_t fn, const void *ctx)
{
    const grid_t *g = f->g;
    double x[3];
    for (int c = -1; c < fluid_ncomp(g); c++) {
        double *a = c < 0 ? f->p : f->u[c];
        int iend = c < 0 ? g->nxl : fluid_iend(g, c);
        int nj = c < 0 ? g->n[1] : fluid_nu(g, c, 1), nk = c < 0 ? g->n[2] : fluid_nu(g, c, 2);
        for (int i = 0; i < iend; i++)
            for (int j = 0; j < nj; j++)
                for (int k = 0; k < nk; k++) {
                    position(g, c, i, j, k, x);
                    a[G_IDX(g, i, j, k)] = fn(c, x, ctx);
                }
    }
}

typedef struct {
    double U, k[3];
    int dim;
} tgv_t;

/* Taylor–Green vortex.  2-D: u = U sin(k_x x) cos(k_y y), v = −U (k_x/k_y)
 * cos(k_x x) sin(k_y y), an exact solution decaying as exp(−ν(k_x²+k_y²)t),
 * p = (U²/4)[cos 2k_x x + (k_x/k_y)² cos 2k_y y].  3-D: the same times
 * cos(k_z z), w = 0, with the t = 0 pressure (U²/16)(cos 2k_x x + cos 2k_y y)
 * (cos 2k_z z + 2) of the isotropic case (not an exact solution for t > 0). */
static double tgv_fn(int c, const double x[3], const void *ctx)
{
    const tgv_t *t = ctx;
    double sx = sin(t->k[0] * x[0]), cx = cos(t->k[0] * x[0]), sy = sin(t->k[1] * x[1]), cy = cos(t->k[1] * x[1]);
    double cz = t->dim == 3 ? cos(t->k[2] * x[2]) : 1.0, r = t->k[0] / t->k[1], U = t->U;
    switch (c) {
    case 0: return U * sx * cy * cz;
    case 1: return -U * r * cx * sy * cz;
    case 2: return 0.0;
    default:
        if (t->dim == 2) return 0.25 * U * U * (cos(2 * t->k[0] * x[0]) + r * r * cos(2 * t->k[1] * x[1]));
        return U * U / 16.0 * (cos(2 * t->k[0] * x[0]) + cos(2 * t->k[1] * x[1])) * (cos(2 * t->k[2] * x[2]) + 2.0);
    }
}

typedef struct {
    double A, B, C, k;
} abc_t;

/* Arnold–Beltrami–Childress flow: ∇×u = k u, so u·∇u = ∇(|u|²/2) and
 * u e^{−νk²t}, p = −|u|²/2 is an exact solution. */
static void abc_velocity(const abc_t *a, const double x[3], double u[3])
{
    double k = a->k;
    u[0] = a->A * sin(k * x[2]) + a->C * cos(k * x[1]);
    u[1] = a->B * sin(k * x[0]) + a->A * cos(k * x[2]);
    u[2] = a->C * sin(k * x[1]) + a->B * cos(k * x[0]);
}

static double abc_fn(int c, const double x[3], const void *ctx)
{
    double u[3];
    abc_velocity(ctx, x, u);
    if (c >= 0) return u[c];
    return -0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
}

typedef struct {
    int dw;             /* the wall-bounded direction */
    int axi;
    double H, s0;       /* wall distance and low-wall coordinate */
    double ulo[3], uhi[3], f[3], nu;
} laminar_t;

/* Steady laminar flow between the walls normal to dw: for each tangential
 * component, u = U_lo + (U_hi − U_lo) s/H + f s (H − s)/(2ν) (plane
 * Couette–Poiseuille); in a pipe of radius R = H, u_axial = U_wall +
 * f (R² − r²)/(4ν) (Hagen–Poiseuille).  A body force normal to the walls is
 * balanced by the pressure p = f_n (s − H/2). */
static double laminar_fn(int c, const double x[3], const void *ctx)
{
    const laminar_t *l = ctx;
    double s = x[l->dw] - l->s0, H = l->H;
    if (c < 0) return l->f[l->dw] * (s - 0.5 * H);
    if (c == l->dw) return 0.0;
    if (l->axi) return l->uhi[c] + l->f[c] * (H * H - s * s) / (4 * l->nu);
    return l->ulo[c] + (l->uhi[c] - l->ulo[c]) * s / H + l->f[c] * s * (H - s) / (2 * l->nu);
}

typedef struct {
    int dp, dw[2];      /* the periodic (flow) direction and the two wall-bounded ones */
    double a, b, s0[2]; /* the duct's sides along dw[0], dw[1] and its low corner */
    double f, nu;       /* the body force along dp */
} duct_t;

/* Steady laminar flow along dp in a rectangular duct with fixed walls, ν∇²u = −f, u = 0 on the
 * walls (0 ≤ s ≤ a, 0 ≤ t ≤ b): u = Σ_{n odd} 4 f a²/(ν π³ n³) sin(nπs/a)
 * [1 − cosh(nπ(t − b/2)/a)/cosh(nπb/(2a))] (the plane Poiseuille profile's sine series less the
 * harmonic terms that cancel it on t = 0, b).  The series converges as n⁻³: the terms to n = 201
 * leave 2e-5 of the centreline velocity, and a held flow rate corrects the flux. */
static double duct_fn(int c, const double x[3], const void *ctx)
{
    const duct_t *l = ctx;
    if (c != l->dp) return 0.0;
    double s = x[l->dw[0]] - l->s0[0], t = fabs(x[l->dw[1]] - l->s0[1] - 0.5 * l->b), u = 0.0;
    for (int n = 1; n <= 201; n += 2) {
        double k = n * M_PI / l->a;
        /* cosh(k t)/cosh(k b/2) without overflow */
        double r = exp(k * (t - 0.5 * l->b)) * (1 + exp(-2 * k * t)) / (1 + exp(-k * l->b));
        u += sin(k * s) * (1 - r) / ((double)n * n * n);
    }
    return 4 * l->f * l->a * l->a / (l->nu * M_PI * M_PI * M_PI) * u;
}

/* init = laminar in a duct (a 3d grid): two wall-bounded directions with fixed no-slip walls,
 * the third periodic and the body force along it only */
static void init_duct(fluid_t *f, cfg_t *cfg)
{
    const grid_t *g = f->g;
    duct_t l = {.dp = -1, .nu = f->prm.nu};
    int nw = 0;
    for (int d = 0; d < 3; d++) {
        if (g->periodic[d]) {
            l.dp = d;
            continue;
        }
        for (int s = 0; s < 2; s++) {
            if (g->bc.type[d][s] != BC_NOSLIP)
                cfg_fail(cfg, "fluid", "init", "laminar in a duct needs no-slip walls on both %c faces", "xyz"[d]);
            char key[16];
            snprintf(key, sizeof key, "%c_%s_velocity", "xyz"[d], s ? "hi" : "lo");
            for (int c = 0; c < 3; c++)
                if (g->bc.vel[d][s][c] != 0.0) cfg_fail(cfg, "boundary", key, "laminar in a duct needs walls at rest");
        }
        l.dw[nw] = d;
        l.s0[nw++] = g->x0[d];
    }
    for (int c = 0; c < 3; c++)
        if (c != l.dp && f->prm.body_force[c] != 0.0)
            cfg_fail(cfg, "fluid", "body_force", "laminar in a duct needs the body force along the duct (%c) only",
                     "xyz"[l.dp]);
    l.a = g->L[l.dw[0]];
    l.b = g->L[l.dw[1]];
    l.f = f->prm.body_force[l.dp];
    set_fields(f, duct_fn, &l);
}

void fluid_init_from_config(fluid_t *f, cfg_t *cfg)
{
    const grid_t *g = f->g;
    int init = cfg_enum(cfg, "fluid", "init");
    int allper = 1;
    for (int d = 0; d < g->dim; d++) allper &= g->periodic[d];
    for (int c = 0; c < fluid_ncomp(g); c++) field_zero(g, f->u[c]);
    field_zero(g, f->p);
    switch (init) {
    case 0: break;
    case 1: {
        if (g->geom == GEOM_AXI) cfg_fail(cfg, "fluid", "init", "taylor_green needs a Cartesian (2d or 3d) grid");
        if (!allper) cfg_fail(cfg, "fluid", "init", "taylor_green needs periodic boundaries in every direction");
        tgv_t t = {.U = cfg_double(cfg, "fluid", "init_velocity"), .dim = g->dim};
        for (int d = 0; d < 3; d++) t.k[d] = 2 * M_PI / g->L[d];
        set_fields(f, tgv_fn, &t);
        break;
    }
    case 2: {
        if (g->dim != 3 || !allper) cfg_fail(cfg, "fluid", "init", "abc needs a triply periodic 3d grid");
        if (fabs(g->L[1] - g->L[0]) > 1e-12 * g->L[0] || fabs(g->L[2] - g->L[0]) > 1e-12 * g->L[0])
            cfg_fail(cfg, "domain", "length", "abc needs a cubic box (one wavenumber 2π/L in every direction)");
        double abc[3];
        cfg_vec3(cfg, "fluid", "init_abc", abc);
        abc_t a = {abc[0], abc[1], abc[2], 2 * M_PI / g->L[0]};
        set_fields(f, abc_fn, &a);
        break;
    }
    case 3: {
        int walled = 0;
        for (int d = 0; d < g->dim; d++) walled += !g->periodic[d];
        if (walled == 2 && g->dim == 3) {
            init_duct(f, cfg);
            break;
        }
        laminar_t l = {.dw = -1, .axi = g->geom == GEOM_AXI, .nu = f->prm.nu};
        for (int d = 0; d < g->dim; d++)
            if (!g->periodic[d]) {
                if (l.dw >= 0)
                    cfg_fail(cfg, "fluid", "init",
                             "laminar needs one wall-bounded direction, or two in a 3d duct (%c and %c have walls)",
                             "xyz"[l.dw], "xyz"[d]);
                l.dw = d;
            }
        if (l.dw < 0) cfg_fail(cfg, "fluid", "init", "laminar needs one wall-bounded direction (all are periodic)");
        for (int s = l.axi ? 1 : 0; s < 2; s++)
            if (g->bc.type[l.dw][s] != BC_NOSLIP)
                cfg_fail(cfg, "fluid", "init", "laminar needs no-slip walls on both %c faces", "xyz"[l.dw]);
        l.H = g->L[l.dw];
        l.s0 = g->x0[l.dw];
        for (int c = 0; c < 3; c++) {
            l.ulo[c] = g->bc.vel[l.dw][0][c];
            l.uhi[c] = g->bc.vel[l.dw][1][c];
            l.f[c] = f->prm.body_force[c];
        }
        set_fields(f, laminar_fn, &l);
        break;
    }
    }
    fluid_project(f);
    fluid_fill_pressure_ghosts(f, f->p);
    f->diag.ke = fluid_kinetic_energy(f);
}
