/* model.c — the pore network as used in a run: triangulate, build and
 * factorise when due (thesis fig. 5.9, step 2), then every step the pore
 * volume rates, the back-substitution and the forces (steps 3–5). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "porenet.h"
#include "util.h"

void pn_model_free(pn_model_t *m)
{
    pn_solver_free(m->sol);
    pn_network_free(&m->net);
    pn_tri_free(&m->tri);
    free(m->p);
    free(m->vol);
    free(m->vol_prev);
    free(m->dvdt);
    free(m->x_prev);
    free(m->f);
    free(m->fp);
    free(m->fv);
    free(m->x_cont);
    free(m->x_tri);
    free(m->xid);
    free(m->rid);
    free(m->snap_time);
    free(m->snap_counts);

    m->snap_time = NULL;
    m->snap_counts = NULL;
    m->nsnap = 0;
    m->sol = NULL;
    m->p = m->vol = m->vol_prev = m->dvdt = m->x_prev = m->x_tri = m->f = m->fp = m->fv = NULL;
    m->x_cont = m->xid = m->rid = NULL;
    m->built = 0;
}

static int cmp_key_1(const void *a, const void *b)
{
    const long long x = *(const long long *)a, y = *(const long long *)b;
    return x < y ? -1 : x > y;
}

static int cmp_key(const void *a, const void *b)
{
    const long long *x = a, *y = b;
    for (int k = 0; k < 4; k++)
        if (x[k] != y[k]) return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* The tetrahedra of the box (power centre inside) of the current triangulation as sorted
 * quadruples of (sphere, image) codes, the array sorted (the re-meshing statistics). */
static int tet_keys(const pn_model_t *m, long long (**out)[4])
{
    const pn_tri_t *t = &m->tri;
    long long(*key)[4] = malloc(((size_t)t->ntet + 1) * sizeof *key);
    int nk = 0;
    for (int k = 0; k < t->ntet; k++) {
        const double *P = t->P + 3 * k;
        int in = 1;
        for (int a = 0; a < 3; a++) in &= P[a] >= m->dom.lo[a] && P[a] <= m->dom.hi[a];
        if (!in) continue;
        for (int v = 0; v < 4; v++) {
            const int q = t->tet[4 * k + v];
            const signed char *g = t->img + 3 * (size_t)q;
            key[nk][v] = 27LL * t->id[q] + 9 * (g[0] + 1) + 3 * (g[1] + 1) + (g[2] + 1);
        }
        qsort(key[nk], 4, sizeof key[nk][0], cmp_key_1);
        nk++;
    }
    qsort(key, (size_t)nk, sizeof *key, cmp_key);
    *out = key;
    return nk;
}

/* The fraction of the new triangulation's tetrahedra of the box that the replaced one had (old:
 * its tet_keys), into the statistics; frees old. */
static void remesh_stats(pn_model_t *m, long long (*old)[4], int nold)
{
    long long(*key)[4] = NULL;
    const int nk = tet_keys(m, &key);
    if (nk > 0) {
        long kept = 0;
        for (int i = 0, j = 0; i < nk && j < nold;) {
            const int c = cmp_key(key[i], old[j]);
            if (c == 0) kept++, i++, j++;
            else if (c < 0) i++;
            else j++;
        }
        const double f = (double)kept / nk;
        m->kept_min = m->kept_count ? fmin(m->kept_min, f) : f;
        m->kept_sum += f;
        m->kept_count++;
    }
    free(key);
    free(old);
}

int pn_model_rebuild(pn_model_t *m, int n, const double *x, const double *r)
{
    /* a coupled run's rebuild replacing a triangulation: what it keeps of it (diagnostic) */
    long long(*old)[4] = NULL;
    const int nold = m->built && m->eps_retri > 0 ? tet_keys(m, &old) : 0;
    pn_solver_free(m->sol);
    m->sol = NULL;
    pn_network_free(&m->net);
    pn_tri_free(&m->tri);
    double t0 = cputime(), t1 = t0;
    /* the width the last triangulation needed: the next one starts there (auto margin).  A pore of
     * the box that still reaches the rim of the cloud (the criterion of the triangulation can miss
     * the large power spheres of a sphere-free layer at a face) widens the layer by half, up to the
     * box's length, and the triangulation is made again */
    if (m->clear_radius > 0) {
        double dsum = 0;
        for (int i = 0; i < n; i++) dsum += 2 * r[i];
        m->dom.clear_h = m->clear_radius * dsum / n;
    }
    double mg = m->margin > 0 ? m->margin : m->margin_used, mcap = INFINITY;
    for (int a = 0; a < 3; a++) mcap = fmin(mcap, 0.999 * (m->dom.hi[a] - m->dom.lo[a]));
    for (int attempt = 0;; attempt++) {
        if (pn_triangulate_with(&m->dom, n, x, r, mg, m->tri_kind, &m->tri, m->err, sizeof m->err)) {
            free(old);
            return -1;
        }
        t1 = cputime();
        const int rc = pn_network_build(&m->dom, &m->prm, &m->tri, x, r, n, &m->net, m->err, sizeof m->err);
        if (rc == 0) break;
        if (rc != -2 || m->tri.margin >= mcap || attempt == 6) {
            free(old);
            return -1;
        }
        mg = fmin(mcap, 1.5 * m->tri.margin);
        pn_network_free(&m->net);
        pn_tri_free(&m->tri);
    }
    m->margin_used = m->tri.margin;
    if (m->tri.margin_needed > m->tri.margin && !(m->margin_warned & 2)) {
        warn("porenet: pores at the faces have power spheres reaching beyond the widest image layer used (%g; "
             "%g would make them exact): a sphere-free layer at a face? (porenet.margin)\n",
             m->tri.margin, m->tri.margin_needed);
        m->margin_warned |= 2;
    } else if (m->margin > 0 && m->tri.margin > m->margin && !(m->margin_warned & 1)) {
        warn("porenet: porenet.margin = %g is too narrow for this packing (pores at the faces need %g): "
             "triangulated with %g\n",
             m->margin, m->tri.margin_needed, m->tri.margin);
        m->margin_warned |= 1;
    }
    double t2 = cputime();
    m->sol = pn_solver_create_ordered(&m->dom, &m->net, m->kind, m->ordering, m->pcg_tol, m->err, sizeof m->err);
    if (!m->sol) {
        free(old);
        return -1;
    }
    m->t_tri = t1 - t0;
    m->t_net = t2 - t1;
    m->t_factor = cputime() - t2;
    m->t_rebuild += cputime() - t0;
    if (old) remesh_stats(m, old, nold);
    int np = m->net.npore;
    m->p = realloc(m->p, (size_t)np * sizeof *m->p);
    m->vol = realloc(m->vol, (size_t)np * sizeof *m->vol);
    m->vol_prev = realloc(m->vol_prev, (size_t)np * sizeof *m->vol_prev);
    m->dvdt = realloc(m->dvdt, (size_t)np * sizeof *m->dvdt);
    memset(m->p, 0, (size_t)np * sizeof *m->p);
    if (n != m->n || !m->f) {
        m->f = realloc(m->f, 3 * (size_t)n * sizeof *m->f);
        m->fp = realloc(m->fp, 3 * (size_t)n * sizeof *m->fp);
        m->fv = realloc(m->fv, 3 * (size_t)n * sizeof *m->fv);
        m->x_prev = realloc(m->x_prev, 3 * (size_t)n * sizeof *m->x_prev);
        m->x_cont = realloc(m->x_cont, 3 * (size_t)n * sizeof *m->x_cont);
        m->x_tri = realloc(m->x_tri, 3 * (size_t)n * sizeof *m->x_tri);
    }
    memcpy(m->x_tri, x, 3 * (size_t)n * sizeof *x);
    m->n = n;
    m->built = 1;
    m->n_retri++;
    m->eps_acc = 0;
    m->vol_current = 0;
    return 0;
}

/* A sphere crossed a periodic face since the previous step (its centre was
 * brought back into the box): the topology, built with its old position and
 * images, no longer follows it. */
static int wrapped(const pn_model_t *m, int n, const double *x)
{
    for (int a = 0; a < 3; a++) {
        if (!m->dom.periodic[a]) continue;
        const double half = 0.5 * (m->dom.hi[a] - m->dom.lo[a]);
        for (int i = 0; i < n; i++)
            if (fabs(x[3 * i + a] - m->x_prev[3 * i + a]) > half) return 1;
    }
    return 0;
}

int pn_model_step(pn_model_t *m, int n, const double *x, const double *r, double dt)
{
    int moving = m->built && dt > 0 && n == m->n;
    if (!m->built || n != m->n || m->eps_acc > m->eps_retri || m->eps_retri == 0 || (moving && wrapped(m, n, x))) {
        if (pn_model_rebuild(m, n, x, r)) return -1;
    }
    int np = m->net.npore;
    double t0 = cputime();
    if (moving) {
        /* previous positions continuous with x (periodic unwrapping: the
         * topology now follows x) */
        for (int i = 0; i < 3 * n; i++) {
            const int a = i % 3;
            double xp = m->x_prev[i];
            if (m->dom.periodic[a]) {
                const double L = m->dom.hi[a] - m->dom.lo[a];
                xp -= L * nearbyint((xp - x[i]) / L);
            }
            m->x_cont[i] = xp;
        }
        /* rate of change of the pore volumes on the current topology, from
         * the positions at the start and the end of the step (4.8); the
         * start's are the previous step's end volumes unless the topology
         * was rebuilt since (x_cont = x_prev then: a periodic wrap rebuilds) */
        if (m->vol_current) {
            double *tmp = m->vol_prev;
            m->vol_prev = m->vol;
            m->vol = tmp;
        } else {
            pn_pore_volumes(&m->dom, &m->tri, &m->net, m->x_cont, m->vol_prev);
        }
        pn_pore_volumes(&m->dom, &m->tri, &m->net, x, m->vol);
        m->vol_current = 1;
        double emax = 0;
        for (int i = 0; i < np; i++) {
            m->dvdt[i] = (m->vol[i] - m->vol_prev[i]) / dt;
            if (m->vol_prev[i] > 0) emax = fmax(emax, fabs(m->vol[i] - m->vol_prev[i]) / m->vol_prev[i]);
        }
        m->eps_acc += emax;
    } else {
        m->vol_current = 0; /* x_prev becomes x, vol is not at x */
    }
    double t1 = cputime();
    int rc = pn_solve(m->sol, &m->dom, &m->net, moving ? m->dvdt : NULL, m->p);
    double t2 = cputime();
    if (rc) {
        snprintf(m->err, sizeof m->err, "PCG did not reach porenet.pcg_tol = %g in %d iterations", m->pcg_tol,
                 pn_solver_iterations(m->sol));
        return -1;
    }
    pn_forces(&m->dom, &m->tri, &m->net, m->p, n, m->f, NULL, NULL);
    m->t_vol += t1 - t0;
    m->t_solve += t2 - t1;
    m->t_force += cputime() - t2;
    memcpy(m->x_prev, x, 3 * (size_t)n * sizeof *x);
    m->n_steps++;
    return 0;
}

double pn_model_permeability(const pn_model_t *m, int a)
{
    const pn_domain_t *d = &m->dom;
    if (!m->built) return NAN;
    if (d->periodic[a]) {
        if (d->grad[a] == 0) return NAN;
        double U[3];
        pn_mean_velocity(d, &m->net, m->p, U);
        return -m->prm.mu * U[a] / d->grad[a];
    }
    int flo = 2 * a, fhi = 2 * a + 1;
    if (d->bc[flo] != PN_BC_PRESSURE || d->bc[fhi] != PN_BC_PRESSURE) return NAN;
    double dP = d->bc_value[flo] - d->bc_value[fhi];
    if (dP == 0) return NAN;
    double q[6];
    pn_face_fluxes(d, &m->net, m->p, q);
    double L = d->hi[a] - d->lo[a], S = 1;
    for (int b = 0; b < 3; b++)
        if (b != a) S *= d->hi[b] - d->lo[b];
    /* mean of inlet and outlet (equal to round-off with the direct solver) */
    double Q = 0.5 * (q[flo] - q[fhi]);
    return m->prm.mu * Q * L / (dP * S);
}

int pn_model_validity(const pn_model_t *m, const double *r, char *buf, size_t nbuf, double *re, double *size_ratio,
                      double *porosity)
{
    int nw = 0;
    size_t used = 0;
    buf[0] = 0;
    double rmean = 0, rmin = INFINITY;
    for (int i = 0; i < m->n; i++) rmean += r[i], rmin = fmin(rmin, r[i]);
    rmean /= m->n;
    double umax = 0;
    for (int f = 0; f < m->net.nthroat; f++) {
        double q = m->net.k[f] * pn_throat_dp(&m->dom, &m->net, m->p, f) / m->net.wt[f];
        umax = fmax(umax, fabs(q) / m->net.area[f]);
    }
    double vv = 0, vt = 0;
    for (int i = 0; i < m->net.npore; i++)
        if (m->net.dirichlet[i] != PN_CLEAR) vv += m->net.vvoid[i], vt += m->net.vol[i]; /* the packing's */
    *re = m->rho_f * umax * 2 * rmean / m->prm.mu;
    *size_ratio = rmin / rmean;
    *porosity = vt > 0 ? vv / vt : NAN;
#define ADD(...)                                                                   \
    do {                                                                           \
        if (used < nbuf) used += (size_t)snprintf(buf + used, nbuf - used, __VA_ARGS__); \
        nw++;                                                                      \
    } while (0)
    /* creeping flow in the throats (Stokes assumption, thesis §1.1) */
    if (*re > 1) ADD("pore Reynolds number %.3g > 1: inertia in the throats, the resolved fluid is needed\n", *re);
    /* per-particle forces: error < 10 % for d/D > 0.2, factor 2 below 0.1 (thesis fig. 3.15) */
    if (*size_ratio < 0.2)
        ADD("smallest/mean radius %.3g < 0.2: forces on the small particles are underestimated (up to 2x below "
            "0.1)\n",
            *size_ratio);
    /* dense packings (n ~ 0.3-0.5): pores are well defined */
    if (*porosity > 0.5 || *porosity < 0.25)
        ADD("porosity %.3g outside 0.25-0.5: the pore network is meant for dense packings\n", *porosity);
#undef ADD
    return nw;
}

/* Is y inside the tetrahedron a b c d (barycentric signs, boundary included)? */
static int in_tet(const double *a, const double *b, const double *c, const double *d, const double *y)
{
    const double *v[4] = {a, b, c, d};
    double s0 = 0;
    for (int k = 0; k < 4; k++) {
        const double *p[4] = {v[0], v[1], v[2], v[3]};
        p[k] = y; /* the volume with vertex k replaced by y: the same sign as the tetrahedron's inside */
        const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]},
                     e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]},
                     e3[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
        const double s = e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
                         e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]);
        if (s == 0) continue;
        if (s0 == 0) s0 = s;
        else if ((s > 0) != (s0 > 0)) return 0;
    }
    return s0 != 0;
}

int pn_model_pore_at(const pn_model_t *m, const double y[3])
{
    const pn_net_t *net = &m->net;
    if (!m->built || !net->ntets || !m->x_prev) return -1; /* a failed rebuild leaves no network */
    /* the point and its copies: a pore of the box may extend across a periodic face, and a
     * tetrahedron of the box whose power centre is beyond a wall is the mirror of a pore's */
    for (int s = 0; s < 27; s++) {
        const int sh[3] = {s % 3 - 1, (s / 3) % 3 - 1, s / 9 - 1};
        double z[3];
        for (int a = 0; a < 3; a++) {
            const double lo = m->dom.lo[a], hi = m->dom.hi[a];
            z[a] = sh[a] == 0 ? y[a] : m->dom.periodic[a] ? y[a] + sh[a] * (hi - lo) : sh[a] < 0 ? 2 * lo - y[a] : 2 * hi - y[a];
        }
        for (int p = 0; p < net->npore; p++)
            for (int q = net->ntets[p]; q < net->ntets[p + 1]; q++) {
                double v[4][3];
                for (int k = 0; k < 4; k++) pn_tri_point(&m->dom, &m->tri, m->x_prev, net->tetv[4 * q + k], v[k]);
                if (in_tet(v[0], v[1], v[2], v[3], z)) return p;
            }
    }
    /* a tetrahedron of the clear fluid that is no pore of the box (its power centre beyond a face) */
    for (int k = 0; k < m->tri.ntet && m->dom.clear_h > 0; k++) {
        double v[4][3];
        for (int q = 0; q < 4; q++) pn_tri_point(&m->dom, &m->tri, m->x_prev, m->tri.tet[4 * k + q], v[q]);
        if (!in_tet(v[0], v[1], v[2], v[3], y)) continue;
        return m->tri.clear && m->tri.clear[k] ? PN_CLEAR_AT : -1;
    }
    /* outside the triangulated cloud (spheres and images): beyond the packing, in the clear fluid */
    return m->dom.clear_h > 0 ? PN_CLEAR_AT : -1;
}
