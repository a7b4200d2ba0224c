/* bench_porenet.c — cost of the pore network per sphere (the seed's Tables
 * 5.1–5.4 and 5.6): triangulation (qhull 4-D lift, images included), network
 * build (geometry + conductances + force coefficients: the thesis's
 * "assembly" T_G), CHOLMOD analyse + factorisation, one back-solve, the forces
 * F = S p, and the per-step work of a coupled step with a fixed topology
 * (pore volumes + back-solve + forces).
 *
 * Packings: N spheres, radii 1 ± 5 %, solid fraction 0.58, periodic box,
 * random positions relaxed with cell lists until the largest overlap is
 * below 1e-3 r (the prototype's procedure, catalano_pfv.md §6); a mean
 * pressure gradient along z.  Times are the best of `reps` runs, on one rank.
 *
 * usage: bench_porenet [N...]   (default 5000 20000 80000)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "porenet.h"
#include "util.h"

static double urand(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* periodic relaxation with a cell list (cells of 2 r_max) */
static double make_packing(int n, double phi, double pd, unsigned long long seed, double *x, double *r)
{
    double vs = 0;
    for (int i = 0; i < n; i++) {
        r[i] = 1 - pd + 2 * pd * urand(&seed);
        vs += 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];
    }
    double L = cbrt(vs / phi);
    for (int i = 0; i < 3 * n; i++) x[i] = L * urand(&seed);
    int nc = (int)(L / (2 * (1 + pd)));
    double h = L / nc;
    int *head = malloc((size_t)nc * nc * nc * sizeof *head), *next = malloc((size_t)n * sizeof *next);
    double *dx = malloc(3 * (size_t)n * sizeof *dx);
    for (int it = 0; it < 3000; it++) {
        for (int c = 0; c < nc * nc * nc; c++) head[c] = -1;
        for (int i = 0; i < n; i++) {
            int ci[3];
            for (int a = 0; a < 3; a++) ci[a] = ((int)(x[3 * i + a] / h)) % nc;
            int c = (ci[0] * nc + ci[1]) * nc + ci[2];
            next[i] = head[c];
            head[c] = i;
        }
        memset(dx, 0, 3 * (size_t)n * sizeof *dx);
        double worst = 0;
        for (int i = 0; i < n; i++) {
            int ci[3];
            for (int a = 0; a < 3; a++) ci[a] = ((int)(x[3 * i + a] / h)) % nc;
            for (int s = 0; s < 27; s++) {
                int cj[3] = {(ci[0] + s % 3 - 1 + nc) % nc, (ci[1] + (s / 3) % 3 - 1 + nc) % nc,
                             (ci[2] + s / 9 - 1 + nc) % nc};
                for (int j = head[(cj[0] * nc + cj[1]) * nc + cj[2]]; j >= 0; j = next[j]) {
                    if (j <= i) continue;
                    double d[3], dd = 0;
                    for (int a = 0; a < 3; a++) {
                        d[a] = x[3 * j + a] - x[3 * i + a];
                        d[a] -= L * round(d[a] / L);
                        dd += d[a] * d[a];
                    }
                    double sr = r[i] + r[j];
                    if (dd >= sr * sr) continue;
                    double dist = sqrt(dd), ov = sr - dist;
                    worst = fmax(worst, ov);
                    for (int a = 0; a < 3; a++) {
                        double f = 0.25 * ov * d[a] / dist;
                        dx[3 * i + a] -= f;
                        dx[3 * j + a] += f;
                    }
                }
            }
        }
        if (worst < 1e-3) break;
        for (int i = 0; i < 3 * n; i++) {
            x[i] += dx[i];
            x[i] -= L * floor(x[i] / L);
            if (x[i] >= L) x[i] = 0;
        }
    }
    free(head);
    free(next);
    free(dx);
    return L;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int sizes[8] = {5000, 20000, 80000}, ns = 3;
    if (argc > 1) {
        ns = 0;
        for (int i = 1; i < argc && ns < 8; i++) sizes[ns++] = atoi(argv[i]);
    }
    printf("# pore network per sphere (us), periodic packing phi = 0.58, radii 1 +- 5 %%, 1 rank\n");
    printf("# %7s %8s %7s %9s %9s %9s %9s %9s %9s %9s\n", "N", "pores", "pores/N", "triang", "network", "factor",
           "solve", "forces", "volumes", "step");
    for (int c = 0; c < ns; c++) {
        int n = sizes[c];
        double *x = malloc(3 * (size_t)n * sizeof *x), *r = malloc((size_t)n * sizeof *r);
        double L = make_packing(n, 0.58, 0.05, 99 + n, x, r);
        pn_domain_t dom;
        memset(&dom, 0, sizeof dom);
        for (int a = 0; a < 3; a++) dom.lo[a] = 0, dom.hi[a] = L, dom.periodic[a] = 1;
        dom.grad[2] = -1;
        pn_params_t prm = {0.5, 1.0};
        char err[512];
        pn_tri_t t;
        pn_net_t net;
        double t0 = wtime();
        if (pn_triangulate(&dom, n, x, r, 0, &t, err, sizeof err)) die("%s", err);
        double t1 = wtime();
        if (pn_network_build(&dom, &prm, &t, x, r, n, &net, err, sizeof err)) die("%s", err);
        double t2 = wtime();
        pn_solver_t *s = pn_solver_create(&dom, &net, PN_SOLVER_CHOLMOD, 0, err, sizeof err);
        if (!s) die("%s", err);
        double t3 = wtime();
        double *p = malloc((size_t)net.npore * sizeof *p), *f = malloc(3 * (size_t)n * sizeof *f);
        double *vol = malloc((size_t)net.npore * sizeof *vol);
        double tsolve = 1e30, tforce = 1e30, tvol = 1e30;
        for (int rep = 0; rep < 5; rep++) {
            double a = wtime();
            pn_solve(s, &dom, &net, NULL, p);
            double b = wtime();
            pn_forces(&dom, &t, &net, p, n, f, NULL, NULL);
            double cc = wtime();
            pn_pore_volumes(&dom, &t, &net, x, vol);
            double d = wtime();
            tsolve = fmin(tsolve, b - a);
            tforce = fmin(tforce, cc - b);
            tvol = fmin(tvol, d - cc);
        }
        double us = 1e6 / n;
        printf("  %7d %8d %7.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f\n", n, net.npore, (double)net.npore / n,
               (t1 - t0) * us, (t2 - t1) * us, (t3 - t2) * us, tsolve * us, tforce * us, tvol * us,
               (tsolve + tforce + tvol) * us);
        fflush(stdout);
        pn_solver_free(s);
        pn_network_free(&net);
        pn_tri_free(&t);
        free(x), free(r), free(p), free(f), free(vol);
    }
    MPI_Finalize();
    return 0;
}
