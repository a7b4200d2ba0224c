/* clear.c — the clear fluid outside a packing that does not fill the box
 * (porenet.clear_fluid_radius, docs/theory.md §8): which tetrahedra are clear
 * fluid, and the pore of the box that stands for a neighbour across a narrow
 * period. */
#include <math.h>
#include <stdlib.h>

#include "porenet.h"
#include "porenet_internal.h"

/* The clear fluid (dom->clear_h): the tetrahedra whose power radius exceeds
 * clear_h (they are orthogonal to a sphere that could hold a grain: outside
 * the packing, the α-shape criterion), connected through such tetrahedra to
 * the rim of the triangulated cloud (a facet without a neighbour): the clear
 * fluid above and ahead of a packing reaches the rim (no images beyond the
 * packing's free surface), a large void enclosed in the packing does not and
 * stays a pore. */
void pn_mark_clear(const pn_domain_t *dom, pn_tri_t *t)
{
    if (!(dom->clear_h > 0)) return;
    const int nt = t->ntet;
    unsigned char *big = malloc((size_t)nt + 1);
    int *stack = malloc(((size_t)nt + 1) * sizeof *stack), ns = 0;
    t->clear = calloc((size_t)nt + 1, 1);
    for (int k = 0; k < nt; k++) {
        const int v = t->tet[4 * k];
        const double *P = t->P + 3 * k, *c = t->x + 3 * (size_t)v;
        const double w = (P[0] - c[0]) * (P[0] - c[0]) + (P[1] - c[1]) * (P[1] - c[1]) + (P[2] - c[2]) * (P[2] - c[2]) -
                         t->r[v] * t->r[v];
        big[k] = w > dom->clear_h * dom->clear_h;
    }
    for (int k = 0; k < nt; k++) {
        if (!big[k]) continue;
        int rim = 0;
        for (int f = 0; f < 4; f++) rim |= t->nbr[4 * k + f] < 0;
        if (rim) t->clear[k] = 1, stack[ns++] = k;
    }
    while (ns > 0) {
        const int k = stack[--ns];
        for (int f = 0; f < 4; f++) {
            const int u = t->nbr[4 * k + f];
            if (u >= 0 && big[u] && !t->clear[u]) t->clear[u] = 1, stack[ns++] = u;
        }
    }
    free(big);
    free(stack);
}

int pn_nearest_pore(const pn_domain_t *dom, const double *cP, const int *root, int np, int skip, const double P[3])
{
    double q[3], best = INFINITY;
    int pj = -1;
    for (int a = 0; a < 3; a++) {
        q[a] = P[a];
        if (dom->periodic[a]) {
            const double L = dom->hi[a] - dom->lo[a];
            q[a] -= L * floor((q[a] - dom->lo[a]) / L);
        }
    }
    for (int pk = 0; pk < np; pk++) {
        const double *c = cP + 3 * root[pk];
        const double d2 = (c[0] - q[0]) * (c[0] - q[0]) + (c[1] - q[1]) * (c[1] - q[1]) + (c[2] - q[2]) * (c[2] - q[2]);
        if (d2 < best && pk != skip) best = d2, pj = pk;
    }
    return pj;
}
