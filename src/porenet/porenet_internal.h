/* porenet_internal.h — helpers shared by the files of src/porenet/. */
#ifndef IBMDEM_PORENET_INTERNAL_H
#define IBMDEM_PORENET_INTERNAL_H
#include <stddef.h>
/* Write the reason into err (vsnprintf) and return -1. */
int pn_fail(char *err, size_t nerr, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* CGAL's regular triangulation of np weighted points (x: 3 np, r: np; weights r²)
 * (regular_cgal.cpp): the finite tetrahedra (4 point indices each), their
 * neighbours (the tetrahedron opposite vertex k, −1 on the hull) and power
 * centres, malloc'd.  0, or −1 with err. */
int pn_cgal_regular(int np, const double *x, const double *r, int *ntet, int **tet, int **nbr, double **P, char *err,
                    size_t nerr);
/* A fill-reducing ordering of n unknowns with positions xyz (3 n) and
 * adjacency rp/ci (CSR, both directions): geometric nested dissection
 * (ordering.c); perm[k] = the unknown eliminated k-th. */
void pn_order_nested_dissection(int n, const int *rp, const int *ci, const double *xyz, int *perm);
#endif
