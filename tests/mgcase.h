/* mgcase.h — manufactured solutions of (L − λI)u = b for every variable
 * location, boundary combination and geometry (tests/test_poisson_mg.c and
 * bench/bench_mg.c).
 *
 * u = f_x(x) f_y(y) f_z(z), each factor cos(k t + φ) of t = (s − s0)/L_d,
 * chosen from the homogeneous BCs the solver derived for the location
 * (p->ebc), so that u satisfies them exactly:
 *   periodic: k = 2π, φ = 0.3          Neumann/Neumann: cos(πt)
 *   Dirichlet/Dirichlet: sin(πt)       Neumann/Dirichlet: cos(πt/2)
 *   Dirichlet/Neumann: sin(πt/2)
 * (Dirichlet = on the face or through the ghost).  In axisymmetric geometry
 * x = r and the axis is Neumann for scalars (even cos) and Dirichlet for u_r
 * (odd sin); the r part of the Laplacian is f'' + f'/r for scalars and
 * f'' + f'/r − f/r² for u_r. */
#ifndef IBMDEM_MGCASE_H
#define IBMDEM_MGCASE_H

#include <math.h>
#include <stdlib.h>

#include "grid.h"
#include "poisson.h"

typedef struct {
    double k[3], phi[3];
} mms_t;

static inline void mms_from_bc(const poisson_t *p, mms_t *m)
{
    for (int d = 0; d < 3; d++) {
        ebc_t lo = p->ebc[d][0], hi = p->ebc[d][1];
        int dlo = lo == EBC_DIRICHLET_FACE || lo == EBC_DIRICHLET_GHOST;
        int dhi = hi == EBC_DIRICHLET_FACE || hi == EBC_DIRICHLET_GHOST;
        if (d >= p->g->dim) {
            m->k[d] = 0.0;
            m->phi[d] = 0.0;
        } else if (lo == EBC_PERIODIC) {
            m->k[d] = 2.0 * M_PI;
            m->phi[d] = 0.3;
        } else {
            m->k[d] = dlo == dhi ? M_PI : 0.5 * M_PI;
            m->phi[d] = dlo ? -0.5 * M_PI : 0.0;
        }
    }
}

/* Position of unknown (i, j, k) (local) of location loc along d. */
static inline double mms_pos(const grid_t *g, var_loc_t loc, int d, int i)
{
    int face = (int)loc == d;
    if (d == 0) return face ? g->xf[i] : g->xc[i];
    if (d == 1) return face ? grid_yf(g, i) : grid_yc(g, i);
    return face ? grid_zf(g, i) : grid_zc(g, i);
}

/* Fill u (exact solution) and b = (L − λI)u on the unknowns. */
static inline void mms_fill(const poisson_t *p, double lambda, double *u, double *b)
{
    const grid_t *g = p->g;
    mms_t m;
    mms_from_bc(p, &m);
    int axi = g->geom == GEOM_AXI;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                long c = G_IDX(g, i, j, k);
                if (!poisson_is_unknown(p, i, j, k)) {
                    u[c] = b[c] = 0.0;
                    continue;
                }
                int idx[3] = {i, j, k};
                double f[3], lap[3];
                for (int d = 0; d < 3; d++) {
                    double s = mms_pos(g, p->loc, d, idx[d]), kk = m.k[d] / g->L[d];
                    double a = kk * (s - g->x0[d]) + m.phi[d];
                    f[d] = cos(a);
                    lap[d] = -kk * kk * cos(a);
                    if (d == 0 && axi) {
                        lap[0] += -kk * sin(a) / s;
                        if (p->loc == VAR_U) lap[0] -= f[0] / (s * s);
                    }
                }
                u[c] = f[0] * f[1] * f[2];
                b[c] = lap[0] * f[1] * f[2] + f[0] * lap[1] * f[2] + f[0] * f[1] * lap[2] - lambda * u[c];
            }
}

/* max |x − u| / max |u| over the unknowns; for a singular problem both
 * are compared with their weighted means removed. */
static inline double mms_error(poisson_t *p, double lambda, const double *x, double *u)
{
    const grid_t *g = p->g;
    double mx = 0.0, mu = 0.0;
    if (p->singular && lambda == 0.0) {
        mx = poisson_weighted_mean(p, x);
        mu = poisson_weighted_mean(p, u);
    }
    double e = 0.0, n = 0.0;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                if (!poisson_is_unknown(p, i, j, k)) continue;
                long c = G_IDX(g, i, j, k);
                e = fmax(e, fabs((x[c] - mx) - (u[c] - mu)));
                n = fmax(n, fabs(u[c] - mu));
            }
    return grid_max(g, e) / grid_max(g, n);
}

#endif
