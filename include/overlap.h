/* overlap.h — overlapping spheres in a box: the check of a scene's initial
 * geometry (DEM particles, immersed spheres) and of free immersed spheres
 * meeting while a run goes on.  Cell lists: O(n) for n spheres of similar
 * sizes; the minimum image along periodic directions. */
#ifndef IBMDEM_OVERLAP_H
#define IBMDEM_OVERLAP_H

typedef struct {
    double lo[3], L[3]; /* the box */
    int periodic[3];
    int dim;            /* 2: discs in the x-y plane (z is ignored); 3: spheres */
} overlap_box_t;

/* The pair (i < j) with the smallest i, then the smallest j, whose overlap
 * depth δ = r_i + r_j − |x_i − x_j| exceeds `frac` × 2 min(r_i, r_j) (frac = 0:
 * any overlap).  Pairs where neither sphere has active[] set are skipped
 * (active may be NULL: every pair counts).  Returns 1 and fills *pi, *pj and
 * *depth (δ) if there is one, 0 if not.  x holds 3 finite values per sphere;
 * centres outside the box count as on its nearest face. */
int overlap_find(const overlap_box_t *box, int n, const double *x, const double *r, const unsigned char *active,
                 double frac, int *pi, int *pj, double *depth);

#endif
