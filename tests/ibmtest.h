/* ibmtest.h — helpers shared by the immersed-boundary tests (test_ibm_*.c). */
#ifndef IBMDEM_IBMTEST_H
#define IBMDEM_IBMTEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "fluid.h"
#include "grid.h"
#include "ibm.h"
#include "util.h"

typedef struct {
    cfg_t *cfg;
    grid_t *g;
    fluid_t *f;
    ibm_t *ibm;
} it_case_t;

/* Build grid, fluid and immersed boundary from a case-file text (the
 * user's path: schema, checks, initial condition).  Stops the program on
 * an input error. */
static inline it_case_t it_from_case(const char *text)
{
    it_case_t c;
    c.cfg = cfg_load_string("test.ini", text, 0, NULL);
    if (!c.cfg) die("test case rejected:\n%s", text);
    c.g = grid_create_from_config(c.cfg, MPI_COMM_WORLD);
    fluid_params_t prm;
    fluid_params_from_config(c.cfg, c.g, &prm);
    c.f = fluid_create(c.g, &prm);
    fluid_init_from_config(c.f, c.cfg);
    c.ibm = ibm_create_from_config(c.cfg, c.f);
    return c;
}

static inline void it_free(it_case_t *c)
{
    ibm_free(c->ibm);
    fluid_free(c->f);
    grid_free(c->g);
    cfg_free(c->cfg);
}

/* Σ u_c V over the unknowns of component c (the whole volume in
 * axisymmetric geometry, 2π included), divided by the domain volume: the
 * superficial (volume-averaged) velocity. */
static inline double it_mean_velocity(const fluid_t *f, int c)
{
    const grid_t *g = f->g;
    double s = 0.0;
    int nu0 = g->n[0] - (c == 0 && !g->periodic[0] ? 1 : 0) - g->ix0;
    int iend = nu0 < g->nxl ? nu0 : g->nxl;
    int nj = g->n[1] - (c == 1 && !g->periodic[1] ? 1 : 0), nk = g->n[2] - (c == 2 && !g->periodic[2] ? 1 : 0);
    for (int i = 0; i < iend; i++)
        for (int j = 0; j < nj; j++)
            for (int k = 0; k < nk; k++) s += f->u[c][G_IDX(g, i, j, k)] * fluid_cell_volume(f, c, i);
    s = grid_sum(g, s);
    double vol = g->L[0] * g->L[1] * (g->dim == 3 ? g->L[2] : 1.0);
    if (g->geom == GEOM_AXI) vol = 0.5 * g->L[0] * g->L[0] * g->L[1]; /* per radian: ∫ r dr dz */
    return s / vol;
}

/* Schiller–Naumann terminal velocity of a sphere of diameter D under its
 * immersed weight: C_D(Re) (π D²/8) ρ u² = (ρ_p − ρ) (π D³/6) g, with
 * C_D = 24/Re (1 + 0.15 Re^0.687) (Clift, Grace & Weber 1978, p. 111). */
static inline double it_schiller_naumann(double D, double rho_ratio, double g, double nu)
{
    double lo = 1e-6, hi = 1e3;
    for (int it = 0; it < 200; it++) {
        double u = 0.5 * (lo + hi), Re = u * D / nu;
        double cd = 24.0 / Re * (1.0 + 0.15 * pow(Re, 0.687));
        if (cd * M_PI * D * D / 8.0 * u * u > fabs(rho_ratio - 1.0) * M_PI * D * D * D / 6.0 * g)
            hi = u;
        else
            lo = u;
    }
    return 0.5 * (lo + hi);
}

/* Least-squares fit of y ≈ Σ_r x_r f_r(t) with three basis functions
 * given at each sample as f[3*i + r]; returns the coefficients in x. */
static inline void it_lsq3(int n, const double *f, const double *y, double x[3])
{
    double A[3][3] = {{0}}, b[3] = {0};
    for (int i = 0; i < n; i++)
        for (int r = 0; r < 3; r++) {
            b[r] += f[3 * i + r] * y[i];
            for (int c = 0; c < 3; c++) A[r][c] += f[3 * i + r] * f[3 * i + c];
        }
    /* Gaussian elimination (3 × 3, symmetric positive definite) */
    for (int k = 0; k < 3; k++)
        for (int r = k + 1; r < 3; r++) {
            double m = A[r][k] / A[k][k];
            for (int c = k; c < 3; c++) A[r][c] -= m * A[k][c];
            b[r] -= m * b[k];
        }
    for (int r = 2; r >= 0; r--) {
        x[r] = b[r];
        for (int c = r + 1; c < 3; c++) x[r] -= A[r][c] * x[c];
        x[r] /= A[r][r];
    }
}

#endif
