/* fluid_internal.h — private state of the fluid solver, shared by the files
 * of src/fluid/ only (the public interface is include/fluid.h). */
#ifndef IBMDEM_FLUID_INTERNAL_H
#define IBMDEM_FLUID_INTERNAL_H

#include "fluid.h"

typedef struct {
    poisson_t *pp;         /* VAR_P: projection (L = D·G) */
    poisson_t *pv[3];      /* L of each velocity location: the Crank–Nicolson Helmholtz
                            * solvers when implicit, the operator alone when explicit */
    double *dudt[3];       /* explicit right-hand side of the current RK stage */
    double *dudt_old[3];   /* ... of the previous stage (the ζ term) */
    double *phi;           /* pressure correction */
    double *work;          /* scratch */
    /* metric of the local x range, index −1..nxl (stored at +1): face and
     * centre area factors (r in axisymmetric geometry, 1 otherwise) */
    double *af, *ac;
    /* coefficient of the wall ghost of a tangential component at a no-slip x
     * wall, times 2 U_wall: the inhomogeneous part of L at the first and last
     * cell (the y and z walls are handled by the ghost values themselves) */
    double xwall[3][2];
} fluid_priv_t;

static inline fluid_priv_t *fluid_priv(const fluid_t *f) { return (fluid_priv_t *)f->priv; }

/* Number of unknowns of component c along direction d (global): a wall or
 * axis face normal to c lies on index n−1 at the high side, which is a
 * boundary value, not an unknown. */
static inline int fluid_nu(const grid_t *g, int c, int d)
{
    return g->n[d] - (c == d && !g->periodic[d] ? 1 : 0);
}
/* One past the last local x index of the unknowns of component c. */
static inline int fluid_iend(const grid_t *g, int c)
{
    int e = fluid_nu(g, c, 0) - g->ix0;
    return e < g->nxl ? e : g->nxl;
}
static inline int fluid_ncomp(const grid_t *g) { return g->dim; }

/* advection.c */
void fluid_advection_add(const fluid_t *f, double scale, double *const out[3]);
/* viscous.c */
void fluid_laplacian_add(const fluid_t *f, int c, const double *u, double scale, double *out);
void fluid_wall_terms_add(const fluid_t *f, int c, double scale, double *out);
void fluid_viscous_setup(fluid_t *f);
/* bc.c */
void fluid_fill_ghosts_component(const fluid_t *f, int c, double *u);
void fluid_fill_pressure_ghosts(const fluid_t *f, double *p);
/* timestep.c: max over cells of Σ_d |u_d|/Δ_d (|u_d| the larger of the two faces) */
double fluid_convective_rate(const fluid_t *f);
/* diagnostics.c: ke, div_max, cfl of f->diag from the current field */
void fluid_update_diagnostics(fluid_t *f);
/* step.c */
void fluid_project_stage(fluid_t *f, double dt_stage, int update_pressure);

#endif
