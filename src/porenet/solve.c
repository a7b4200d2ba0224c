/* solve.c — the pore-pressure system [G]{p} = {b} (Catalano eq. 3.16–3.17,
 * 4.4): one row per pore without an imposed pressure,
 *   Σ_j k_ij (p_i − p_j) = −w_i dV_i/dt + Σ_j k_ij G·(P_j − P_i) (periodic
 *   mean gradient) + flux sources,
 * the imposed pressures moved to the right-hand side.  G is symmetric
 * positive definite once one pressure is imposed (a pore is held at 0 when
 * none is).  CHOLMOD factorises it once per triangulation (the factorisation
 * is 97–99 % of a direct solve, thesis Table 5.5) and every step only
 * back-substitutes; the fallback is conjugate gradients with a Jacobi
 * preconditioner.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/cholmod.h>

#include "porenet.h"
#include "porenet_internal.h"
#include "util.h"

/* unknowns up to which the factor is simplicial (LDLᵀ), supernodal above */
#define PN_SIMPLICIAL_MAX 5000

struct pn_solver {
    pn_solver_kind_t kind;
    int nu;          /* unknowns */
    int *unk;        /* pore -> unknown index, -1 for an imposed pressure */
    int pinned;      /* pore held at 0 (no pressure imposed anywhere), -1 */
    double *b, *x;   /* nu */
    /* CHOLMOD */
    cholmod_common cc;
    cholmod_factor *L;
    cholmod_dense *B, *X, *Y, *E; /* right-hand side, solution and workspace of cholmod_solve2, kept */
    int cc_started;
    /* PCG: CSR of the full matrix */
    int *rp, *ci;
    double *va, *dinv, *r, *z, *pp, *q;
    double tol;
    int iters;
    double t_factor;
    double flux_area[6]; /* Σ section areas of the pores of each flux face */
};

int pn_solver_iterations(const pn_solver_t *s) { return s->iters; }

void pn_solver_set_solution(pn_solver_t *s, const double *p, int npore)
{
    for (int i = 0; i < npore; i++)
        if (s->unk[i] >= 0) s->x[s->unk[i]] = p[i];
}
double pn_solver_factor_time(const pn_solver_t *s) { return s->t_factor; }

void pn_solver_free(pn_solver_t *s)
{
    if (!s) return;
    if (s->cc_started) {
        if (s->L) cholmod_free_factor(&s->L, &s->cc);
        cholmod_free_dense(&s->B, &s->cc);
        cholmod_free_dense(&s->X, &s->cc);
        cholmod_free_dense(&s->Y, &s->cc);
        cholmod_free_dense(&s->E, &s->cc);
        cholmod_finish(&s->cc);
    }
    free(s->unk);
    free(s->b);
    free(s->x);
    free(s->rp);
    free(s->ci);
    free(s->va);
    free(s->dinv);
    free(s->r);
    free(s->z);
    free(s->pp);
    free(s->q);
    free(s);
}

/* Periodic part of the mean-gradient jump G·dx across throat f. */
static double jump(const pn_domain_t *dom, const pn_net_t *net, int f)
{
    double j = 0;
    for (int a = 0; a < 3; a++)
        if (dom->periodic[a]) j += dom->grad[a] * net->dx[3 * f + a];
    return j;
}

double pn_throat_dp(const pn_domain_t *dom, const pn_net_t *net, const double *p, int f)
{
    return p[net->tp[2 * f]] - p[net->tp[2 * f + 1]] - jump(dom, net, f);
}

pn_solver_t *pn_solver_create(const pn_domain_t *dom, const pn_net_t *net, pn_solver_kind_t kind, double pcg_tol,
                              char *err, size_t nerr)
{
    return pn_solver_create_ordered(dom, net, kind, PN_ORDER_METIS, pcg_tol, err, nerr);
}

pn_solver_t *pn_solver_create_ordered(const pn_domain_t *dom, const pn_net_t *net, pn_solver_kind_t kind,
                                      pn_ordering_t ordering, double pcg_tol, char *err, size_t nerr)
{
    pn_solver_t *s = calloc(1, sizeof *s);
    s->kind = kind;
    s->tol = pcg_tol;
    int np = net->npore;
    s->unk = malloc((size_t)np * sizeof *s->unk);
    s->pinned = 0;
    for (int p = 0; p < np; p++)
        if (net->dirichlet[p] >= 0) s->pinned = -1;
    int nu = 0;
    for (int p = 0; p < np; p++) s->unk[p] = (net->dirichlet[p] >= 0 || p == s->pinned) ? -1 : nu++;
    s->nu = nu;
    for (int p = 0; p < np; p++)
        if (net->face[p] >= 0 && dom->bc[net->face[p]] == PN_BC_FLUX) s->flux_area[net->face[p]] += net->bc_area[p];
    s->b = calloc((size_t)nu + 1, sizeof *s->b);
    s->x = calloc((size_t)nu + 1, sizeof *s->x);
    if (nu == 0) return s;

    /* triplets of the upper triangle (CHOLMOD) / full rows (PCG) */
    int nth = net->nthroat;
    double *diag = calloc((size_t)nu, sizeof *diag);
    for (int f = 0; f < nth; f++) {
        int i = s->unk[net->tp[2 * f]], j = s->unk[net->tp[2 * f + 1]];
        double k = net->k[f];
        if (i >= 0) diag[i] += k;
        if (j >= 0) diag[j] += k;
    }
    for (int i = 0; i < nu; i++)
        if (!(diag[i] > 0)) {
            /* a pore with no conductance: its row would be singular */
            snprintf(err, nerr, "pore-pressure matrix: a pore has no open throat (zero row)");
            free(diag);
            pn_solver_free(s);
            return NULL;
        }
    double t0 = wtime();
    if (kind == PN_SOLVER_CHOLMOD) {
        cholmod_start(&s->cc);
        s->cc_started = 1;
        s->cc.print = 0;
        /* nested dissection: METIS (less fill than AMD on these 3-D mesh-like
         * graphs), or geometric (ordering.c: 1.5× the fill and the flops of
         * the factorisation, a fifth of METIS's time to order; for a system
         * solved once) */
        s->cc.nmethods = 1;
        s->cc.method[0].ordering = CHOLMOD_METIS;
        /* a small system is back-substituted faster by the simplicial
         * factor (one BLAS call per supernode costs more than the column it
         * replaces): measured on the 300-sphere oedometer (≈ 2000 unknowns)
         * 72 against 101 µs per solve, the factorisation equal; at 31 000
         * unknowns the simplicial factorisation was 7× slower, the solve
         * 1.1× (docs/performance.md) */
        s->cc.supernodal = nu <= PN_SIMPLICIAL_MAX ? CHOLMOD_SIMPLICIAL : CHOLMOD_SUPERNODAL;
        cholmod_triplet *T = cholmod_allocate_triplet((size_t)nu, (size_t)nu, (size_t)(nu + nth), 1, CHOLMOD_REAL, &s->cc);
        int *Ti = T->i, *Tj = T->j;
        double *Tx = T->x;
        size_t m = 0;
        for (int i = 0; i < nu; i++) Ti[m] = Tj[m] = i, Tx[m++] = diag[i];
        for (int f = 0; f < nth; f++) {
            int i = s->unk[net->tp[2 * f]], j = s->unk[net->tp[2 * f + 1]];
            if (i < 0 || j < 0 || i == j) continue;
            Ti[m] = i < j ? i : j;
            Tj[m] = i < j ? j : i;
            Tx[m++] = -net->k[f];
        }
        T->nnz = m;
        cholmod_sparse *A = cholmod_triplet_to_sparse(T, m, &s->cc);
        cholmod_free_triplet(&T, &s->cc);
        if (ordering == PN_ORDER_GEOMETRIC) {
            /* geometric nested dissection of the unknowns (their pores' positions) */
            int *cnt = calloc((size_t)nu + 1, sizeof *cnt);
            for (int f = 0; f < nth; f++) {
                int i = s->unk[net->tp[2 * f]], j = s->unk[net->tp[2 * f + 1]];
                if (i < 0 || j < 0 || i == j) continue;
                cnt[i + 1]++, cnt[j + 1]++;
            }
            for (int i = 0; i < nu; i++) cnt[i + 1] += cnt[i];
            int *ci = malloc(((size_t)cnt[nu] + 1) * sizeof *ci), *fill = malloc(((size_t)nu + 1) * sizeof *fill);
            memcpy(fill, cnt, (size_t)nu * sizeof *fill);
            for (int f = 0; f < nth; f++) {
                int i = s->unk[net->tp[2 * f]], j = s->unk[net->tp[2 * f + 1]];
                if (i < 0 || j < 0 || i == j) continue;
                ci[fill[i]++] = j, ci[fill[j]++] = i;
            }
            double *xyz = malloc(3 * ((size_t)nu + 1) * sizeof *xyz);
            for (int p = 0; p < np; p++)
                if (s->unk[p] >= 0) memcpy(xyz + 3 * s->unk[p], net->P + 3 * p, 3 * sizeof *xyz);
            int *perm = malloc(((size_t)nu + 1) * sizeof *perm);
            pn_order_nested_dissection(nu, cnt, ci, xyz, perm);
            s->cc.method[0].ordering = CHOLMOD_GIVEN;
            s->L = cholmod_analyze_p(A, perm, NULL, 0, &s->cc);
            free(cnt), free(ci), free(fill), free(xyz), free(perm);
        } else {
            s->L = cholmod_analyze(A, &s->cc);
        }
        cholmod_factorize(A, s->L, &s->cc);
        cholmod_free_sparse(&A, &s->cc);
        if (s->cc.status != CHOLMOD_OK || !s->L || s->L->minor < (size_t)nu) {
            snprintf(err, nerr, "CHOLMOD: the pore-pressure matrix is not positive definite (status %d)", s->cc.status);
            free(diag);
            pn_solver_free(s);
            return NULL;
        }
    } else {
        int *cnt = calloc((size_t)nu + 1, sizeof *cnt);
        for (int i = 0; i < nu; i++) cnt[i + 1]++;
        for (int f = 0; f < nth; f++) {
            int i = s->unk[net->tp[2 * f]], j = s->unk[net->tp[2 * f + 1]];
            if (i < 0 || j < 0 || i == j) continue;
            cnt[i + 1]++, cnt[j + 1]++;
        }
        for (int i = 0; i < nu; i++) cnt[i + 1] += cnt[i];
        s->rp = malloc(((size_t)nu + 1) * sizeof *s->rp);
        memcpy(s->rp, cnt, ((size_t)nu + 1) * sizeof *cnt);
        s->ci = malloc((size_t)cnt[nu] * sizeof *s->ci);
        s->va = malloc((size_t)cnt[nu] * sizeof *s->va);
        for (int i = 0; i < nu; i++) s->ci[cnt[i]] = i, s->va[cnt[i]++] = diag[i];
        for (int f = 0; f < nth; f++) {
            int i = s->unk[net->tp[2 * f]], j = s->unk[net->tp[2 * f + 1]];
            if (i < 0 || j < 0 || i == j) continue;
            s->ci[cnt[i]] = j, s->va[cnt[i]++] = -net->k[f];
            s->ci[cnt[j]] = i, s->va[cnt[j]++] = -net->k[f];
        }
        free(cnt);
        s->dinv = malloc((size_t)nu * sizeof *s->dinv);
        for (int i = 0; i < nu; i++) s->dinv[i] = 1.0 / diag[i];
        s->r = malloc((size_t)nu * sizeof(double));
        s->z = malloc((size_t)nu * sizeof(double));
        s->pp = malloc((size_t)nu * sizeof(double));
        s->q = malloc((size_t)nu * sizeof(double));
    }
    s->t_factor = wtime() - t0;
    free(diag);
    return s;
}

static void spmv(const pn_solver_t *s, const double *x, double *y)
{
    for (int i = 0; i < s->nu; i++) {
        double a = 0;
        for (int m = s->rp[i]; m < s->rp[i + 1]; m++) a += s->va[m] * x[s->ci[m]];
        y[i] = a;
    }
}

static double dot(int n, const double *a, const double *b)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* Jacobi-preconditioned conjugate gradients from the current s->x, to
 * ‖r‖ ≤ tol ‖b‖. */
static int pcg(pn_solver_t *s)
{
    int n = s->nu;
    double *x = s->x, *r = s->r, *z = s->z, *p = s->pp, *q = s->q;
    double bn = sqrt(dot(n, s->b, s->b));
    s->iters = 0;
    if (bn == 0) {
        memset(x, 0, (size_t)n * sizeof *x);
        return 0;
    }
    spmv(s, x, q);
    for (int i = 0; i < n; i++) r[i] = s->b[i] - q[i], z[i] = s->dinv[i] * r[i];
    memcpy(p, z, (size_t)n * sizeof *p);
    double rz = dot(n, r, z);
    int maxit = 20 * n + 100;
    for (int it = 0; it < maxit; it++) {
        if (sqrt(dot(n, r, r)) <= s->tol * bn) return 0;
        spmv(s, p, q);
        double alpha = rz / dot(n, p, q);
        for (int i = 0; i < n; i++) x[i] += alpha * p[i], r[i] -= alpha * q[i];
        for (int i = 0; i < n; i++) z[i] = s->dinv[i] * r[i];
        double rz1 = dot(n, r, z);
        double beta = rz1 / rz;
        rz = rz1;
        for (int i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
        s->iters = it + 1;
    }
    return sqrt(dot(n, r, r)) <= s->tol * bn ? 0 : -1;
}

int pn_solve(pn_solver_t *s, const pn_domain_t *dom, const pn_net_t *net, const double *dvdt, double *p)
{
    int np = net->npore, nu = s->nu;
    /* imposed pressures */
    for (int i = 0; i < np; i++) {
        int f = net->dirichlet[i];
        p[i] = f >= 0 && f < 6 ? dom->bc_value[f] : 0.0; /* PN_CLEAR: hydrostatic */
    }
    memset(s->b, 0, (size_t)nu * sizeof *s->b);
    for (int i = 0; i < np; i++) {
        int u = s->unk[i];
        if (u < 0) continue;
        if (dvdt) s->b[u] -= dvdt[i];
        int f = net->face[i];
        if (f >= 0 && dom->bc[f] == PN_BC_FLUX && s->flux_area[f] > 0)
            s->b[u] += dom->bc_value[f] * net->bc_area[i] / s->flux_area[f];
    }
    for (int f = 0; f < net->nthroat; f++) {
        int i = net->tp[2 * f], j = net->tp[2 * f + 1];
        int ui = s->unk[i], uj = s->unk[j];
        double k = net->k[f], c = k * jump(dom, net, f);
        if (ui >= 0) s->b[ui] += c + (uj < 0 ? k * p[j] : 0);
        if (uj >= 0) s->b[uj] += -c + (ui < 0 ? k * p[i] : 0);
    }
    int rc = 0;
    if (nu > 0) {
        if (s->kind == PN_SOLVER_CHOLMOD) {
            if (!s->B) s->B = cholmod_allocate_dense((size_t)nu, 1, (size_t)nu, CHOLMOD_REAL, &s->cc);
            memcpy(s->B->x, s->b, (size_t)nu * sizeof(double));
            cholmod_solve2(CHOLMOD_A, s->L, s->B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cc);
            memcpy(s->x, s->X->x, (size_t)nu * sizeof(double));
        } else {
            rc = pcg(s);
        }
    }
    for (int i = 0; i < np; i++)
        if (s->unk[i] >= 0) p[i] = s->x[s->unk[i]];
    return rc;
}
