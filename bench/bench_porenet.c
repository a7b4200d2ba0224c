/* bench_porenet.c — cost of the pore network per sphere (the seed's Tables
 * 5.1–5.4 and 5.6): triangulation (qhull 4-D lift, images included), network
 * build (geometry + conductances + force coefficients: the thesis's
 * "assembly" T_G), CHOLMOD analyse + factorisation, one back-solve, the forces
 * F = S p, and the per-step work of a coupled step with a fixed topology
 * (pore volumes + back-solve + forces).
 *
 * Packings (porenet_packing.h): N spheres, radii 1 ± 5 %, solid fraction
 * 0.58, periodic box, random positions relaxed until the largest overlap is
 * below 1e-3 r; a mean pressure gradient along z.  Times are CPU times of
 * the process (the machine is shared: a loaded core inflates wall times),
 * the per-step parts the best of 5 runs, on one rank, one BLAS thread.
 *
 * usage: bench_porenet [N...]   (default 5000 20000 80000)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "porenet.h"
#include "porenet_packing.h"
#include "util.h"

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int sizes[8] = {5000, 20000, 80000}, ns = 3;
    if (argc > 1) {
        ns = 0;
        for (int i = 1; i < argc && ns < 8; i++) sizes[ns++] = atoi(argv[i]);
    }
    printf("# pore network per sphere (us of CPU time), periodic packing phi = 0.58, radii 1 +- 5 %%, 1 rank\n");
    printf("# %7s %8s %7s %9s %9s %9s %9s %9s %9s %9s\n", "N", "pores", "pores/N", "triang", "network", "factor",
           "solve", "forces", "volumes", "step");
    for (int c = 0; c < ns; c++) {
        int n = sizes[c];
        double *x = malloc(3 * (size_t)n * sizeof *x), *r = malloc((size_t)n * sizeof *r);
        double tp = cputime();
        double L = make_packing(n, 0.58, 0.05, 99 + n, 0, x, r);
        tp = cputime() - tp;
        pn_domain_t dom;
        memset(&dom, 0, sizeof dom);
        for (int a = 0; a < 3; a++) dom.lo[a] = 0, dom.hi[a] = L, dom.periodic[a] = 1;
        dom.grad[2] = -1;
        pn_params_t prm = {0.5, 1.0, PN_WALL_MIRROR};
        char err[512];
        pn_tri_t t;
        pn_net_t net;
        double t0 = cputime();
        if (pn_triangulate(&dom, n, x, r, 0, &t, err, sizeof err)) die("%s", err);
        double t1 = cputime();
        if (pn_network_build(&dom, &prm, &t, x, r, n, &net, err, sizeof err)) die("%s", err);
        double t2 = cputime();
        pn_solver_t *s = pn_solver_create(&dom, &net, PN_SOLVER_CHOLMOD, 0, err, sizeof err);
        if (!s) die("%s", err);
        double t3 = cputime();
        double *p = malloc((size_t)net.npore * sizeof *p), *f = malloc(3 * (size_t)n * sizeof *f);
        double *vol = malloc((size_t)net.npore * sizeof *vol);
        double tsolve = 1e30, tforce = 1e30, tvol = 1e30;
        for (int rep = 0; rep < 5; rep++) {
            double a = cputime();
            pn_solve(s, &dom, &net, NULL, p);
            double b = cputime();
            pn_forces(&dom, &t, &net, p, n, f, NULL, NULL);
            double cc = cputime();
            pn_pore_volumes(&dom, &t, &net, x, vol);
            double d = cputime();
            tsolve = fmin(tsolve, b - a);
            tforce = fmin(tforce, cc - b);
            tvol = fmin(tvol, d - cc);
        }
        double us = 1e6 / n;
        printf("  %7d %8d %7.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f\n", n, net.npore, (double)net.npore / n,
               (t1 - t0) * us, (t2 - t1) * us, (t3 - t2) * us, tsolve * us, tforce * us, tvol * us,
               (tsolve + tforce + tvol) * us);
        printf("#   N = %d: packing %.3g s, triangulation %.3g s, network %.3g s, factorisation %.3g s (CPU), peak RSS "
               "%.0f MB\n",
               n, tp, t1 - t0, t2 - t1, t3 - t2, peak_rss_bytes() / 1048576.0);
        fflush(stdout);
        pn_solver_free(s);
        pn_network_free(&net);
        pn_tri_free(&t);
        free(x), free(r), free(p), free(f), free(vol);
    }
    MPI_Finalize();
    return 0;
}
