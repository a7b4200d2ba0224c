/* fluidtest.h — helpers shared by the fluid tests (test_fluid_*.c). */
#ifndef IBMDEM_FLUIDTEST_H
#define IBMDEM_FLUIDTEST_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "fluid.h"
#include "grid.h"
#include "util.h"

/* Solver used by the time-stepping tests: the environment variable
 * IBMDEM_TEST_POISSON=multigrid selects multigrid instead of the FFT solver. */
static inline poisson_opts_t ft_poisson_opts(void)
{
    poisson_opts_t o = {.method = POISSON_FFT, .mg_tol = 1e-12, .mg_max_cycles = 200, .mg_pre = 2, .mg_post = 2};
    const char *m = getenv("IBMDEM_TEST_POISSON");
    if (m && !strcmp(m, "multigrid")) o.method = POISSON_MG;
    return o;
}

/* Tolerance of the "exact on the grid" checks: round-off with the direct
 * FFT solver; with multigrid (relative residual 1e-12 per solve) the
 * Crank–Nicolson Helmholtz solves leave up to ~1e-11 (measured 1.4e-11 in
 * the channel tests), hence 1e-10. */
static inline double ft_exact_tol(void) { return ft_poisson_opts().method == POISSON_MG ? 1e-10 : 1e-12; }

static inline fluid_params_t ft_params(double nu, int implicit)
{
    fluid_params_t p;
    memset(&p, 0, sizeof p);
    p.nu = nu;
    p.rho = 1.0;
    p.implicit_viscous = implicit;
    p.cfl = 0.5;
    p.fourier = 0.5;
    p.poisson = ft_poisson_opts();
    return p;
}

/* Position of the unknown (i,j,k) (local i) of component c; c = −1: cell centre. */
static inline void ft_pos(const grid_t *g, int c, int i, int j, int k, double x[3])
{
    x[0] = c == 0 ? g->xf[i] : g->xc[i];
    x[1] = c == 1 ? grid_yf(g, j) : grid_yc(g, j);
    x[2] = g->dim == 3 ? (c == 2 ? grid_zf(g, k) : grid_zc(g, k)) : 0.0;
}

/* Unknown index ranges of component c (as the solver defines them). */
static inline int ft_nu(const grid_t *g, int c, int d) { return g->n[d] - (c == d && !g->periodic[d] ? 1 : 0); }
static inline int ft_iend(const grid_t *g, int c)
{
    int e = ft_nu(g, c, 0) - g->ix0;
    return e < g->nxl ? e : g->nxl;
}

#define FT_FOR_UNKNOWNS(g, c, i, j, k)                      \
    for (int i = 0; i < ft_iend(g, c); i++)                 \
        for (int j = 0; j < ft_nu(g, c, 1); j++)            \
            for (int k = 0; k < ft_nu(g, c, 2); k++)

typedef double (*ft_fn_t)(int c, const double x[3], double t, const void *ctx);

/* u[c] = fn(c, x, t) at the unknowns, then the ghosts. */
static inline void ft_set_velocity(fluid_t *f, ft_fn_t fn, double t, const void *ctx)
{
    const grid_t *g = f->g;
    double x[3];
    for (int c = 0; c < g->dim; c++) {
        field_zero(g, f->u[c]);
        FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            ft_pos(g, c, i, j, k, x);
            f->u[c][G_IDX(g, i, j, k)] = fn(c, x, t, ctx);
        }
    }
    fluid_apply_bc(f);
}

/* Max and volume-weighted RMS error of the velocity against fn at time t,
 * over every unknown of every component. */
static inline void ft_velocity_error(const fluid_t *f, ft_fn_t fn, double t, const void *ctx, double *emax,
                                     double *erms)
{
    const grid_t *g = f->g;
    double x[3], m = 0.0, s = 0.0, v = 0.0;
    for (int c = 0; c < g->dim; c++) FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            ft_pos(g, c, i, j, k, x);
            double e = f->u[c][G_IDX(g, i, j, k)] - fn(c, x, t, ctx), w = fluid_cell_volume(f, c, i);
            m = fmax(m, fabs(e));
            s += w * e * e;
            v += w;
        }
    if (emax) *emax = grid_max(g, m);
    s = grid_sum(g, s);
    v = grid_sum(g, v);
    if (erms) *erms = sqrt(s / v);
}

/* Max difference between the velocities of two solvers on the same grid. */
static inline double ft_velocity_diff(const fluid_t *a, const fluid_t *b)
{
    const grid_t *g = a->g;
    double m = 0.0;
    for (int c = 0; c < g->dim; c++) FT_FOR_UNKNOWNS(g, c, i, j, k)
        {
            long q = G_IDX(g, i, j, k);
            m = fmax(m, fabs(a->u[c][q] - b->u[c][q]));
        }
    return grid_max(g, m);
}

/* Advance to t_end with the fixed step dt (the last one shortened). */
static inline void ft_run_to(fluid_t *f, double t_end, double dt)
{
    while (f->time < t_end - 1e-12 * t_end) {
        double h = fmin(dt, t_end - f->time);
        fluid_step(f, h);
    }
}

/* Build grid and fluid from a loaded case (the user's path: schema, checks,
 * initial condition); frees cfg.  The solver is ft_poisson_opts()'s. */
static inline fluid_t *ft_from_cfg(cfg_t *cfg, grid_t **gp)
{
    grid_t *g = grid_create_from_config(cfg, MPI_COMM_WORLD);
    fluid_params_t prm;
    fluid_params_from_config(cfg, g, &prm);
    prm.poisson = ft_poisson_opts();
    fluid_t *f = fluid_create(g, &prm);
    fluid_init_from_config(f, cfg);
    cfg_free(cfg);
    *gp = g;
    return f;
}

/* The same from a case-file text.  Stops the test program on an input error. */
static inline fluid_t *ft_from_case(const char *text, grid_t **gp)
{
    cfg_t *cfg = cfg_load_string("test.ini", text, 0, NULL);
    if (!cfg) die("test case rejected");
    return ft_from_cfg(cfg, gp);
}

#endif
