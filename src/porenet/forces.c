/* forces.c — what the pore pressures give: fluid forces on the spheres and
 * the walls, face fluxes, mean velocity (Catalano 2012 §3.3).
 *
 * Throat f between pores i → j with pressure jump Δp = p_i − p_j (periodic
 * mean gradient included) pushes each of its three spheres along n = P_i→P_j:
 *   pressure part   A_k Δp n       (A_k = sector ½ r_k² θ_k, eq. 3.10)
 *   viscous part    A γ_k/γ Δp n   (eq. 3.13–3.14, drag ALONG the flow:
 *                                   project decision 10)
 * so each throat gives |S| Δp n = S Δp in total, and over the network the
 * forces telescope to the boundary: Σ spheres + Σ faces = −V ∇p_mean.
 * A vertex that is a mirror image of a sphere gives its force to the sphere,
 * reflected; a periodic copy gives it unchanged.
 */
#include <math.h>
#include <string.h>

#include "porenet.h"

void pn_forces(const pn_domain_t *dom, const pn_tri_t *t, const pn_net_t *net, const double *p, int n, double *f,
               double *fp, double *fv)
{
    memset(f, 0, 3 * (size_t)n * sizeof *f);
    if (!fp || !fv) {
        /* the sum only (every coupled step): the precomputed coefficients */
        double g[3];
        for (int a = 0; a < 3; a++) g[a] = dom->periodic[a] ? dom->grad[a] : 0.0;
        const int *tp = net->tp, *fs = net->fsph;
        const double *fd = net->fdir, *dx = net->dx;
        for (int th = 0; th < net->nthroat; th++) {
            const double dp = p[tp[2 * th]] - p[tp[2 * th + 1]] -
                              (g[0] * dx[3 * th] + g[1] * dx[3 * th + 1] + g[2] * dx[3 * th + 2]);
            for (int v = 0; v < 3; v++) {
                double *fi = f + 3 * fs[3 * th + v];
                const double *c = fd + 9 * th + 3 * v;
                fi[0] += c[0] * dp;
                fi[1] += c[1] * dp;
                fi[2] += c[2] * dp;
            }
        }
        return;
    }
    if (fp) memset(fp, 0, 3 * (size_t)n * sizeof *fp);
    if (fv) memset(fv, 0, 3 * (size_t)n * sizeof *fv);
    for (int th = 0; th < net->nthroat; th++) {
        double dp = pn_throat_dp(dom, net, p, th);
        const double *nv = net->nrm + 3 * th;
        for (int v = 0; v < 3; v++) {
            int q = net->fv[3 * th + v], id = t->id[q];
            double cs = net->fsec[3 * th + v] * dp, cv = net->fvis[3 * th + v] * dp;
            for (int a = 0; a < 3; a++) {
                double sgn = (!dom->periodic[a] && t->img[3 * q + a]) ? -1.0 : 1.0;
                f[3 * id + a] += sgn * (cs + cv) * nv[a];
                if (fp) fp[3 * id + a] += sgn * cs * nv[a];
                if (fv) fv[3 * id + a] += sgn * cv * nv[a];
            }
        }
    }
}

void pn_face_forces(const pn_domain_t *dom, const pn_net_t *net, const double *p, double F[6][3])
{
    memset(F, 0, 6 * sizeof F[0]);
    for (int i = 0; i < net->npore; i++) {
        if (net->face[i] < 0) continue;
        /* each component on the face of its axis the pore lies on (round-off
         * components of the other axes on the first face: the sum is exact) */
        for (int a = 0; a < 3; a++) {
            int f = net->face[i];
            if (net->faces[i] & (1 << (2 * a))) f = 2 * a;
            if (net->faces[i] & (1 << (2 * a + 1))) f = 2 * a + 1;
            F[f][a] += p[i] * net->sect[3 * i + a];
        }
    }
    for (int th = 0; th < net->nthroat; th++) {
        int f = net->wallf[th];
        if (f < 0) continue;
        double share = net->wt[th] * net->area[th];
        for (int v = 0; v < 3; v++) share -= net->fvis[3 * th + v];
        double dp = pn_throat_dp(dom, net, p, th);
        for (int a = 0; a < 3; a++) F[f][a] += share * dp * net->nrm[3 * th + a];
    }
}

void pn_face_fluxes(const pn_domain_t *dom, const pn_net_t *net, const double *p, double q[6])
{
    for (int f = 0; f < 6; f++) q[f] = dom->bc[f] == PN_BC_FLUX && !dom->periodic[f / 2] ? dom->bc_value[f] : 0.0;
    for (int th = 0; th < net->nthroat; th++) {
        int i = net->tp[2 * th], j = net->tp[2 * th + 1];
        int fi = net->dirichlet[i], fj = net->dirichlet[j];
        if (fi == fj) continue; /* both interior, or both on the same reservoir */
        double qq = net->k[th] * pn_throat_dp(dom, net, p, th); /* from i to j */
        if (fi >= 0 && fi < 6) q[fi] += qq; /* PN_CLEAR: the clear fluid is no face */
        if (fj >= 0 && fj < 6) q[fj] -= qq;
    }
}

void pn_mean_velocity(const pn_domain_t *dom, const pn_net_t *net, const double *p, double U[3])
{
    U[0] = U[1] = U[2] = 0;
    for (int th = 0; th < net->nthroat; th++) {
        double qq = net->k[th] * pn_throat_dp(dom, net, p, th);
        for (int a = 0; a < 3; a++) U[a] += qq * net->dx[3 * th + a];
    }
    for (int a = 0; a < 3; a++) U[a] /= net->box_volume;
}
