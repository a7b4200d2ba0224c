/* network.c — pores, throats, geometry and conductances of the pore network
 * (Catalano 2012 §3.1–3.3; catalano_pfv.md §1.4–1.6).
 *
 * Pores: the tetrahedra of the regular triangulation, those sharing a power
 * centre (|P_i − P_j| < 1e-8 d̄: co-spherical sets, e.g. a cubic lattice or
 * the symmetric sets at a wall) merged into one pore — a zero-length throat
 * would have an infinite conductance (note §6).  A pore is kept when its power
 * centre is inside the box or on a wall plane (weight ½ per plane), and, on a
 * periodic axis, when it is the canonical copy: the one whose smallest sphere
 * id appears unshifted.
 *
 * Throats: the facets between two different kept pores, each counted once.
 * Per facet (c_a, c_b, c_c; power centres P_i, P_j):
 *   S = ½ (c_a − c_c) × (c_b − c_c), oriented from P_i to P_j (P_iP_j ⟂ facet)
 *   sectors ½ r_k² θ_k, fluid area A = |S| − Σ sectors
 *   throat volume |S·(P_j − P_i)|/3, solid angles ω_k (Van Oosterom–Strackee)
 *   φ = volume − Σ r_k³ ω_k/3, γ = Σ r_k² ω_k (+ wall area if no-slip), R_h = φ/γ
 *   k = w α A R_h²/(μ L)                                           (3.3–3.5)
 * and the force per unit pressure jump on each vertex: sector (3.10) plus its
 * share A γ_k/γ of the viscous force (3.13–3.14) along n = P_i→P_j.
 * porenet.wall_throats = yade replaces the conductances of the throats lying in
 * a wall plane by YADE FlowEngine's (network_yade.c).
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "network_internal.h"
#include "porenet.h"
#include "porenet_internal.h"
#include "util.h"

enum { ST_IN = 0, ST_LO, ST_HI, ST_OUT };


void pn_network_free(pn_net_t *n)
{
    free(n->P);
    free(n->w);
    free(n->vol);
    free(n->vvoid);
    free(n->face);
    free(n->dirichlet);
    free(n->bc_area);
    free(n->faces);
    free(n->sect);
    free(n->ntets);
    free(n->tets);
    free(n->tp);
    free(n->dx);
    free(n->k);
    free(n->wt);
    free(n->area);
    free(n->rh);
    free(n->len);
    free(n->fv);
    free(n->nrm);
    free(n->fsec);
    free(n->fvis);
    free(n->wallf);
    free(n->tetv);
    free(n->fsph);
    free(n->fdir);
    memset(n, 0, sizeof *n);
}

static int uf_find(int *par, int i)
{
    while (par[i] != i) {
        par[i] = par[par[i]];
        i = par[i];
    }
    return i;
}


/* ---- hash of canonical vertex sets ---- */
typedef struct {
    int cap;
    int *slot;       /* pore index or -1 */
    uint64_t *hash;
} khash_t;

static uint64_t key_hash(const long *k, int n)
{
    uint64_t h = 1469598103934665603ULL;
    for (int i = 0; i < n; i++) {
        h ^= (uint64_t)k[i];
        h *= 1099511628211ULL;
        h ^= h >> 29;
    }
    return h | 1;
}

/* Canonical key of a cluster: its vertices as id*125 + image code, the
 * periodic shifts relative to those of the smallest (id, shift) vertex; the
 * shift that was removed goes to sh (all 0: this is the canonical copy). */
static int cluster_key(const pn_domain_t *dom, const pn_tri_t *t, const int *vl, int nv, long *key, int sh[3])
{
    int best = -1;
    for (int i = 0; i < nv; i++) {
        int p = vl[i];
        if (best < 0) {
            best = p;
            continue;
        }
        int b = best;
        if (t->id[p] != t->id[b]) {
            if (t->id[p] < t->id[b]) best = p;
            continue;
        }
        for (int a = 0; a < 3; a++) {
            if (!dom->periodic[a] || t->img[3 * p + a] == t->img[3 * b + a]) continue;
            if (t->img[3 * p + a] < t->img[3 * b + a]) best = p;
            break;
        }
    }
    for (int a = 0; a < 3; a++) sh[a] = dom->periodic[a] ? t->img[3 * best + a] : 0;
    for (int i = 0; i < nv; i++) {
        int p = vl[i];
        long code = 0, m = 1;
        for (int a = 0; a < 3; a++, m *= 5) code += (t->img[3 * p + a] - sh[a] + 2) * m;
        key[i] = (long)t->id[p] * 125 + code;
    }
    /* sort (small lists: insertion sort) */
    for (int i = 1; i < nv; i++) {
        long v = key[i];
        int j = i - 1;
        while (j >= 0 && key[j] > v) key[j + 1] = key[j], j--;
        key[j + 1] = v;
    }
    return nv;
}

/* A tetrahedron of the clear fluid (pn_tri_t.clear, triangulate.c). */
static int tet_clear(const pn_domain_t *dom, const pn_tri_t *t, int tt)
{
    (void)dom;
    return t->clear && t->clear[tt];
}

int pn_network_build(const pn_domain_t *dom, const pn_params_t *prm, const pn_tri_t *t, const double *x,
                     const double *r, int n, pn_net_t *net, char *err, size_t nerr)
{
    (void)x;
    memset(net, 0, sizeof *net);
    int nt = t->ntet;
    double rmean = 0;
    for (int i = 0; i < n; i++) rmean += r[i];
    rmean /= n;
    const double dbar = 2.0 * rmean;
    const double tol_merge = 1e-8 * dbar, tol_wall = 1e-7 * dbar;

    /* ---- clusters of tetrahedra sharing a power centre ---- */
    int *par = malloc((size_t)nt * sizeof *par);
    for (int i = 0; i < nt; i++) par[i] = i;
    for (int i = 0; i < nt; i++)
        for (int k = 0; k < 4; k++) {
            int j = t->nbr[4 * i + k];
            if (j < 0 || j < i) continue;
            double d[3];
            sub3(t->P + 3 * i, t->P + 3 * j, d);
            if (norm3(d) < tol_merge) {
                int a = uf_find(par, i), b = uf_find(par, j);
                if (a != b) par[a < b ? b : a] = a < b ? a : b;
            }
        }
    /* tetrahedra split by qhull from one co-spherical facet */
    {
        int ng = 0;
        for (int i = 0; i < nt; i++) ng = t->grp[i] + 1 > ng ? t->grp[i] + 1 : ng;
        int *first = malloc((size_t)(ng + 1) * sizeof *first);
        for (int g = 0; g < ng; g++) first[g] = -1;
        for (int i = 0; i < nt; i++) {
            int g = t->grp[i];
            if (g < 0) continue;
            if (first[g] < 0) {
                first[g] = i;
                continue;
            }
            int a = uf_find(par, i), b = uf_find(par, first[g]);
            if (a != b) par[a < b ? b : a] = a < b ? a : b;
        }
        free(first);
    }
    int *cl = malloc((size_t)nt * sizeof *cl); /* cluster of each tet (its root tet) */
    for (int i = 0; i < nt; i++) cl[i] = uf_find(par, i);
    free(par);
    /* tets of each cluster (CSR over roots) */
    int *cstart = calloc((size_t)nt + 1, sizeof *cstart), *clist = malloc((size_t)nt * sizeof *clist);
    for (int i = 0; i < nt; i++) cstart[cl[i] + 1]++;
    for (int i = 0; i < nt; i++) cstart[i + 1] += cstart[i];
    {
        int *fill = malloc((size_t)nt * sizeof *fill);
        memcpy(fill, cstart, (size_t)nt * sizeof *fill);
        for (int i = 0; i < nt; i++) clist[fill[cl[i]]++] = i;
        free(fill);
    }

    /* ---- centre of each cluster: the best-conditioned member's ---- */
    double *cP = malloc(3 * (size_t)nt * sizeof *cP);
    for (int c = 0; c < nt; c++) {
        if (cl[c] != c) continue;
        int best = c;
        for (int q = cstart[c]; q < cstart[c + 1]; q++)
            if (t->cond[clist[q]] > t->cond[best]) best = clist[q];
        memcpy(cP + 3 * c, t->P + 3 * best, 3 * sizeof(double));
    }

    /* ---- status of each cluster with respect to the walls ---- */
    unsigned char *st = malloc(3 * (size_t)nt); /* per axis, for roots */
    double *cw = malloc((size_t)nt * sizeof *cw);
    for (int c = 0; c < nt; c++) {
        if (cl[c] != c) continue;
        const double *P = cP + 3 * c;
        double w = 1.0;
        for (int a = 0; a < 3; a++) {
            unsigned char s = ST_IN;
            if (!dom->periodic[a]) {
                if (fabs(P[a] - dom->lo[a]) < tol_wall)
                    s = ST_LO, w *= 0.5;
                else if (fabs(P[a] - dom->hi[a]) < tol_wall)
                    s = ST_HI, w *= 0.5;
                else if (P[a] < dom->lo[a] || P[a] > dom->hi[a])
                    s = ST_OUT, w = 0;
            }
            st[3 * c + a] = s;
        }
        cw[c] = w;
    }

    /* ---- canonical keys and pore numbering ---- */
    int maxv = 0;
    for (int c = 0; c < nt; c++)
        if (cl[c] == c) maxv = (cstart[c + 1] - cstart[c]) * 4 > maxv ? (cstart[c + 1] - cstart[c]) * 4 : maxv;
    int *vl = malloc((size_t)maxv * sizeof *vl);
    long *key = malloc((size_t)maxv * sizeof *key);
    int *pore_of = malloc((size_t)nt * sizeof *pore_of); /* root -> pore (canonical copies), -1 */
    int np = 0;
    /* stored keys of the pores for lookups of images */
    size_t kcap = 1024, klen = 0;
    long *kstore = malloc(kcap * sizeof *kstore);
    int *koff = NULL, *klenp = NULL;
    int *proot = NULL;
    size_t pcap = 0;
    khash_t H = {0};

    /* vertex list of cluster c (unique points) */
#define CLUSTER_VERTS(c, nvout)                                                          \
    do {                                                                                 \
        int nv_ = 0;                                                                     \
        for (int q_ = cstart[c]; q_ < cstart[c + 1]; q_++)                               \
            for (int v_ = 0; v_ < 4; v_++) {                                             \
                int p_ = t->tet[4 * clist[q_] + v_], dup_ = 0;                            \
                for (int u_ = 0; u_ < nv_; u_++)                                         \
                    if (vl[u_] == p_) { dup_ = 1; break; }                               \
                if (!dup_) vl[nv_++] = p_;                                               \
            }                                                                            \
        nvout = nv_;                                                                     \
    } while (0)

    for (int c = 0; c < nt; c++) {
        pore_of[c] = -1;
        if (cl[c] != c || cw[c] == 0) continue;
        int nv, sh[3];
        CLUSTER_VERTS(c, nv);
        cluster_key(dom, t, vl, nv, key, sh);
        if (sh[0] || sh[1] || sh[2]) continue; /* a periodic copy */
        if ((size_t)np == pcap) {
            pcap = pcap ? 2 * pcap : 1024;
            koff = realloc(koff, pcap * sizeof *koff);
            klenp = realloc(klenp, pcap * sizeof *klenp);
            proot = realloc(proot, pcap * sizeof *proot);
        }
        while (klen + (size_t)nv > kcap) kcap *= 2, kstore = realloc(kstore, kcap * sizeof *kstore);
        memcpy(kstore + klen, key, (size_t)nv * sizeof *key);
        koff[np] = (int)klen;
        klenp[np] = nv;
        klen += (size_t)nv;
        proot[np] = c;
        pore_of[c] = np++;
    }
    if (np == 0) {
        free(cl), free(cstart), free(clist), free(st), free(cw), free(cP), free(vl), free(key), free(pore_of), free(kstore);
        return pn_fail(err, nerr, "no pore inside the box");
    }
    H.cap = 1;
    while (H.cap < 2 * np) H.cap *= 2;
    H.slot = malloc((size_t)H.cap * sizeof *H.slot);
    H.hash = malloc((size_t)H.cap * sizeof *H.hash);
    for (int i = 0; i < H.cap; i++) H.slot[i] = -1;
    for (int p = 0; p < np; p++) {
        uint64_t h = key_hash(kstore + koff[p], klenp[p]);
        int s = (int)(h & (uint64_t)(H.cap - 1));
        while (H.slot[s] >= 0) s = (s + 1) & (H.cap - 1);
        H.slot[s] = p;
        H.hash[s] = h;
    }

    /* ---- throats ---- */
    net->npore = np;
    size_t tcap = (size_t)np * 4 + 16;
    int nth = 0;
    int *tp = malloc(2 * tcap * sizeof *tp), *tfv = malloc(3 * tcap * sizeof *tfv);
    double *tdx = malloc(3 * tcap * sizeof *tdx), *twt = malloc(tcap * sizeof *twt);
    int *tplane = malloc(tcap * sizeof *tplane); /* no-slip wall face crossing the throat, -1 */
    double *tPi = malloc(3 * tcap * sizeof *tPi), *tPj = malloc(3 * tcap * sizeof *tPj);
    int *canon = malloc((size_t)nt * sizeof *canon); /* root -> pore, or -2 unknown */
    for (int c = 0; c < nt; c++) canon[c] = pore_of[c] >= 0 ? pore_of[c] : -2;
    int status = 0;
    /* a clear-fluid pore (dom->clear_h) holds the hydrostatic pressure, as every other: a neighbour of the
     * packing in the clear fluid whose periodic copy is not a pore of the box (the image layer is not
     * meant to make the clear fluid's pores exact) is any of them */
    int any_clear = -1;
    for (int pi = 0; pi < np && any_clear < 0 && dom->clear_h > 0; pi++)
        if (tet_clear(dom, t, clist[cstart[proot[pi]]])) any_clear = pi;
    for (int pi = 0; pi < np && !status; pi++) {
        int c = proot[pi];
        for (int q = cstart[c]; q < cstart[c + 1] && !status; q++) {
            int tt = clist[q];
            /* the facets of the clear fluid with the packing are the packing pores' throats */
            const int clear_i = tet_clear(dom, t, tt);
            for (int k = 0; k < 4; k++) {
                int u = t->nbr[4 * tt + k];
                if (u < 0) {
                    /* the rim of the cloud: fine across the facet of a tetrahedron beyond a wall
                     * (the half of a wall pore outside the box: its neighbours there are mirror
                     * pores, whose throats are not kept); anywhere else the images are too few */
                    int beyond = 0;
                    for (int a = 0; a < 3 && !beyond; a++) {
                        if (dom->periodic[a]) continue;
                        int lo = 1, hi = 1;
                        for (int v = 0; v < 4; v++) {
                            if (v == k) continue;
                            const double c = t->x[3 * (size_t)t->tet[4 * tt + v] + a];
                            lo &= c < dom->lo[a];
                            hi &= c > dom->hi[a];
                        }
                        beyond = lo || hi;
                    }
                    /* a clear-fluid pore holds the hydrostatic pressure: only its facets
                     * with the pores of the packing matter */
                    if (beyond || tet_clear(dom, t, tt)) continue;
                    pn_fail(err, nerr, "pore %d reaches the rim of the triangulated cloud: image margin (%g) too small",
                            pi, t->margin);
                    status = -2;
                    break;
                }
                int nb = cl[u];
                if (nb == c || clear_i) continue;
                const int clear_j = tet_clear(dom, t, u);
                /* throat weight and the wall plane it lies in */
                double w = 1.0;
                int plane = -1;
                for (int a = 0; a < 3; a++) {
                    int sc = st[3 * c + a], sn = st[3 * nb + a];
                    if (sc == ST_OUT || sn == ST_OUT) w = 0;
                    else if (sc == sn && sc != ST_IN) {
                        w *= 0.5;
                        int f = 2 * a + (sc == ST_HI);
                        if (dom->noslip[f]) plane = f;
                    }
                }
                if (w == 0) continue;
                /* canonical pore of the neighbour */
                if (canon[nb] == -2) {
                    int nv, sh[3];
                    CLUSTER_VERTS(nb, nv);
                    cluster_key(dom, t, vl, nv, key, sh);
                    uint64_t h = key_hash(key, nv);
                    int s = (int)(h & (uint64_t)(H.cap - 1)), found = -1;
                    while (H.slot[s] >= 0) {
                        int p = H.slot[s];
                        if (H.hash[s] == h && klenp[p] == nv && !memcmp(kstore + koff[p], key, (size_t)nv * sizeof *key)) {
                            found = p;
                            break;
                        }
                        s = (s + 1) & (H.cap - 1);
                    }
                    canon[nb] = found >= 0 ? found : -1;
                }
                int pj = canon[nb];
                if (pj < 0 && clear_j) pj = any_clear;
                int seam = 0;
                if (pj < 0 && dom->clear_h > 0) {
                    /* a packing that does not fill the box in a period narrower than the image layer its
                     * pores need (the column collapse): the pore of the box nearest to the copy's power
                     * centre brought into the box */
                    double q[3];
                    for (int a = 0; a < 3; a++) q[a] = cP[3 * nb + a];
                    pj = pn_nearest_pore(dom, cP, proot, np, pi, q);
                    seam = pj >= 0;
                    net->n_seam += seam;
                }
                if (pj < 0) {
                    status = pn_fail(err, nerr, "pore %d: the periodic copy of a neighbour has no canonical pore", pi);
                    break;
                }
                double dx[3];
                sub3(cP + 3 * nb, cP + 3 * c, dx);
                /* count each facet once: from the pore with the smaller index,
                 * or, between a pore and its own periodic copy, along +shift */
                if (pj < pi && !clear_j && !seam) continue;
                if (pj == pi) {
                    double s[3];
                    sub3(cP + 3 * nb, cP + 3 * proot[pj], s);
                    int pos = 0;
                    for (int a = 0; a < 3; a++)
                        if (fabs(s[a]) > 0.5 * tol_merge) {
                            pos = s[a] > 0;
                            break;
                        }
                    if (!pos) continue;
                }
                if ((size_t)nth == tcap) {
                    tcap *= 2;
                    tp = realloc(tp, 2 * tcap * sizeof *tp);
                    tfv = realloc(tfv, 3 * tcap * sizeof *tfv);
                    tdx = realloc(tdx, 3 * tcap * sizeof *tdx);
                    twt = realloc(twt, tcap * sizeof *twt);
                    tplane = realloc(tplane, tcap * sizeof *tplane);
                    tPi = realloc(tPi, 3 * tcap * sizeof *tPi);
                    tPj = realloc(tPj, 3 * tcap * sizeof *tPj);
                }
                tp[2 * nth] = pi;
                tp[2 * nth + 1] = pj;
                int m = 0;
                for (int v = 0; v < 4; v++)
                    if (v != k) tfv[3 * nth + m++] = t->tet[4 * tt + v];
                memcpy(tdx + 3 * nth, dx, sizeof dx);
                memcpy(tPi + 3 * nth, cP + 3 * c, 3 * sizeof(double));
                memcpy(tPj + 3 * nth, cP + 3 * nb, 3 * sizeof(double));
                twt[nth] = w;
                tplane[nth] = plane;
                nth++;
            }
        }
    }
#undef CLUSTER_VERTS
    free(H.slot);
    free(H.hash);
    free(kstore);
    free(koff);
    free(klenp);
    free(vl);
    free(key);
    free(canon);
    if (status) {
        free(cl), free(cstart), free(clist), free(st), free(cw), free(cP), free(pore_of), free(proot);
        free(tp), free(tfv), free(tdx), free(twt), free(tplane), free(tPi), free(tPj);
        return status < 0 ? status : -1;
    }

    /* ---- pores: centre, weight, faces, tetrahedra, volumes ---- */
    net->P = malloc(3 * (size_t)np * sizeof(double));
    net->w = malloc((size_t)np * sizeof(double));
    net->vol = calloc((size_t)np, sizeof(double));
    net->vvoid = calloc((size_t)np, sizeof(double));
    net->face = malloc((size_t)np * sizeof(int));
    net->dirichlet = malloc((size_t)np * sizeof(int));
    net->bc_area = calloc((size_t)np, sizeof(double));
    net->faces = calloc((size_t)np, sizeof(int));
    net->sect = calloc(3 * (size_t)np, sizeof(double));
    net->ntets = malloc(((size_t)np + 1) * sizeof(int));
    net->ntets[0] = 0;
    for (int p = 0; p < np; p++) net->ntets[p + 1] = net->ntets[p] + cstart[proot[p] + 1] - cstart[proot[p]];
    net->tets = malloc((size_t)net->ntets[np] * sizeof(int));
    net->tetv = malloc(4 * (size_t)net->ntets[np] * sizeof(int));
    for (int p = 0; p < np; p++) {
        int c = proot[p];
        memcpy(net->P + 3 * p, cP + 3 * c, 3 * sizeof(double));
        net->w[p] = cw[c];
        net->face[p] = net->dirichlet[p] = -1;
        for (int a = 0; a < 3; a++) {
            int s = st[3 * c + a];
            if (s == ST_LO || s == ST_HI) {
                int f = 2 * a + (s == ST_HI);
                if (net->face[p] < 0) net->face[p] = f;
                net->faces[p] |= 1 << f;
                if (dom->bc[f] == PN_BC_PRESSURE && net->dirichlet[p] < 0) net->dirichlet[p] = f;
            }
        }
        if (net->dirichlet[p] < 0 && tet_clear(dom, t, clist[cstart[c]])) net->dirichlet[p] = PN_CLEAR;
        double vt = 0, vs = 0;
        for (int q = cstart[c], m = net->ntets[p]; q < cstart[c + 1]; q++, m++) {
            int tt = clist[q];
            net->tets[m] = tt;
            const int *v = t->tet + 4 * tt;
            memcpy(net->tetv + 4 * m, v, 4 * sizeof *v);
            const double *X = t->x;
            vt += fabs(tet_volume(X + 3 * v[0], X + 3 * v[1], X + 3 * v[2], X + 3 * v[3]));
            for (int i = 0; i < 4; i++) {
                double om = solid_angle(X + 3 * v[i], X + 3 * v[(i + 1) % 4], X + 3 * v[(i + 2) % 4], X + 3 * v[(i + 3) % 4]);
                double rr = t->r[v[i]];
                vs += rr * rr * rr * om / 3.0;
            }
        }
        net->vol[p] = cw[c] * vt;
        net->vvoid[p] = cw[c] * (vt - vs);
    }

    /* ---- throat geometry, conductances, force coefficients ---- */
    net->nthroat = nth;
    net->tp = tp;
    net->fv = tfv;
    net->dx = tdx;
    net->wt = twt;
    net->k = malloc((size_t)nth * sizeof(double));
    net->area = malloc((size_t)nth * sizeof(double));
    net->rh = malloc((size_t)nth * sizeof(double));
    net->len = malloc((size_t)nth * sizeof(double));
    net->nrm = malloc(3 * (size_t)nth * sizeof(double));
    net->fsec = malloc(3 * (size_t)nth * sizeof(double));
    net->fvis = malloc(3 * (size_t)nth * sizeof(double));
    for (int f = 0; f < nth; f++) {
        const double *Pi = tPi + 3 * f, *Pj = tPj + 3 * f;
        const double *c[3];
        double rr[3];
        for (int v = 0; v < 3; v++) {
            c[v] = t->x + 3 * tfv[3 * f + v];
            rr[v] = t->r[tfv[3 * f + v]];
        }
        double e0[3], e1[3], S[3];
        sub3(c[0], c[2], e0);
        sub3(c[1], c[2], e1);
        cross3(e0, e1, S);
        for (int a = 0; a < 3; a++) S[a] *= 0.5;
        double d[3];
        sub3(Pj, Pi, d);
        double L = norm3(d), Sa = norm3(S);
        if (dot3(S, d) < 0)
            for (int a = 0; a < 3; a++) S[a] = -S[a];
        double nv[3] = {S[0] / Sa, S[1] / Sa, S[2] / Sa};
        double sec[3], secsum = 0;
        for (int v = 0; v < 3; v++) {
            sec[v] = 0.5 * rr[v] * rr[v] * angle_at(c[v], c[(v + 1) % 3], c[(v + 2) % 3]);
            secsum += sec[v];
        }
        double Af = Sa - secsum;
        if (Af <= 1e-6 * Sa) {
            /* The sectors cover the facet (a flat triangle whose obtuse-angle
             * sector overshoots the opposite edge, or overlapping spheres):
             * keep a sliver of fluid area and scale the sectors down so that
             * the facet still passes |S| Δp in total (the force balance). */
            net->n_negative_area++;
            Af = 1e-6 * Sa;
            for (int v = 0; v < 3; v++) sec[v] *= (Sa - Af) / secsum;
        }
        double Vtot = fabs(dot3(S, d)) / 3.0, om[3], vsol = 0, gam = 0;
        for (int v = 0; v < 3; v++) {
            om[v] = solid_angle(c[v], c[(v + 1) % 3], Pi, Pj) + solid_angle(c[v], c[(v + 2) % 3], Pi, Pj);
            vsol += rr[v] * rr[v] * rr[v] * om[v] / 3.0;
            gam += rr[v] * rr[v] * om[v];
        }
        double phi = Vtot - vsol;
        double gam_sph = gam;
        /* no-slip wall in the throat: its area in the double pyramid
         * (P_i, P_j on the plane, the facet cut along a segment X1X2 ⟂ P_iP_j)
         * is ½|X1X2| L on each side of the facet; the physical half of the
         * throat has φ/2 and γ/2 + that area, so R_h = φ/(γ + 2 A_wall). */
        double awall2 = 0;
        if (tplane[f] >= 0) {
            int a = tplane[f] / 2;
            double pl = tplane[f] % 2 ? dom->hi[a] : dom->lo[a], X[2][3];
            int nx = 0;
            for (int v = 0; v < 3 && nx < 2; v++) {
                const double *p0 = c[v], *p1 = c[(v + 1) % 3];
                double s0 = p0[a] - pl, s1 = p1[a] - pl;
                if ((s0 < 0) != (s1 < 0)) {
                    double tt = s0 / (s0 - s1);
                    for (int b = 0; b < 3; b++) X[nx][b] = p0[b] + tt * (p1[b] - p0[b]);
                    nx++;
                }
            }
            if (nx == 2) {
                double seg[3];
                sub3(X[1], X[0], seg);
                awall2 = norm3(seg) * L; /* 2 × ½ |X1X2| L */
                gam += awall2;
            }
        }
        double Rh = phi > 0 ? phi / gam : 0;
        double w = twt[f];
        net->area[f] = Af;
        net->rh[f] = Rh;
        net->len[f] = L;
        net->k[f] = w * prm->alpha * Af * Rh * Rh / (prm->mu * L);
        for (int a = 0; a < 3; a++) net->nrm[3 * f + a] = nv[a];
        for (int v = 0; v < 3; v++) {
            net->fsec[3 * f + v] = w * sec[v];
            net->fvis[3 * f + v] = w * Af * rr[v] * rr[v] * om[v] / gam;
        }
        (void)gam_sph;
        net->void_sum += w * phi;
        net->solid_area_sum += w * gam_sph;
        /* section areas of the wall pores: Σ of the weighted facet area vectors
         * leaving the pore closes on its section with the wall (S_f includes
         * the sphere sectors, the pressure acting on the solid is counted too) */
        for (int s = 0; s < 2; s++) {
            int p = tp[2 * f + s];
            if (net->face[p] < 0) continue;
            for (int a = 0; a < 3; a++) net->sect[3 * p + a] -= (s == 0 ? 1.0 : -1.0) * w * S[a];
        }
    }
    if (prm->wall_model == PN_WALL_YADE) pn_wall_throats_yade(dom, prm, t, net, tplane);
    /* force on each vertex's sphere per unit pressure jump (pn_forces): a
     * mirror image gives its force reflected across the wall */
    net->fsph = malloc(3 * (size_t)nth * sizeof(int));
    net->fdir = malloc(9 * (size_t)nth * sizeof(double));
    for (int f = 0; f < nth; f++)
        for (int v = 0; v < 3; v++) {
            const int q = tfv[3 * f + v];
            const double c = net->fsec[3 * f + v] + net->fvis[3 * f + v];
            net->fsph[3 * f + v] = t->id[q];
            for (int a = 0; a < 3; a++)
                net->fdir[9 * f + 3 * v + a] = ((!dom->periodic[a] && t->img[3 * q + a]) ? -c : c) * net->nrm[3 * f + a];
        }
    for (int p = 0; p < np; p++)
        if (net->face[p] >= 0) net->bc_area[p] = fabs(net->sect[3 * p + net->face[p] / 2]);
    net->box_volume = 1.0;
    for (int a = 0; a < 3; a++) net->box_volume *= dom->hi[a] - dom->lo[a];
    for (int i = 0; i < n; i++) net->solid_volume += 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];

    net->wallf = tplane;
    free(tPi);
    free(tPj);
    free(cl);
    free(cstart);
    free(clist);
    free(st);
    free(cw);
    free(cP);
    free(pore_of);
    free(proot);
    return 0;
}

void pn_pore_volumes(const pn_domain_t *dom, const pn_tri_t *t, const pn_net_t *net, const double *x, double *vol)
{
    for (int p = 0; p < net->npore; p++) {
        double v = 0;
        for (int m = net->ntets[p]; m < net->ntets[p + 1]; m++) {
            const int *q = net->tetv + 4 * m;
            double c[4][3];
            for (int i = 0; i < 4; i++) pn_tri_point(dom, t, x, q[i], c[i]);
            v += fabs(tet_volume(c[0], c[1], c[2], c[3]));
        }
        vol[p] = net->w[p] * v;
    }
}
