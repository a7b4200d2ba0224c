/* bench_mg.c — cost of a multigrid pressure solve (src/poisson/multigrid.c).
 *
 * Problems (VAR_P, λ = 0, relative residual 1e-8, the tolerance a projection
 * needs for max |div u| ~ 1e-8 of the velocity scale):
 *   walls     closed box, Neumann on all six faces, uniform grid
 *   periodic  triply periodic
 *   channel   walls in x with tanh_both stretching (β = 2), periodic y and z:
 *             the x-line relaxation path
 * The right-hand side is pseudo-random (uniform in [−1, 1], a hash of the
 * global cell index, so the same on any rank count): it excites every
 * wavenumber, like the divergence of a turbulent intermediate velocity, and
 * is harder than a smooth manufactured source.
 *
 * Grid: 128³ (2.1 M cells) by default, the size of the fluid benchmark; a
 * field is 17 MB, so x, b and the residual do not fit in the 32 MB L3 and the
 * fine-level sweeps run from memory, as in production; 128 = 2⁷ gives the
 * full 7-level hierarchy.
 *
 * Prints per problem: V-cycles, time per solve (best of `reps`), time per
 * V-cycle, mean convergence factor, the FFT solve of the same problem in the
 * same run and the ratio, and the peak resident set per cell (summed over the
 * ranks, read before the FFT solver of that problem is created; the peak is
 * the process's high-water mark, so for a clean figure run one problem per
 * process — bench/run.sh should call the three problems separately).
 *
 * usage: bench_mg [N=128] [reps=3] [walls|periodic|channel|all]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "poisson.h"
#include "util.h"

static double hash_uniform(uint64_t k)
{
    k += 0x9e3779b97f4a7c15ull; /* splitmix64 */
    k = (k ^ (k >> 30)) * 0xbf58476d1ce4e5b9ull;
    k = (k ^ (k >> 27)) * 0x94d049bb133111ebull;
    k ^= k >> 31;
    return (double)(k >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/* Best wall time (max over ranks) of `reps` solves. */
static double time_solves(poisson_t *p, const double *b, double *x, int reps)
{
    double best = 1e30;
    for (int r = 0; r < reps; r++) {
        MPI_Barrier(p->g->comm);
        double t0 = wtime();
        if (poisson_solve(p, 0.0, b, x) != 0) warn("solve did not converge (residual %.2e)", p->last_residual);
        double t = grid_max(p->g, wtime() - t0);
        if (t < best) best = t;
    }
    return best;
}

static void run(const char *name, int N, int reps)
{
    int n[3] = {N, N, N};
    double L[3] = {1, 1, 1};
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    stretch_t st = STRETCH_UNIFORM;
    if (!strcmp(name, "walls"))
        for (int d = 0; d < 3; d++) bc.type[d][0] = bc.type[d][1] = BC_NOSLIP;
    if (!strcmp(name, "channel")) {
        bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
        st = STRETCH_TANH_BOTH;
    }
    grid_t *g = grid_create(GEOM_3D, n, L, NULL, &bc, st, 2.0, MPI_COMM_WORLD);
    double *b = field_alloc(g), *x = field_alloc(g);
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < N; j++)
            for (int k = 0; k < N; k++)
                b[G_IDX(g, i, j, k)] = hash_uniform(((uint64_t)(i + g->ix0) * N + j) * N + k);

    poisson_opts_t o = {.method = POISSON_MG, .mg_tol = 1e-8, .mg_max_cycles = 100, .mg_pre = 2, .mg_post = 2};
    double t0 = wtime();
    poisson_t *pm = poisson_create(g, VAR_P, &o);
    double tsetup = grid_max(g, wtime() - t0);
    double tmg = time_solves(pm, b, x, reps);
    int cycles = pm->last_iterations;
    double res = poisson_residual(pm, 0.0, b, x), factor = pow(pm->last_residual, 1.0 / cycles);
    double rss = grid_sum(g, (double)peak_rss_bytes()) / ((double)N * N * N);

    poisson_opts_t of = o;
    of.method = POISSON_FFT;
    poisson_t *pf = poisson_create(g, VAR_P, &of);
    double tfft = time_solves(pf, b, x, reps);

    msg("%-9s N=%d ranks=%d: %2d V(2,2)-cycles to %.0e (residual %.1e, factor %.3f)  solve %.3f s  "
        "%.1f ms/cycle  setup %.3f s  | fft solve %.3f s, mg/fft %.1f  | peak RSS %.0f B/cell\n",
        name, N, g->nranks, cycles, o.mg_tol, res, factor, tmg, 1e3 * tmg / cycles, tsetup, tfft, tmg / tfft, rss);
    poisson_free(pm);
    poisson_free(pf);
    free(b);
    free(x);
    grid_free(g);
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int N = argc > 1 ? atoi(argv[1]) : 128;
    int reps = argc > 2 ? atoi(argv[2]) : 3;
    const char *which = argc > 3 ? argv[3] : "all";
    const char *names[3] = {"walls", "periodic", "channel"};
    for (int i = 0; i < 3; i++)
        if (!strcmp(which, "all") || !strcmp(which, names[i])) run(names[i], N, reps);
    MPI_Finalize();
    return 0;
}
