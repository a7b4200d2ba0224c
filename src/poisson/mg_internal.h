/* mg_internal.h — the multigrid solver's levels and the functions its files
 * share: multigrid.c (hierarchy, coarsest level, V-cycle, solve), mg_smooth.c
 * (red-black point and zebra x-line relaxation, residual), mg_transfer.c
 * (restriction, prolongation and their set-up).  The method is described at
 * the top of multigrid.c. */
#ifndef IBMDEM_MG_INTERNAL_H
#define IBMDEM_MG_INTERNAL_H

#include "poisson.h"

#define MG_GATHER_CELLS 4096 /* levels at most this large (16³) live on rank 0 alone */
#define MG_ANISOTROPY 1.5     /* halve a direction if its spacing ≤ 1.5 × the smallest one */
#define MG_COARSE_TOL 1e-8    /* coarsest-level CG: residual reduction */

enum { LINK_NONE = 0, LINK_COARSEN, LINK_GATHER };

/* One row of a 1-D transfer operator: up to 4 (index, weight) pairs. */
typedef struct {
    int n;
    int idx[4];
    double w[4];
} mg_row_t;

typedef struct {
    grid_t *g;      /* NULL on ranks that take no part in this level */
    poisson_t *op;  /* L on this level (level 0: the caller's) */
    int own;        /* g and op belong to the hierarchy */
    double *x, *r;  /* solution/correction and residual */
    const double *b;
    double *bbuf;   /* storage of b on coarse levels */
    double *dgy, *dgz; /* y and z parts of the diagonal of L, BC folded (index j, k) */
    double *rowbuf;    /* one row of the smoother */
    double *zbuf;      /* prolongation: coarse rows interpolated along z */
    /* link to the next level */
    int link, coarsen[3];
    mg_row_t *rst[3]; /* restriction rows, indexed by the coarse (local) index */
    mg_row_t *prl[3]; /* prolongation rows, indexed by the fine (local) index */
    /* coarsest level: CG work fields */
    double *cg_z, *cg_d, *cg_q;
    /* gather link: packing buffers */
    double *pack, *gathered;
    struct mg_line *line; /* x-line relaxation data, NULL for point smoothing */
} mg_level_t;

typedef struct {
    int nlev;
    mg_level_t *lev;
    double *bcopy; /* copy of b when it aliases x */
} mg_t;

/* Unknowns of a level along d. */
static inline int level_nu(const mg_level_t *L, int d) { return L->op->nu[d]; }

/* Number of local x unknowns of a level (the last rank may own one less). */
static inline int local_nux(const mg_level_t *L)
{
    int n = L->op->nu[0] - L->g->ix0;
    return n < L->g->nxl ? n : L->g->nxl;
}

/* smoothing and residual (mg_smooth.c) */
void mg_line_setup(mg_level_t *L);
void mg_line_free(struct mg_line *ln);
void mg_smooth(mg_level_t *L, double lambda);
double mg_residual(mg_level_t *L, double lambda, const double *x, double *r);

/* transfers between levels (mg_transfer.c) */
void mg_restrict_residual(mg_level_t *F, mg_level_t *C);
void mg_prolong_add(mg_level_t *F, mg_level_t *C);
void mg_gather_level(mg_level_t *F, mg_level_t *C, const double *src, double *dst);
void mg_scatter_add_level(mg_level_t *F, mg_level_t *C, const double *src, double *dst);
void mg_build_transfer(mg_level_t *F, mg_level_t *C, int d, int adjoint);

#endif
