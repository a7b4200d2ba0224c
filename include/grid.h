/* grid.h — the staggered (MAC) grid, its decomposition among MPI ranks,
 * field storage and halo exchange.
 *
 * Conventions (every module relies on them):
 *  - Three index directions x, y, z (0, 1, 2).  2-D runs have nz = 1 and no
 *    ghost layer in z.  Axisymmetric runs are 2-D with x = r (axis at x = 0)
 *    and y = the axial coordinate.
 *  - x is the only direction that may be stretched, and the direction along
 *    which the ranks split the grid into slabs (nx must divide by the rank
 *    count).  The FFT Poisson solver transforms in y and z and solves
 *    tridiagonal systems in x.
 *  - Cell (i,j,k) has its centre at (xc[i], y0+(j+½)dy, z0+(k+½)dz).
 *    u(i,j,k) lives on the face x = xf[i] (right face of cell i), v(i,j,k) on
 *    y = y0+(j+1)dy, w(i,j,k) on z = z0+(k+1)dz: the face index is that of the
 *    cell on its low side, as in CaNS.  So at a wall on the low x side the
 *    boundary value of u is u(-1,...), on the high side u(nx-1,...).
 *  - Storage: one ghost layer in x and y, gz (1 in 3-D, 0 in 2-D) in z;
 *    k is the fastest index.  Local indices i = -1..nxl, j = -1..ny,
 *    k = -gz..nz-1+gz.  Use G_IDX.
 */
#ifndef IBMDEM_GRID_H
#define IBMDEM_GRID_H

#include <mpi.h>

#include "config.h"

typedef enum { GEOM_3D = 0, GEOM_2D = 1, GEOM_AXI = 2 } geom_t;
typedef enum { BC_PERIODIC = 0, BC_NOSLIP = 1, BC_FREESLIP = 2, BC_AXIS = 3 } bc_type_t;
typedef enum { STRETCH_UNIFORM = 0, STRETCH_TANH_LOW, STRETCH_TANH_HIGH, STRETCH_TANH_BOTH, STRETCH_UNIFORM_ARITHMETIC } stretch_t;

typedef struct {
    bc_type_t type[3][2]; /* [direction][0 = low face, 1 = high face] */
    double vel[3][2][3];  /* wall velocity (u, v, w) of a no-slip wall */
} bc_t;

typedef struct grid {
    geom_t geom;
    int dim;          /* 3, or 2 for planar and axisymmetric */
    int n[3];         /* global cells */
    double L[3];      /* domain size */
    double x0[3];     /* origin (low corner) */
    int periodic[3];
    bc_t bc;
    stretch_t stretch;
    double stretch_beta;
    int stretch_uniform_cells;     /* uniform_arithmetic: cells of the uniform part from the low face */
    double stretch_uniform_length; /* ... and its length */

    /* decomposition: slabs in x */
    MPI_Comm comm;
    int rank, nranks;
    int nxl, ix0;     /* local cells in x and the global index of the first one */
    int left, right;  /* neighbour ranks in x, MPI_PROC_NULL at a wall */

    /* storage */
    int gz;           /* ghost width in z */
    long sx, sy;      /* strides of i and j (stride of k is 1) */
    long nalloc;      /* doubles per field */
    long ncell_local; /* nxl*ny*nz */

    /* x geometry, local arrays valid for i = -1..nxl */
    double *xf, *xc, *dxf, *dxc;
    /* the same for the whole grid, valid for i = -1..nx */
    double *gxf, *gxc, *gdxf, *gdxc;
    double dy, dz;
} grid_t;

#define G_IDX(g, i, j, k) (((long)(i) + 1) * (g)->sx + ((long)(j) + 1) * (g)->sy + (long)(k) + (g)->gz)

/* Schema of [domain] and [boundary]; called once before cfg_load. */
void grid_register_keys(void);

/* Read and validate [domain] and [boundary] (stops with file:line: key:
 * reason on bad input), then build the grid on `comm`. */
grid_t *grid_create_from_config(cfg_t *cfg, MPI_Comm comm);

/* Build a grid directly (tests).  bc may be NULL for all-periodic.  For
 * GEOM_2D/GEOM_AXI, n[2] must be 1. */
grid_t *grid_create(geom_t geom, const int n[3], const double L[3], const double x0[3], const bc_t *bc,
                    stretch_t stretch, double beta, MPI_Comm comm);
/* The same with the uniform_arithmetic spacing in x: nu cells of size lu/nu
 * from the low face, then sizes growing in arithmetic progression (Izard's
 * bouncing-sphere grid, §2.6 of the reference notes). */
grid_t *grid_create_uniform_arithmetic(geom_t geom, const int n[3], const double L[3], const double x0[3], const bc_t *bc,
                                       int nu, double lu, MPI_Comm comm);
void grid_free(grid_t *g);
/* The smallest cell size of the grid, over every direction. */
double grid_min_spacing(const grid_t *g);

double *field_alloc(const grid_t *g);
void field_copy(const grid_t *g, double *dst, const double *src);
void field_zero(const grid_t *g, double *f);

/* Halo exchange of one field: periodic copies in y and z, then the x planes
 * (ghosts included) with the neighbour ranks / periodic image.  Ghosts at a
 * non-periodic face are left for the boundary conditions. */
void grid_halo_yz(const grid_t *g, double *f);
/* the periodic y/z copies of the x planes ilo..ihi only (each plane's
 * ghosts come from the same plane) */
void grid_halo_yz_planes(const grid_t *g, double *f, int ilo, int ihi);
void grid_halo_x(const grid_t *g, double *f);
void grid_halo(const grid_t *g, double *f);

/* Global reductions over the grid's communicator. */
double grid_sum(const grid_t *g, double v);
double grid_max(const grid_t *g, double v);
double grid_min(const grid_t *g, double v);

/* Coordinates */
static inline double grid_yc(const grid_t *g, int j) { return g->x0[1] + (j + 0.5) * g->dy; }
static inline double grid_yf(const grid_t *g, int j) { return g->x0[1] + (j + 1.0) * g->dy; }
static inline double grid_zc(const grid_t *g, int k) { return g->x0[2] + (k + 0.5) * g->dz; }
static inline double grid_zf(const grid_t *g, int k) { return g->x0[2] + (k + 1.0) * g->dz; }

/* Cell volume (axisymmetric: per radian, r dr dz). */
double grid_cell_volume(const grid_t *g, int i);

#endif
