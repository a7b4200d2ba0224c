/* bench_poisson.c — time of the direct (FFT) pressure solve on an N³ grid,
 * triply periodic and wall-bounded (Neumann in every direction), against the
 * time of one FFTW 3-D real transform pair (r2c + c2r) of the same grid
 * measured in the same run: the floor of any FFT-based solve.
 *
 *   mpirun -np P bench_poisson [N [repetitions]]     (default 128, 10)
 *
 * Times are the best of the repetitions (less sensitive to a shared machine
 * than the mean), as wall time and as CPU time of the process (max over
 * ranks; CPU time excludes the periods other jobs hold the core, so on a
 * loaded machine it is the better estimate of the quiet wall time).  The
 * reference pair runs on rank 0 alone on the whole grid (serial FFTW),
 * planned with FFTW_ESTIMATE (as the solver) and with FFTW_MEASURE (the
 * best FFTW can do); ratios are given to both.  With P ranks the solve is
 * distributed and its ratio to the serial pair includes the parallel
 * speed-up.  Peak RSS is per rank, after the first solver (periodic,
 * estimate) was set up and ran once.
 * The solves run with the default planner (FFTW_ESTIMATE, bit-reproducible)
 * and with [poisson] fftw_planner = measure (plans from the wisdom file named
 * by the environment variable FFTW_WISDOM when set: created by the first
 * run, reused after), the four solvers timed in turn in each repetition.
 */
#include <fftw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "grid.h"
#include "poisson.h"
#include "util.h"

typedef struct {
    double wall, cpu;
} times_t;

static double cpu_time(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void keep_best(times_t *best, double w0, double c0, MPI_Comm comm)
{
    double v[2] = {wtime() - w0, cpu_time() - c0}, m[2];
    MPI_Allreduce(v, m, 2, MPI_DOUBLE, MPI_MAX, comm);
    if (m[0] < best->wall) best->wall = m[0];
    if (m[1] < best->cpu) best->cpu = m[1];
}

static times_t best_pair_time(int n, unsigned flags, int reps)
{
    double *r = fftw_alloc_real((size_t)n * n * n);
    fftw_complex *c = fftw_alloc_complex((size_t)n * n * (n / 2 + 1));
    fftw_plan f = fftw_plan_dft_r2c_3d(n, n, n, r, c, flags);
    fftw_plan b = fftw_plan_dft_c2r_3d(n, n, n, c, r, flags);
    for (long i = 0; i < (long)n * n * n; i++) r[i] = sin(0.001 * i);
    times_t best = {1e30, 1e30};
    for (int it = 0; it < reps; it++) {
        double w0 = wtime(), c0 = cpu_time();
        fftw_execute(f);
        fftw_execute(b);
        keep_best(&best, w0, c0, MPI_COMM_SELF);
        /* renormalise so that repeated pairs do not grow without bound */
        double s = 1.0 / ((double)n * n * n);
        for (long i = 0; i < (long)n * n * n; i++) r[i] *= s;
    }
    fftw_destroy_plan(f);
    fftw_destroy_plan(b);
    fftw_free(r);
    fftw_free(c);
    return best;
}

/* One solver of the benchmark: its grid, planner, right-hand side. */
typedef struct {
    grid_t *g;
    poisson_t *p;
    double *b, *x;
    int measure;
    double setup; /* seconds of poisson_create (planning) */
    times_t best;
} solver_t;

static void solver_create(solver_t *s, int n, bc_type_t wall, int measure, const char *wisdom)
{
    int nn[3] = {n, n, n};
    double L[3] = {1, 1, 1};
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < 3; d++) bc.type[d][0] = bc.type[d][1] = wall;
    s->g = grid_create(GEOM_3D, nn, L, NULL, &bc, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    poisson_opts_t o = {.method = POISSON_FFT, .fftw_measure = measure};
    if (measure && wisdom) snprintf(o.fftw_wisdom, sizeof o.fftw_wisdom, "%s", wisdom);
    s->measure = measure;
    MPI_Barrier(s->g->comm);
    double tp = wtime();
    s->p = poisson_create(s->g, VAR_P, &o);
    s->setup = wtime() - tp;
    const grid_t *g = s->g;
    s->b = field_alloc(g);
    s->x = field_alloc(g);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < n; j++)
            for (int k = 0; k < n; k++)
                s->b[G_IDX(g, i, j, k)] = sin(2 * M_PI * g->xc[i]) * cos(2 * M_PI * grid_yc(g, j)) *
                                              cos(4 * M_PI * grid_zc(g, k)) +
                                          0.1 * sin(0.37 * (i + g->ix0 + 3 * j + 7 * k));
    s->best = (times_t){1e30, 1e30};
    poisson_solve(s->p, 0.0, s->b, s->x); /* first touches */
}

static void solver_time(solver_t *s)
{
    MPI_Barrier(s->g->comm);
    double w0 = wtime(), c0 = cpu_time();
    poisson_solve(s->p, 0.0, s->b, s->x);
    keep_best(&s->best, w0, c0, s->g->comm);
}

static void solver_free(solver_t *s, const char *name)
{
    double res = poisson_residual(s->p, 0.0, s->b, s->x);
    msg("  %s: relative residual %.2e, set-up (planning) %.2f s\n", name, res, s->setup);
    free(s->b);
    free(s->x);
    poisson_free(s->p);
    grid_free(s->g);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int n = argc > 1 ? atoi(argv[1]) : 128, reps = argc > 2 ? atoi(argv[2]) : 10;
    int P = mpi_size();
    if (n < 4 || n % P || reps < 1) {
        if (mpi_rank() == 0) fprintf(stderr, "usage: bench_poisson [N [reps]] with N divisible by the rank count\n");
        MPI_Finalize();
        return 1;
    }
    msg("bench_poisson: %d^3 cells, %d rank(s), best of %d (wall / cpu seconds)\n", n, P, reps);
    const char *names[4] = {"periodic", "walls", "periodic, measure planner", "walls, measure planner"};
    bc_type_t walls[2] = {BC_PERIODIC, BC_NOSLIP};
    /* the measuring planner's wisdom file (FFTW_WISDOM): measured once, reused */
    const char *wisdom = getenv("FFTW_WISDOM");
    solver_t sv[4];
    times_t t[4];
    double rss = 0, rmax;
    for (int c = 0; c < 4; c++) {
        solver_create(&sv[c], n, walls[c % 2], c / 2, wisdom);
        /* peak memory of one solver and its fields (the first: periodic, estimate) */
        if (c == 0) rss = (double)peak_rss_bytes();
    }
    /* the four solvers in turn, so that each sees the same machine state */
    for (int it = 0; it < reps; it++)
        for (int c = 0; c < 4; c++) solver_time(&sv[c]);
    for (int c = 0; c < 4; c++) {
        t[c] = sv[c].best;
        solver_free(&sv[c], names[c]);
    }
    if (wisdom) msg("  measure planner: wisdom file %s (FFTW_WISDOM)\n", wisdom);
    MPI_Allreduce(&rss, &rmax, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    times_t pe = {0, 0}, pm = {0, 0};
    if (mpi_rank() == 0) {
        pe = best_pair_time(n, FFTW_ESTIMATE, reps);
        pm = best_pair_time(n, FFTW_MEASURE, reps);
    }
    /* the other ranks wait without spinning (a busy-polling MPI call would
     * take a core from rank 0 on a machine with no spare core) */
    MPI_Request rq;
    MPI_Ibarrier(MPI_COMM_WORLD, &rq);
    for (int done = 0; !done;) {
        MPI_Test(&rq, &done, MPI_STATUS_IGNORE);
        if (!done) nanosleep(&(struct timespec){0, 1000000}, NULL);
    }
    MPI_Bcast(&pe, 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    MPI_Bcast(&pm, 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    msg("  FFTW r2c+c2r pair (serial, whole grid): ESTIMATE %.4f / %.4f, MEASURE %.4f / %.4f\n", pe.wall, pe.cpu,
        pm.wall, pm.cpu);
    double cells = (double)n * n * n;
    for (int c = 0; c < 4; c++) {
        msg("  %s: solve %.4f / %.4f (%.1f ns per cell wall); ratio to the pair ESTIMATE %.2f / %.2f, "
            "MEASURE %.2f / %.2f\n",
            names[c], t[c].wall, t[c].cpu, 1e9 * t[c].wall / cells, t[c].wall / pe.wall, t[c].cpu / pe.cpu,
            t[c].wall / pm.wall, t[c].cpu / pm.cpu);
    }
    msg("  peak RSS of one solver with its fields (max over ranks) %.1f MB = %.0f bytes per local cell\n", rmax / 1048576.0,
        rmax / (cells / P));
    const char *keys[4] = {"periodic", "walls", "periodic_measure", "walls_measure"};
    for (int c = 0; c < 4; c++)
        msg("RESULT bench_poisson np=%d n=%d case=%s solve_wall=%.5f solve_cpu=%.5f pair_est_wall=%.5f "
            "pair_est_cpu=%.5f pair_meas_wall=%.5f pair_meas_cpu=%.5f\n",
            P, n, keys[c], t[c].wall, t[c].cpu, pe.wall, pe.cpu, pm.wall, pm.cpu);
    MPI_Finalize();
    return 0;
}
