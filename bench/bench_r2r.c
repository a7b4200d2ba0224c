/* bench_r2r.c — the r2r kinds of the Poisson solver computed from complex
 * DFTs (src/poisson/r2r.c) against FFTW's own r2r plans, side by side in one
 * run: the same lines, the same planner (FFTW_ESTIMATE, the solver's
 * default), interleaved, best of the repetitions.
 *
 * usage: bench_r2r [lines=80] [n=880] [reps=50]
 * The default is the axisymmetric bouncing sphere at D/Δx = 20 (80 radial
 * lines of 880 axial points; the axial velocity has n − 1 unknowns).
 * prints per kind: microseconds for all lines, the ratio, and the largest
 * difference between the two relative to the largest output. */
#include <fftw3.h>
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/poisson/r2r.h"

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int nl = argc > 1 ? atoi(argv[1]) : 80, n0 = argc > 2 ? atoi(argv[2]) : 880, reps = argc > 3 ? atoi(argv[3]) : 50;
    if (nl < 1 || n0 < 3 || reps < 1) {
        fprintf(stderr, "usage: bench_r2r [lines >= 1] [n >= 3] [reps >= 1]\n");
        return 2;
    }
    const fftw_r2r_kind kinds[] = {FFTW_REDFT10, FFTW_REDFT01, FFTW_RODFT10, FFTW_RODFT01,
                                   FFTW_REDFT11, FFTW_RODFT11, FFTW_RODFT00};
    const char *names[] = {"REDFT10", "REDFT01", "RODFT10", "RODFT01", "REDFT11", "RODFT11", "RODFT00"};
    long ld = n0 + 2; /* line stride: the field's, ghosts included */
    double *x = fftw_alloc_real(nl * ld), *a = fftw_alloc_real(nl * ld), *b = fftw_alloc_real(nl * ld);
    printf("bench_r2r: %d lines of n points (n = %d, n - 1 for RODFT00), FFTW_ESTIMATE, best of %d\n", nl, n0, reps);
    for (int q = 0; q < 7; q++) {
        int n = kinds[q] == FFTW_RODFT00 ? n0 - 1 : n0;
        fftw_iodim d = {n, 1, 1}, h = {nl, (int)ld, (int)ld};
        fftw_plan f = fftw_plan_guru_r2r(1, &d, 1, &h, x, a, &kinds[q], FFTW_ESTIMATE | FFTW_PRESERVE_INPUT);
        r2r_plan_t *c = r2r_plan_make(kinds[q], n, FFTW_ESTIMATE);
        if (!f || !c) {
            printf("bench_r2r kind=%s n=%d: not covered\n", names[q], n);
            continue;
        }
        for (long m = 0; m < nl * ld; m++) x[m] = sin(0.37 * m + 0.1) + 0.25 * cos(1.3 * m);
        double tf = 1e30, tc = 1e30;
        for (int r = 0; r < reps; r++) {
            double t0 = MPI_Wtime();
            fftw_execute(f);
            double t1 = MPI_Wtime();
            r2r_plan_exec(c, x, 1, b, 1, nl, ld, ld, 1, 0, 0);
            double t2 = MPI_Wtime();
            tf = fmin(tf, t1 - t0);
            tc = fmin(tc, t2 - t1);
        }
        double err = 0.0, big = 0.0;
        for (int l = 0; l < nl; l++)
            for (int k = 0; k < n; k++) {
                err = fmax(err, fabs(a[l * ld + k] - b[l * ld + k]));
                big = fmax(big, fabs(a[l * ld + k]));
            }
        printf("bench_r2r kind=%s n=%d lines=%d: fftw %.1f us, from complex DFTs %.1f us, ratio %.2f, max difference %.1e "
               "(relative)\n",
               names[q], n, nl, 1e6 * tf, 1e6 * tc, tf / tc, err / big);
        fftw_destroy_plan(f);
        r2r_plan_destroy(c);
    }
    fftw_free(x), fftw_free(a), fftw_free(b);
    MPI_Finalize();
    return 0;
}
