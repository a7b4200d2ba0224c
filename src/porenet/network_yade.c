/* network_yade.c — porenet.wall_throats = yade: the conductances of the throats
 * lying in a wall plane replaced by those YADE's FlowEngine gives the same
 * geometry (network.c builds the network; this file rewrites those throats).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "network_internal.h"
#include "porenet.h"
#include "porenet_internal.h"

/* Throats in a wall plane (weight w < 1: both pores on the plane) with YADE
 * FlowEngine's model (FlowBoundingSphere::computeHydraulicRadius with
 * slipBoundary, Network::volumeSingleFictiousPore / surfaceSolidThroat;
 * docs/theory.md).  YADE has one throat per pair of boundary cells, its facet
 * the in-box part of the mirrored facet set: for one wall plane the
 * trapezoid of the two real spheres c_2, c_3 and their projections A_2, A_3
 * on the plane, for two planes (an edge) the rectangle of the real sphere c
 * and its projections A, B on both.  On it:
 *   S = ½(h_2 + h_3) e_n × (c_3 − c_2)   (trapezoid; rectangle: (c − A) × (c − B))
 *   φ = |S·(P_j − P_i)|/3 − Σ_k r_k³ ω_k/3, γ = Σ_k r_k² ω_k, the solid angles
 *       ω_k of sphere k seen through (its projection, P_i, P_j) and (the other
 *       sphere, P_i, P_j)   (rectangle: through its two projections)
 *   A = |S| − Σ_k ½ r_k² θ_k, θ_k the facet's angle at c_k (π/2 on an edge)
 *   R_h = φ/γ × 2^(-1/4) per slip wall plane (YADE's multSym1, multSym2)
 *   k = α A R_h²/(μ L)
 * shared among the mirrored facets between the two pores in proportion to
 * w A_f so that the network keeps its throats.  With the mirror model the
 * same set is split into the triangles of the triangulation, each with its
 * own R_h (and the solid angles of a triangle that P_iP_j does not pierce
 * overlap), which gives a different conductance for the same geometry. */
static int cmp_pair(const void *a, const void *b)
{
    const long *x = a, *y = b;
    return x[0] < y[0] ? -1 : x[0] > y[0] ? 1 : (x[1] > y[1]) - (x[1] < y[1]);
}

static double yade_wall_conductance(const pn_domain_t *dom, const pn_params_t *prm, const pn_tri_t *t,
                                    const pn_net_t *net, const int *pts, int npts, int common, int slip, int f0)
{
    const double *Pi = net->P + 3 * net->tp[2 * f0], *Pj = net->P + 3 * net->tp[2 * f0 + 1];
    int ax[2], na = 0;
    double pl[2];
    for (int f = 0; f < 6; f++)
        if (common & (1 << f)) {
            if (na == 2) return -1;
            ax[na] = f / 2;
            pl[na++] = f % 2 ? dom->hi[f / 2] : dom->lo[f / 2];
        }
    if (!(na == 1 && npts == 2) && !(na == 2 && npts == 1)) return -1; /* not a trapezoid or a rectangle */
    double S[3], vsol = 0, gam = 0, sect = 0, d[3];
    sub3(Pj, Pi, d);
    if (na == 1) {
        const double *c2 = t->x + 3 * pts[0], *c3 = t->x + 3 * pts[1];
        const double r2 = t->r[pts[0]], r3 = t->r[pts[1]];
        double A2[3], A3[3], mh[3] = {0, 0, 0}, e[3];
        memcpy(A2, c2, sizeof A2);
        memcpy(A3, c3, sizeof A3);
        A2[ax[0]] = A3[ax[0]] = pl[0];
        mh[ax[0]] = pl[0] - 0.5 * (c2[ax[0]] + c3[ax[0]]);
        sub3(c3, c2, e);
        cross3(mh, e, S);
        const double w2 = solid_angle(c2, A2, Pi, Pj) + solid_angle(c2, c3, Pi, Pj);
        const double w3 = solid_angle(c3, A3, Pi, Pj) + solid_angle(c3, c2, Pi, Pj);
        vsol = (r2 * r2 * r2 * w2 + r3 * r3 * r3 * w3) / 3.0;
        gam = r2 * r2 * w2 + r3 * r3 * w3;
        sect = 0.5 * r2 * r2 * angle_at(c2, A2, c3) + 0.5 * r3 * r3 * angle_at(c3, A3, c2);
    } else {
        const double *c = t->x + 3 * pts[0], r = t->r[pts[0]];
        double A[3], B[3], u[3], v[3];
        memcpy(A, c, sizeof A);
        memcpy(B, c, sizeof B);
        A[ax[0]] = pl[0];
        B[ax[1]] = pl[1];
        sub3(c, A, u);
        sub3(c, B, v);
        cross3(u, v, S);
        const double w = solid_angle(c, A, Pi, Pj) + solid_angle(c, B, Pi, Pj);
        vsol = r * r * r * w / 3.0;
        gam = r * r * w;
        sect = 0.25 * M_PI * r * r;
    }
    const double phi = fabs(dot3(S, d)) / 3.0 - vsol;
    const double area = fabs(norm3(S) - sect);
    double rh = phi > 0 && gam > 0 ? phi / gam : 0;
    if (slip) rh *= pow(2.0, -0.25 * na);
    return prm->alpha * area * rh * rh / (prm->mu * norm3(d));
}

void pn_wall_throats_yade(const pn_domain_t *dom, const pn_params_t *prm, const pn_tri_t *t, pn_net_t *net,
                          const int *tplane)
{
    long *key = malloc(2 * (size_t)net->nthroat * sizeof *key); /* (pore pair, throat) of the wall throats */
    int m = 0;
    for (int f = 0; f < net->nthroat; f++) {
        if (net->wt[f] >= 1) continue;
        const long i = net->tp[2 * f], j = net->tp[2 * f + 1];
        key[2 * m] = (i < j ? i : j) * (long)net->npore + (i < j ? j : i);
        key[2 * m + 1] = f;
        m++;
    }
    qsort(key, (size_t)m, 2 * sizeof *key, cmp_pair);
    for (int a = 0; a < m;) {
        int b = a;
        double A = 0;
        while (b < m && key[2 * b] == key[2 * a]) {
            const int f = (int)key[2 * b + 1];
            A += net->wt[f] * net->area[f];
            b++;
        }
        const int f0 = (int)key[2 * a + 1];
        const int common = net->faces[net->tp[2 * f0]] & net->faces[net->tp[2 * f0 + 1]];
        /* the real spheres of the set: the facet vertices that are not mirror images across these planes */
        int pts[4], np = 0, ok = 1;
        for (int c = a; c < b && ok; c++)
            for (int v = 0; v < 3; v++) {
                const int p = net->fv[3 * (int)key[2 * c + 1] + v];
                int image = 0, dup = 0;
                for (int q = 0; q < 6; q++)
                    if ((common & (1 << q)) && t->img[3 * p + q / 2]) image = 1;
                for (int u = 0; u < np; u++) dup |= pts[u] == p;
                if (image || dup) continue;
                if (np == 4) {
                    ok = 0;
                    break;
                }
                pts[np++] = p;
            }
        /* k < 0: not the trapezoid or rectangle YADE builds, the mirror model's conductances stay */
        const double k = ok ? yade_wall_conductance(dom, prm, t, net, pts, np, common, tplane[f0] < 0, f0) : -1;
        for (int c = a; c < b && k >= 0; c++) {
            const int f = (int)key[2 * c + 1];
            net->k[f] = A > 0 ? k * net->wt[f] * net->area[f] / A : k / (b - a);
        }
        a = b;
    }
    free(key);
}
