/* poisson.h — elliptic solves on the MAC grid: the pressure Poisson problem
 * and the Helmholtz problems of the implicit (Crank–Nicolson) viscous term.
 *
 * Every solve is   (L − λ I) x = b   on the interior unknowns of one variable
 * location, where L is the discrete Laplacian defined ONCE, in
 * poisson_apply() (src/poisson/poisson.c), with homogeneous boundary
 * conditions derived from the grid's faces:
 *
 *   location      periodic   no-slip wall          free-slip wall   axis (r = 0)
 *   VAR_P         periodic   Neumann               Neumann          r-weighted flux = 0
 *   normal comp.  periodic   Dirichlet on the face (unknown lies on the boundary: 0)  u_r = 0
 *   tangential    periodic   Dirichlet (ghost = −interior)  Neumann  Neumann (r-weighted)
 *
 * For VAR_P, L = D·G, the divergence of the gradient used by the projection,
 * so a projected field is divergence-free to round-off.  For velocity
 * components, L is the vector Laplacian (axisymmetric u_r: ∂r[(1/r)∂r(r u_r)],
 * which equals (1/r)∂r(r∂r u_r) − u_r/r² and stays second order at the axis).
 * The fluid adds the inhomogeneous wall values to b itself.
 *
 * Methods (chosen in the case file, [poisson] method): "fft" — eigenfunction
 * expansion with FFTW real transforms in y and z and tridiagonal solves in x;
 * "multigrid" — geometric V-cycles on the same operator.
 */
#ifndef IBMDEM_POISSON_H
#define IBMDEM_POISSON_H

#include "config.h"
#include "grid.h"

typedef enum { POISSON_FFT = 0, POISSON_MG = 1 } poisson_method_t;
typedef enum { VAR_P = -1, VAR_U = 0, VAR_V = 1, VAR_W = 2 } var_loc_t;

/* Homogeneous boundary type of one face for one variable location. */
typedef enum { EBC_PERIODIC = 0, EBC_NEUMANN, EBC_DIRICHLET_FACE, EBC_DIRICHLET_GHOST } ebc_t;

typedef struct {
    poisson_method_t method;
    double mg_tol;     /* multigrid: relative residual tolerance */
    int mg_max_cycles; /* multigrid: maximum V-cycles */
    int mg_pre, mg_post; /* multigrid: smoothing sweeps */
    int fftw_measure;    /* fft: plan with FFTW_MEASURE, reproducibly through FFTW wisdom (fft.c) */
    char fftw_wisdom[4096]; /* fft, measure: wisdom file read before planning, written when it grows ("" none) */
} poisson_opts_t;

typedef struct poisson poisson_t;

/* Solver back-end: a method implements these (fft.c, multigrid.c). */
typedef struct {
    void *(*create)(poisson_t *p);
    int (*solve)(poisson_t *p, void *impl, double lambda, const double *b, double *x);
    void (*destroy)(void *impl);
} poisson_backend_t;

struct poisson {
    const grid_t *g;
    var_loc_t loc;
    poisson_opts_t opt;
    ebc_t ebc[3][2];      /* homogeneous BC of each face for this location */
    int nu[3];            /* global number of unknowns in each direction: indices 0..nu-1
                           * (a Dirichlet face on the low side is the ghost index −1, on the
                           * high side the index n−1, so it is never an unknown) */
    int singular;         /* λ = 0 has a constant null space (all faces periodic/Neumann) */
    /* x part of L (global, stretched/axisymmetric metric included):
     *   (L_x x)_i = cw[i] x[i−1] + ce[i] x[i+1] − cd[i] x[i],  i = 0..nu[0]−1.
     * At a non-periodic end the outer coefficient is 0 and the boundary
     * condition is folded into cd; at a periodic end x[−1] ≡ x[nu−1]. */
    double *cw, *ce, *cd;
    /* y and z parts: uniform 3-point stencils (x[j+1] − 2x[j] + x[j−1])/dy²
     * with the homogeneous BC applied through the ghosts. */
    double cy, cz;        /* 1/dy², 1/dz² (cz = 0 in 2-D) */
    const poisson_backend_t *backend;
    void *impl;
    /* set by a back-end's create() when its solve() handles a singular
     * problem (λ = 0, no Dirichlet face) itself: it removes the weighted mean
     * of b and returns x of zero weighted mean, so poisson_solve need not
     * copy b (otherwise poisson_solve does it around the back-end) */
    int backend_handles_singular;
    double *rhs_scratch;  /* compatible copy of b for singular solves, allocated on first use */
    /* statistics of the last solve */
    double last_residual; /* relative residual ||b − A x|| / ||b|| (measured), or −1 when the
                           * method does not measure it (the direct solver: round-off by
                           * construction, measured by its tests; one more operator
                           * application costs 15 % of its solve at 128³, measured) */
    int last_iterations;  /* V-cycles (multigrid) or 1 (direct) */
};

void poisson_register_keys(void);
void poisson_opts_from_config(cfg_t *cfg, poisson_opts_t *o);

poisson_t *poisson_create(const grid_t *g, var_loc_t loc, const poisson_opts_t *opt);
/* The operator alone, without a solver back-end: poisson_apply and
 * poisson_fill_ghosts work, poisson_solve does not (explicit viscous term). */
poisson_t *poisson_create_operator(const grid_t *g, var_loc_t loc);
/* Give an operator its solver back-end (as poisson_create does; nothing if it has one). */
void poisson_add_solver(poisson_t *p, const poisson_opts_t *opt);
void poisson_free(poisson_t *p);

/* Solve (L − λI) x = b.  b and x are fields of the grid (x may equal b);
 * only interior unknowns of b are read and of x written (a Dirichlet-face
 * boundary value of x is set to 0).  For a singular problem (λ = 0, no
 * Dirichlet face) the mean of b is removed first and x has zero mean.
 * Returns 0, or −1 if an iterative method did not converge. */
int poisson_solve(poisson_t *p, double lambda, const double *b, double *x);

/* The solve in two parts, for a caller that reads x plane by plane
 * (available when poisson_solve_by_planes: the FFT solver on one rank with
 * the transforms by planes, y and z each periodic or Neumann):
 * poisson_solve_begin(p, λ, b) does all but writing x;
 * poisson_solve_plane(p, x, i) then writes the unknowns of x
 * plane i (every plane once, before the next solve).  Bit-identical to
 * poisson_solve; the ghosts of x are not touched. */
int poisson_solve_by_planes(const poisson_t *p);
void poisson_solve_begin(poisson_t *p, double lambda, const double *b);
void poisson_solve_plane(poisson_t *p, double *x, int i);
/* The forward transform of plane i of b done ahead of the solve (same
 * availability), by the writer of b once that plane is final: the next
 * solve with that b skips it.  Bit-identical. */
void poisson_forward_plane(poisson_t *p, const double *b, int i);

/* y = (L − λI) x on the interior unknowns.  Fills the ghosts of x first
 * (halo exchange + homogeneous BC), so x is modified in its ghosts only. */
void poisson_apply(poisson_t *p, double lambda, double *x, double *y);

/* Fill the ghosts of x with the homogeneous BCs of this location (after a
 * halo exchange). */
void poisson_fill_ghosts(const poisson_t *p, double *x);
/* The same in two parts, for a field whose x planes become final one after
 * another: the ghosts of the edge planes (0 and nxl−1: their y/z ghosts, the
 * x halo, the ghost planes), then those of an inner plane i (1..nxl−2,
 * which no other plane's ghosts read).  Together they set every ghost to
 * the value poisson_fill_ghosts gives. */
void poisson_fill_ghosts_edges(const poisson_t *p, double *x);
void poisson_fill_ghosts_plane(const poisson_t *p, double *x, int i);

/* Is (i,j,k) (local) an unknown of this location? */
int poisson_is_unknown(const poisson_t *p, int i, int j, int k);

/* Weight of the x unknown ig (global) in the volume-weighted inner product
 * for which L is symmetric: Σ w (L x) = 0 for every x when L is singular. */
double poisson_x_weight(const poisson_t *p, int ig);
/* Weighted mean of the unknowns of f (global), and f += c on the unknowns. */
double poisson_weighted_mean(const poisson_t *p, const double *f);
void poisson_add_constant(const poisson_t *p, double *f, double c);

/* Relative residual ||b − (L − λI)x||₂ / ||b||₂ over the unknowns (uses a
 * scratch field; for tests and diagnostics). */
double poisson_residual(poisson_t *p, double lambda, const double *b, double *x);

/* FFTW wisdom of the measuring planner (fft back-end, fftw_planner = measure;
 * see fft.c).  preset: wisdom imported instead of the file before the next
 * measured set-up (a restart passes the checkpoint's copy; NULL clears).
 * used: the wisdom the measured plans were made from, the same on every rank
 * (NULL before any measured set-up); the checkpoints store it.  check: 0 if
 * path is usable (an existing file holds wisdom of this FFTW build, or the
 * folder of a missing one is writable), else 1 with the reason in why. */
void poisson_fftw_wisdom_preset(const char *wisdom);
const char *poisson_fftw_wisdom_used(void);
int poisson_fftw_wisdom_check(const char *path, char *why, size_t n);

/* Back-ends */
extern const poisson_backend_t poisson_backend_fft;
extern const poisson_backend_t poisson_backend_mg;

#endif
