/* probes.h — values of the fluid fields at given points (pressure probes).
 *
 * A probe is a point of the domain.  Its value of a cell-centred field is the
 * trilinear (2-D: bilinear) interpolation between the eight (four) cell
 * centres around it.  Across a periodic face the stencil wraps to the cells
 * of the other side; between a wall and the first cell centre it takes the
 * value of that centre (constant across the half cell: the zero normal
 * gradient of the pressure at a wall).  The velocity of a probe is the same
 * interpolation of the velocity at cell centres, each component the mean of
 * the two faces of the cell.
 *
 * The interpolation is a weighted sum of cell values: each rank adds the
 * terms of the cells it owns and a sum over the ranks gives the values, so
 * a probe on the boundary between two slabs needs no ghost layer and any
 * decomposition gives the same values to round-off.  Linear fields are
 * reproduced exactly between the outermost cell centres.
 */
#ifndef IBMDEM_PROBES_H
#define IBMDEM_PROBES_H

#include "grid.h"

typedef struct probes probes_t;

/* Stencils of n points pts[3n] on the grid g (collective: no communication,
 * but every rank must give the same points).  Returns NULL with the index of
 * the first point outside the domain in *bad (a point on a face is inside);
 * in 2-D the third coordinate is not used. */
probes_t *probes_create(const grid_t *g, int n, const double *pts, int *bad);
int probes_count(const probes_t *pr);
/* Collective: out[i] = the interpolated cell-centred field f at point i. */
void probes_eval_cell(const probes_t *pr, const double *f, double *out);
/* Collective: out[i*dim + c] = component c of the velocity at point i, from
 * the face velocities u[c] (c < g->dim; their ghost faces valid, as after a
 * fluid step or fluid_apply_bc). */
void probes_eval_velocity(const probes_t *pr, double *const u[3], double *out);
void probes_free(probes_t *pr);

#endif
