/* bench_fluid_step.c — cost of a full RK3 time step (3 projections) of the
 * Navier–Stokes solver, against the physical floor of an FFT solve: one
 * FFTW forward + backward 3-D real transform (r2c + c2r) of the same grid,
 * measured in the same run (FFTW-MPI, FFTW_MEASURE: the best FFTW offers),
 * interleaved with the steps and solves (best of each over the repetitions).
 *
 * usage: bench_fluid_step [N=128] [periodic|walls] [fft|multigrid] [explicit|implicit] [steps=5]
 *                         [estimate|measure|both]
 * The FFT solver runs with FFTW_ESTIMATE plans and/or with [poisson]
 * fftw_planner = measure (default: both, two fluids timed in turn), the
 * measured plans from the wisdom file named by the environment variable
 * FFTW_WISDOM (created by the first run, reused after: the plans a run with
 * that file makes).
 * prints per planner: ns per cell per step, step / transform pair, Poisson
 * solve / pair, peak resident set per cell (one fluid), set-up time.
 */
#include <fftw3-mpi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "util.h"

/* One FFTW-MPI forward + backward 3-D real transform pair of the grid,
 * planned once (FFTW_MEASURE) and timed between the steps, so that the
 * step and its reference see the same machine state. */
typedef struct {
    double *r;
    fftw_complex *c;
    fftw_plan fwd, bwd;
} fft_pair_t;

static void fft_pair_create(fft_pair_t *q, int N)
{
    ptrdiff_t local_n0, local_0_start;
    ptrdiff_t alloc = fftw_mpi_local_size_3d(N, N, N / 2 + 1, MPI_COMM_WORLD, &local_n0, &local_0_start);
    q->r = fftw_alloc_real(2 * alloc);
    q->c = fftw_alloc_complex(alloc);
    q->fwd = fftw_mpi_plan_dft_r2c_3d(N, N, N, q->r, q->c, MPI_COMM_WORLD, FFTW_MEASURE);
    q->bwd = fftw_mpi_plan_dft_c2r_3d(N, N, N, q->c, q->r, MPI_COMM_WORLD, FFTW_MEASURE);
    for (ptrdiff_t i = 0; i < 2 * alloc; i++) q->r[i] = sin(0.1 * (double)i);
}

static void fft_pair_run(fft_pair_t *q)
{
    fftw_execute(q->fwd);
    fftw_execute(q->bwd);
}

static void fft_pair_free(fft_pair_t *q)
{
    fftw_destroy_plan(q->fwd);
    fftw_destroy_plan(q->bwd);
    fftw_free(q->r);
    fftw_free(q->c);
}

/* wall and CPU time of one call, max over the ranks; keep the minimum */
typedef struct {
    double wall, cpu;
} tmin_t;

static void timed(tmin_t *best, void (*fn)(void *), void *arg)
{
    MPI_Barrier(MPI_COMM_WORLD);
    double w0 = wtime(), c0 = cputime();
    fn(arg);
    double t[2] = {wtime() - w0, cputime() - c0};
    MPI_Allreduce(MPI_IN_PLACE, t, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (t[0] < best->wall) best->wall = t[0];
    if (t[1] < best->cpu) best->cpu = t[1];
}

static void run_pair(void *a) { fft_pair_run(a); }
typedef struct {
    fluid_t *f;
    double dt;
} step_arg_t;
static void run_step(void *a) { fluid_step(((step_arg_t *)a)->f, ((step_arg_t *)a)->dt); }
typedef struct {
    poisson_t *ps;
    double *b, *x;
} solve_arg_t;
static void run_solve(void *a)
{
    solve_arg_t *s = a;
    poisson_solve(s->ps, 0.0, s->b, s->x);
}

/* The fluid of one planner: Taylor–Green initial field (3-D), projected,
 * one warm-up step (first touches, plan caches); set-up time in *setup. */
static fluid_t *fluid_of_planner(grid_t *g, fluid_params_t *prm, int measure, double *setup)
{
    prm->poisson.fftw_measure = measure;
    double t0 = wtime();
    fluid_t *f = fluid_create(g, prm);
    *setup = wtime() - t0;
    int N = g->n[1];
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < N; j++)
            for (int k = 0; k < N; k++) {
                long c = G_IDX(g, i, j, k);
                double xf = g->xf[i], xc = g->xc[i], yf = grid_yf(g, j), yc = grid_yc(g, j), zc = grid_zc(g, k);
                f->u[0][c] = sin(xf) * cos(yc) * cos(zc);
                f->u[1][c] = -cos(xc) * sin(yf) * cos(zc);
                f->u[2][c] = 0.0;
            }
    fluid_project(f);
    fluid_step(f, prm->dt_fixed);
    return f;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int N = argc > 1 ? atoi(argv[1]) : 128;
    int walls = argc > 2 && !strcmp(argv[2], "walls");
    int mg = argc > 3 && !strcmp(argv[3], "multigrid");
    int implicit = argc > 4 && !strcmp(argv[4], "implicit");
    int nsteps = argc > 5 ? atoi(argv[5]) : 5;
    const char *planner = argc > 6 ? argv[6] : "both";
    /* the planners timed: estimate (variant 0) and/or measure (variant 1);
     * multigrid plans nothing */
    int use[2] = {mg || strcmp(planner, "measure") != 0, !mg && strcmp(planner, "estimate") != 0};
    /* the measuring planner's wisdom file (FFTW_WISDOM): measured once, reused */
    const char *wisdom = getenv("FFTW_WISDOM");

    int n[3] = {N, N, N};
    double L[3] = {2 * M_PI, 2 * M_PI, 2 * M_PI};
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    if (walls)
        for (int d = 0; d < 3; d++) bc.type[d][0] = bc.type[d][1] = BC_NOSLIP;
    grid_t *g = grid_create(GEOM_3D, n, L, NULL, &bc, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    fluid_params_t prm;
    memset(&prm, 0, sizeof prm);
    prm.nu = 1e-2;
    prm.rho = 1.0;
    prm.implicit_viscous = implicit;
    prm.cfl = 0.5;
    prm.fourier = 0.2;
    prm.dt_fixed = 1e-3;
    prm.dt_max = 1.0;
    prm.poisson.method = mg ? POISSON_MG : POISSON_FFT;
    prm.poisson.mg_tol = 1e-8;
    prm.poisson.mg_max_cycles = 50;
    prm.poisson.mg_pre = prm.poisson.mg_post = 2;
    if (wisdom) snprintf(prm.poisson.fftw_wisdom, sizeof prm.poisson.fftw_wisdom, "%s", wisdom);
    fluid_t *f[2] = {NULL, NULL};
    poisson_t *ps[2] = {NULL, NULL};
    double setup[2] = {0, 0};
    long rss = -1, rss_max;
    double *b = NULL, *x = NULL;
    for (int v = 0; v < 2; v++) {
        if (!use[v]) continue;
        f[v] = fluid_of_planner(g, &prm, v, &setup[v]);
        /* the solver's memory: one fluid, before the benchmark's own fields, solvers and transform */
        if (rss < 0) {
            rss = peak_rss_bytes();
            b = field_alloc(g);
            x = field_alloc(g);
            for (int i = 0; i < g->nxl; i++)
                for (int j = 0; j < N; j++)
                    for (int k = 0; k < N; k++)
                        b[G_IDX(g, i, j, k)] = cos(g->xc[i]) * cos(2 * grid_yc(g, j)) * cos(3 * grid_zc(g, k));
        }
        /* the Poisson solve alone, on the same grid (its plans come from the
         * wisdom the fluid's set-up left) */
        ps[v] = poisson_create(g, VAR_P, &prm.poisson);
        poisson_solve(ps[v], 0.0, b, x);
    }
    /* FFTW-MPI registers its planners only now: they change the signature
     * of the wisdom, and the solvers' wisdom file must stay the one of
     * ibmdem (which does not use FFTW-MPI) */
    fftw_mpi_init();
    fft_pair_t fp;
    fft_pair_create(&fp, N);
    fft_pair_run(&fp);
    /* transform pair, then each planner's step and solve, interleaved; best of nsteps each */
    tmin_t tstep[2], tsolve[2], tpair = {1e30, 1e30};
    step_arg_t sa[2];
    solve_arg_t so[2];
    for (int v = 0; v < 2; v++) {
        tstep[v] = tsolve[v] = (tmin_t){1e30, 1e30};
        sa[v] = (step_arg_t){f[v], prm.dt_fixed};
        so[v] = (solve_arg_t){ps[v], b, x};
    }
    for (int s = 0; s < nsteps; s++) {
        timed(&tpair, run_pair, &fp);
        for (int v = 0; v < 2; v++)
            if (use[v]) timed(&tstep[v], run_step, &sa[v]);
        for (int v = 0; v < 2; v++)
            if (use[v]) timed(&tsolve[v], run_solve, &so[v]);
    }
    MPI_Allreduce(&rss, &rss_max, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
    double bytes_per_cell = (double)rss_max / (double)g->ncell_local, pair = tpair.wall;
    double cells = (double)N * N * N;
    const char *pname[2] = {"estimate", "measure"};
    for (int v = 0; v < 2; v++) {
        if (!use[v]) continue;
        double best = tstep[v].wall, best_p = tsolve[v].wall;
        msg("bench_fluid_step N=%d %s %s %s ranks=%d%s%s: step %.4f s = %.1f ns/cell | poisson %.4f s%s | fftw "
            "r2c+c2r pair %.4f s | step/pair %.2f | poisson/pair %.2f | peak RSS %.0f B/cell\n",
            N, walls ? "walls" : "periodic", mg ? "multigrid" : "fft", implicit ? "implicit" : "explicit", g->nranks,
            mg ? "" : " planner=", mg ? "" : pname[v], best, best / cells * 1e9, best_p,
            mg ? " (multigrid cycles shown below)" : "", pair, best / pair, best_p / pair, bytes_per_cell);
        /* the same ratios in CPU time (max over ranks): insensitive to time
         * slices lost to other processes, not to memory-bandwidth contention */
        msg("bench_fluid_step   cpu time%s%s: step %.4f s | poisson %.4f s | pair %.4f s | step/pair %.2f | "
            "poisson/pair %.2f\n",
            mg ? "" : ", ", mg ? "" : pname[v], tstep[v].cpu, tsolve[v].cpu, tpair.cpu, tstep[v].cpu / tpair.cpu,
            tsolve[v].cpu / tpair.cpu);
        if (!mg)
            msg("bench_fluid_step   set-up (fluid_create, plans of the pressure%s solver) %s: %.2f s%s\n",
                implicit ? " and Helmholtz" : "", pname[v], setup[v],
                v == 1 ? (wisdom ? " (wisdom file FFTW_WISDOM)" : " (no wisdom file)") : "");
    }
    if (mg) msg("  multigrid V-cycles per solve to 1e-8: %d\n", ps[0]->last_iterations);
    free(b);
    free(x);
    fft_pair_free(&fp);
    for (int v = 0; v < 2; v++) {
        poisson_free(ps[v]);
        if (f[v]) fluid_free(f[v]);
    }
    grid_free(g);
    fftw_mpi_cleanup();
    MPI_Finalize();
    return 0;
}
