/* alpha_gaps.c — `radius_correction = gaps`: the neighbours of each sphere
 * and the local thickening of its forced radius at a node (docs/theory.md,
 * "Narrow gaps").  The node lists of alpha.c build the neighbour lists
 * (ibm_gap_neighbours) and add ibm_gap_extra() to the radius at each node. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ibm_internal.h"
#include "util.h"

/* Append one neighbour entry (offset of its centre from sphere p's, radius,
 * distance from p's centre to its surface). */
static void gap_push(ibm_priv_t *q, long *cnt, const double off[3], double R, double dist)
{
    if (*cnt + 1 > q->cap_nb) {
        long c = q->cap_nb > 0 ? 2 * q->cap_nb : 64;
        q->nb = realloc(q->nb, (size_t)c * IBM_NB_STRIDE * sizeof *q->nb);
        if (!q->nb) die_local("immersed boundary: out of memory for %ld neighbours", c);
        q->cap_nb = c;
    }
    double *e = q->nb + IBM_NB_STRIDE * (*cnt)++;
    e[0] = off[0], e[1] = off[1], e[2] = off[2], e[3] = R, e[4] = dist - R;
}

/* Entries by their distance from the sphere's centre to their surface (then
 * by offset and radius, for a fixed order). */
static int by_surface_distance(const void *a, const void *b)
{
    const double *x = a, *y = b;
    static const int key[IBM_NB_STRIDE] = {4, 0, 1, 2, 3};
    for (int k = 0; k < IBM_NB_STRIDE; k++)
        if (x[key[k]] != y[key[k]]) return x[key[k]] < y[key[k]] ? -1 : 1;
    return 0;
}

/* The neighbour lists of ibm_priv_t (nb_head, nb) at the centres xa: for
 * sphere p, every other sphere and every periodic image (its own included)
 * whose surface may come within the cutoff of a node of p's band.  A cell
 * list: the centres binned in cells of at least the largest reach plus the
 * largest radius (along a periodic direction, a whole number of cells per
 * period, the centres wrapped into it; along another, over the centres'
 * extent), each sphere looks at the cells within its reach around its own.
 * A cell index beyond the period stands for the periodic image it wraps to,
 * so a box of fewer cells than the reach spans visits one cell several
 * times, once per image (each a different offset): O(N) per build for a
 * bed of spheres, the periodic images included.  The order of a sphere's
 * entries does not matter (ibm_gap_extra takes their minimum). */
void ibm_gap_neighbours(ibm_t *ibm)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    const int n = ibm->n;
    double hmax = fmax(g->dy, g->dz), rmax = 0.0;
    for (int i = 0; i < g->n[0]; i++) hmax = fmax(hmax, g->gdxf[i]);
    for (int p = 0; p < n; p++) rmax = fmax(rmax, ibm->s[p].radius);
    const double margin = (ibm_band_halfwidth() + IBM_GAP_MAX + 1.5) * hmax;
    if (!q->nb_head) q->nb_head = xcalloc((size_t)n + 1, sizeof *q->nb_head); /* ibm->n is fixed */
    /* the cells: side >= the largest reach + rmax; at most ~8 per sphere */
    const double span = rmax + margin + IBM_GAP_CUTOFF_D * 2.0 * rmax + rmax;
    double lo[3], ext[3], *w = xcalloc(3 * (size_t)(n > 0 ? n : 1), sizeof *w); /* centres, wrapped */
    int nc[3], *per_of = xcalloc(3 * (size_t)(n > 0 ? n : 1), sizeof *per_of); /* xa = w + per_of L */
    for (int d = 0; d < 3; d++) {
        const int per = d < g->dim && g->periodic[d];
        lo[d] = per ? g->x0[d] : INFINITY;
        double hi = per ? g->x0[d] + g->L[d] : -INFINITY;
        for (int p = 0; p < n; p++) {
            double x = ibm->s[p].xa[d];
            if (per) {
                x = g->x0[d] + fmod(x - g->x0[d], g->L[d]);
                if (x < g->x0[d]) x += g->L[d];
                if (x >= hi) x = g->x0[d];
            } else {
                lo[d] = fmin(lo[d], x);
                hi = fmax(hi, x);
            }
            w[3 * p + d] = x;
            per_of[3 * p + d] = per ? (int)lround((ibm->s[p].xa[d] - x) / g->L[d]) : 0;
        }
        ext[d] = n > 0 ? hi - lo[d] : 0.0;
    }
    double cs[3];
    for (double side = span;; side *= 1.26) { /* widened until there are at most ~8 cells per sphere */
        long tot = 1;
        for (int d = 0; d < 3; d++) {
            if (d < g->dim && g->periodic[d]) {
                nc[d] = (int)fmax(1.0, floor(g->L[d] / side));
                cs[d] = g->L[d] / nc[d];
            } else {
                nc[d] = (int)floor(ext[d] / side) + 1;
                cs[d] = side;
            }
            tot *= nc[d];
        }
        if (tot <= 8L * n + 64) break;
    }
    int *cell = xcalloc((size_t)(n > 0 ? n : 1), sizeof *cell), *next = xcalloc((size_t)(n > 0 ? n : 1), sizeof *next);
    int *head = xcalloc((size_t)nc[0] * nc[1] * nc[2], sizeof *head);
    for (long c = 0; c < (long)nc[0] * nc[1] * nc[2]; c++) head[c] = -1;
    for (int p = n - 1; p >= 0; p--) {
        int ci[3];
        for (int d = 0; d < 3; d++) {
            ci[d] = (int)floor((w[3 * p + d] - lo[d]) / cs[d]);
            if (ci[d] < 0) ci[d] = 0;
            if (ci[d] >= nc[d]) ci[d] = nc[d] - 1;
        }
        cell[p] = (ci[2] * nc[1] + ci[1]) * nc[0] + ci[0];
        next[p] = head[cell[p]];
        head[cell[p]] = p;
    }
    long cnt = 0;
    for (int p = 0; p < n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        const double reach = s->radius + margin + IBM_GAP_CUTOFF_D * 2.0 * s->radius; /* from p's centre */
        int c0[3] = {cell[p] % nc[0], (cell[p] / nc[0]) % nc[1], cell[p] / (nc[0] * nc[1])}, wd[3];
        for (int d = 0; d < 3; d++) wd[d] = (int)ceil((reach + rmax) / cs[d]);
        q->nb_head[p] = (int32_t)cnt;
        for (int k = c0[2] - wd[2]; k <= c0[2] + wd[2]; k++)
            for (int j = c0[1] - wd[1]; j <= c0[1] + wd[1]; j++)
                for (int i = c0[0] - wd[0]; i <= c0[0] + wd[0]; i++) {
                    const int ix[3] = {i, j, k};
                    int wc[3], m[3], skip = 0;
                    for (int d = 0; d < 3; d++) {
                        const int per = d < g->dim && g->periodic[d];
                        if (!per && (ix[d] < 0 || ix[d] >= nc[d])) skip = 1;
                        m[d] = per ? (int)floor((double)ix[d] / nc[d]) : 0; /* periods crossed */
                        wc[d] = ix[d] - m[d] * nc[d];
                    }
                    if (skip) continue;
                    const int self = m[0] == 0 && m[1] == 0 && m[2] == 0;
                    for (int o = head[(wc[2] * nc[1] + wc[1]) * nc[0] + wc[0]]; o >= 0; o = next[o]) {
                        if (o == p && self) continue;
                        double off[3];
                        for (int d = 0; d < 3; d++) /* from the centres themselves: whole periods added */
                            off[d] = ibm->s[o].xa[d] - ibm->s[p].xa[d] +
                                     (double)(m[d] - per_of[3 * o + d] + per_of[3 * p + d]) * g->L[d];
                        double dist = sqrt(off[0] * off[0] + off[1] * off[1] + off[2] * off[2]);
                        if (dist - ibm->s[o].radius >= reach) continue;
                        gap_push(q, &cnt, off, ibm->s[o].radius, dist);
                    }
                }
        qsort(q->nb + IBM_NB_STRIDE * q->nb_head[p], (size_t)(cnt - q->nb_head[p]), IBM_NB_STRIDE * sizeof *q->nb,
              by_surface_distance);
    }
    q->nb_head[n] = (int32_t)cnt;
    free(w);
    free(per_of);
    free(cell);
    free(head);
    free(next);
}

/* The local thickening (length) of sphere p's forced radius at offset r
 * from its centre, cell size h: ibm_gap_thickening() of the distance to
 * the nearest neighbour's surface, clamped to [0, IBM_GAP_CUTOFF_D D_p].
 * The entries come by increasing distance s from p's centre to their
 * surface, and a node at |r| is at least s − |r| from such a surface: the
 * scan stops once that bound reaches the nearest distance found (the same
 * minimum as over every entry; the bound is taken a part in 10¹² short,
 * against its rounding). */
double ibm_gap_extra(const ibm_t *ibm, int p, const double r[3], double h)
{
    const ibm_priv_t *q = ibm_priv(ibm);
    double G = IBM_GAP_CUTOFF_D * 2.0 * ibm->s[p].radius;
    const double rn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (long e = q->nb_head[p]; e < q->nb_head[p + 1]; e++) {
        const double *n = q->nb + IBM_NB_STRIDE * e;
        if ((n[4] - rn) * (1.0 - 1e-12) - 1e-12 * rn >= G) break;
        double x = r[0] - n[0], y = r[1] - n[1], z = r[2] - n[2];
        double Gq = sqrt(x * x + y * y + z * z) - n[3];
        if (Gq < G) G = Gq;
    }
    return ibm_gap_thickening(G > 0.0 ? G : 0.0, h);
}

