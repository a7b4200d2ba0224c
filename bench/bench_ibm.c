/* bench_ibm.c — cost of the immersed boundary (solid fraction, forcing,
 * integrals and sphere update, at all three RK3 stages) for many spheres,
 * as a fraction of the cost of the fluid step it is part of.
 *
 * Scene: a triply periodic box of N³ cells, Δx = D/dpd, with `count`
 * spheres placed at random without overlap (random sequential addition,
 * fixed seed).  Five variants of the spheres (one warm-up step each), each
 * timed over `steps` steps; the best step (least disturbed on a shared
 * machine) is reported:
 *   external_moving  external spheres (the DEM-coupled kind) moved by
 *                    0.01 Δx along a random direction before every step,
 *                    with the matching velocity, ibm_update_geometry() —
 *                    the realistic case: α rebuilt once per step;
 *   external_rest    external spheres at rest (α built once);
 *   free             free spheres (ρ_p/ρ = 2 under gravity): α rebuilt
 *                    after every stage;
 *   free_step        the same with [ibm] free_alpha = step: α held over the
 *                    step, rebuilt once per step;
 *   external_moving_gaps  external_moving with [ibm] radius_correction =
 *                    gaps and forcing_time = 0.2 (the local gap term: a
 *                    neighbour list and a distance scan at every node).
 * Every repetition times one step of the fluid alone (the immersed
 * boundary's hooks detached) and then one step with the spheres, so that
 * both see the same machine state; the best of each is kept.  The cost of
 * the immersed boundary is the difference of the two, as a fraction of the
 * step alone: it includes the forcing done inside the fluid's sweeps and
 * what the fluid can no longer fuse with the spheres present.  The immersed
 * boundary's own timers (ibm->wall_*) split it into α, forcing and
 * integrals.
 *
 * Last, a floor (ibm_floor): the same arithmetic on flat arrays of the same
 * sizes, what any data structure must at least spend.
 *
 * usage: bench_ibm [N=128] [count=1000] [dpd=10] [steps=5] [explicit|implicit] [variant]
 * (variant: run only that one, e.g. for a profile)
 * prints, per variant: the fluid step alone and with the spheres, their
 * difference as a fraction of the step alone (the cost; `fraction=` of the
 * ibm_result line), the immersed boundary's timers (α, forcing, integrals;
 * `timers_fraction=`), node entries per sphere; then the floor, and one
 * ibm_result line each.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "ibm.h"
#include "util.h"

static double urand(unsigned long *s)
{
    *s = *s * 6364136223846793005UL + 1442695040888963407UL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* The fluid's hooks, detached for a step of the fluid alone and put back. */
typedef struct {
    fluid_stage_hook_t begin, stage, end;
    fluid_plane_hook_t plane;
    void *ctx;
    int flags;
} hooks_t;

static hooks_t hooks_detach(fluid_t *f)
{
    hooks_t h = {f->stage_begin_hook, f->stage_hook, f->stage_end_hook, f->plane_hook, f->hook_ctx, f->hook_flags};
    f->stage_begin_hook = f->stage_hook = f->stage_end_hook = NULL;
    f->plane_hook = NULL;
    f->hook_ctx = NULL;
    f->hook_flags = 0;
    return h;
}

static void hooks_attach(fluid_t *f, hooks_t h)
{
    f->stage_begin_hook = h.begin;
    f->stage_hook = h.stage;
    f->stage_end_hook = h.end;
    f->plane_hook = h.plane;
    f->hook_ctx = h.ctx;
    f->hook_flags = h.flags;
}

/* One fluid step, the slowest rank's wall time. */
static double time_step(fluid_t *f, double dt)
{
    MPI_Barrier(MPI_COMM_WORLD);
    double t0 = wtime();
    fluid_step(f, dt);
    double t = wtime() - t0;
    MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return t;
}

/* A floor for the immersed boundary's work per fluid step, whatever the data
 * structure: the same arithmetic on flat arrays of the same sizes (this
 * rank's node entries and distinct forced nodes), best of `reps`:
 *   α of every entry (one square root, one division and the table of
 *   alpha.c: the profile of ibm_alpha with λσ folded into one quotient),
 *   three forcings u ← u + β(Ū − u) storing the impulse (β, Ū, impulse, u:
 *   the arrays force_node_runs streams),
 *   one pass of the end-of-step sums (α_p u and its moment, the impulse
 *   share α_p/Σα J and its moment).
 * Returns the three times in t[0..2]. */
static void ibm_floor(long entries, long nodes, int reps, double t[3])
{
    enum { NT = 8192 };
    static double tab[NT + 2];
    for (int i = 0; i <= NT; i++) tab[i] = 0.5 * (1.0 - tanh(i * 3.45 / NT));
    tab[NT + 1] = 0.0;
    long ne = entries > 1 ? entries : 1, nn = nodes > 1 ? nodes : 1;
    double *z = xcalloc((size_t)ne, sizeof *z), *p2 = xcalloc((size_t)ne, sizeof *p2), *pa = xcalloc((size_t)ne, sizeof *pa);
    double *al = xcalloc((size_t)ne, sizeof *al), *A = xcalloc((size_t)nn, sizeof *A), *T = xcalloc((size_t)nn, sizeof *T);
    double *J = xcalloc((size_t)nn, sizeof *J), *u = xcalloc((size_t)nn, sizeof *u);
    unsigned long seed = 7;
    for (long k = 0; k < ne; k++) { /* offsets within a band of ±2.3 cells around R = 5 cells */
        z[k] = 14.0 * (urand(&seed) - 0.5);
        p2[k] = 30.0 * urand(&seed);
        pa[k] = 1.2 * sqrt(p2[k]);
    }
    for (long k = 0; k < nn; k++) A[k] = 0.2 + 0.9 * urand(&seed), T[k] = urand(&seed), u[k] = urand(&seed);
    double best[3] = {INFINITY, INFINITY, INFINITY}, sink = 0.0, ts = NT / 3.45 / M_SQRT2;
    for (int r = 0; r < reps; r++) {
        double t0 = wtime();
        for (long k = 0; k < ne; k++) {
            double rr = sqrt(p2[k] + z[k] * z[k]), S = pa[k] + fabs(z[k]);
            double x = (rr - 5.0) * ts * rr * rr * rr / ((0.455 * rr * rr - 0.065 * S * S) * S);
            al[k] = x < -NT ? -NT : (x > NT ? NT : x);
        }
        for (long k = 0; k < ne; k++) {
            double xa = fabs(al[k]);
            int i = (int)xa;
            double f = tab[i] + (xa - i) * (tab[i + 1] - tab[i]);
            al[k] = al[k] < 0.0 ? 1.0 - f : f;
        }
        double t1 = wtime();
        for (int stage = 0; stage < 3; stage++)
            for (long k = 0; k < nn; k++) {
                double imp = (A[k] < 1.0 ? A[k] : 1.0) * (T[k] - u[k]);
                u[k] += imp;
                J[k] = stage ? J[k] + imp : imp;
            }
        double t2 = wtime(), m0 = 0, m1 = 0, j0 = 0, j1 = 0;
        for (long k = 0; k < ne; k++) {
            long n = k < nn ? k : k - nn;
            double a = al[k] * u[n], sh = al[k] / A[n] * J[n];
            m0 += a, m1 += z[k] * a, j0 += sh, j1 += z[k] * sh;
        }
        double t3 = wtime();
        sink += m0 + m1 + j0 + j1;
        best[0] = fmin(best[0], t1 - t0), best[1] = fmin(best[1], t2 - t1), best[2] = fmin(best[2], t3 - t2);
    }
    memcpy(t, best, sizeof best);
    if (sink == 42.0) msg("(unlikely)\n"); /* keeps the sums live */
    free(z), free(p2), free(pa), free(al), free(A), free(T), free(J), free(u);
}

/* Best of `steps` fluid steps (the slowest rank's time of each step): the
 * machine is shared, and the best step is the least disturbed one. */
static double time_steps(fluid_t *f, int steps, double dt)
{
    double best = INFINITY;
    for (int s = 0; s < steps; s++) {
        MPI_Barrier(MPI_COMM_WORLD);
        double t0 = wtime();
        fluid_step(f, dt);
        double t = wtime() - t0;
        MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        best = fmin(best, t);
    }
    return best;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int N = argc > 1 ? atoi(argv[1]) : 128;
    int count = argc > 2 ? atoi(argv[2]) : 1000;
    double dpd = argc > 3 ? atof(argv[3]) : 10;
    int steps = argc > 4 ? atoi(argv[4]) : 5;
    int implicit = argc > 5 && !strcmp(argv[5], "implicit");
    const char *only = argc > 6 ? argv[6] : NULL;

    double dx = 1.0 / dpd, L = N * dx;
    int n[3] = {N, N, N};
    double Lv[3] = {L, L, L};
    grid_t *g = grid_create(GEOM_3D, n, Lv, NULL, NULL, STRETCH_UNIFORM, 0, MPI_COMM_WORLD);
    fluid_params_t prm;
    memset(&prm, 0, sizeof prm);
    prm.nu = 0.01;
    prm.rho = 1;
    prm.implicit_viscous = implicit;
    prm.poisson.method = POISSON_FFT;
    fluid_t *f = fluid_create(g, &prm);

    /* random sequential addition, identical on every rank */
    ibm_sphere_t *s = xcalloc((size_t)count, sizeof *s);
    unsigned long seed = 12345;
    int placed = 0;
    for (long tries = 0; placed < count && tries < 1000000L * count; tries++) {
        double x[3];
        for (int d = 0; d < 3; d++) x[d] = L * urand(&seed);
        int ok = 1;
        for (int q = 0; q < placed && ok; q++) {
            double r2 = 0;
            for (int d = 0; d < 3; d++) {
                double dd = x[d] - s[q].x[d];
                dd -= L * round(dd / L);
                r2 += dd * dd;
            }
            ok = r2 >= 1.0;
        }
        if (!ok) continue;
        s[placed].kind = IBM_FREE;
        s[placed].radius = 0.5;
        s[placed].density = 2.0;
        memcpy(s[placed].x, x, sizeof x);
        s[placed].history = -1;
        placed++;
    }
    if (placed < count) die("could place only %d of %d spheres", placed, count);
    double phi = count * M_PI / 6 / (L * L * L);

    double dt = 0.2 * dx; /* a CFL of 0.2 at unit velocity */
    if (!implicit) dt = fmin(dt, 0.5 * dx * dx / (6 * prm.nu));
    fluid_step(f, dt); /* warm-up: FFTW plans, first touches */
    double t_fluid0 = time_steps(f, steps, dt); /* before any sphere exists: the reference of the log */

    msg("bench_ibm: %d^3 cells, %d ranks, %s viscous term; %d spheres at D/dx = %g (solid fraction %.3f)\n", N,
        g->nranks, implicit ? "Crank-Nicolson" : "explicit", count, dpd, phi);
    msg("  fluid step alone            %8.4f s (before the spheres; each variant times its own, interleaved)\n",
        t_fluid0);
    long entries = 0, distinct = 0; /* this rank's, from a variant run (for the floor) */
    /* the variants, each timed after one warm-up step with its spheres */
    static const struct {
        const char *name, *what;
        ibm_kind_t kind;
        int move, free_step, gaps;
    } variant[] = {
        {"external_moving", "external spheres (DEM-coupled) moved by 0.01 dx between steps, alpha rebuilt every step",
         IBM_EXTERNAL, 1, 0},
        {"external_rest", "external spheres at rest (alpha built once)", IBM_EXTERNAL, 0, 0},
        {"free", "free spheres (rho_p/rho = 2 under gravity, alpha rebuilt at every stage)", IBM_FREE, 0, 0},
        {"free_step", "free spheres, [ibm] free_alpha = step (alpha held over the step, rebuilt once per step)",
         IBM_FREE, 0, 1},
        {"external_moving_gaps", "external spheres moved as external_moving, radius_correction = gaps, forcing_time = 0.2",
         IBM_EXTERNAL, 1, 0, 1},
    };
    for (int v = 0; v < (int)(sizeof variant / sizeof variant[0]); v++) {
        if (only && strcmp(only, variant[v].name)) continue;
        for (int p = 0; p < count; p++) {
            s[p].kind = variant[v].kind;
            memset(s[p].u, 0, sizeof s[p].u);
            memset(s[p].omega, 0, sizeof s[p].omega);
        }
        ibm_params_t ip = ibm_default_params();
        ip.gravity[1] = -1.0;
        ip.free_alpha_per_step = variant[v].free_step;
        if (variant[v].gaps) {
            ip.radius_calibrated = IBM_RADIUS_GAPS;
            ip.forcing_time = 0.2;
        }
        ibm_t *ibm = ibm_create(f, &ip, s, count);
        /* external spheres: a small displacement between steps along a fixed
         * random direction per sphere, as the DEM would make, with the
         * matching velocity */
        double *dir = xcalloc(3 * (size_t)count, sizeof *dir);
        for (int p = 0; p < count; p++) {
            for (int d = 0; d < 3; d++) dir[3 * p + d] = urand(&seed) - 0.5;
            double nrm = sqrt(dir[3 * p] * dir[3 * p] + dir[3 * p + 1] * dir[3 * p + 1] + dir[3 * p + 2] * dir[3 * p + 2]);
            for (int d = 0; d < 3; d++) dir[3 * p + d] *= 0.01 * dx / nrm;
        }
        /* the step with the spheres (and its immersed-boundary timers) that
         * took the least time: w = {alpha, forcing, integrals, total} */
        double t_both = INFINITY, t_fluid = INFINITY, w[4] = {0, 0, 0, 0};
        for (int it = 0; it <= steps; it++) { /* step 0: warm-up */
            hooks_t h = hooks_detach(f);
            double ta = time_step(f, dt);
            hooks_attach(f, h);
            if (it > 0) t_fluid = fmin(t_fluid, ta);
            double a0 = ibm->wall_alpha, f0 = ibm->wall_forcing, i0 = ibm->wall_integrals;
            MPI_Barrier(MPI_COMM_WORLD);
            double t0 = wtime();
            if (variant[v].move) {
                for (int p = 0; p < count; p++)
                    for (int d = 0; d < 3; d++) {
                        ibm->s[p].x[d] += dir[3 * p + d];
                        ibm->s[p].u[d] = dir[3 * p + d] / dt;
                    }
                ibm_update_geometry(ibm);
            }
            fluid_step(f, dt);
            double t[5] = {wtime() - t0, ibm->wall_alpha - a0, ibm->wall_forcing - f0, ibm->wall_integrals - i0, 0};
            t[4] = t[1] + t[2] + t[3];
            MPI_Allreduce(MPI_IN_PLACE, t, 5, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
            if (it > 0 && t[0] < t_both) {
                t_both = t[0];
                memcpy(w, t + 1, sizeof w);
            }
        }
        double nodes = grid_sum(g, (double)ibm->nodes_forced), shared = grid_sum(g, (double)ibm->nodes_shared);
        if (!variant[v].gaps) { /* the floor: decision 1's band */
            entries = ibm->nodes_forced;
            distinct = ibm->nodes_distinct;
        }
        msg("  %s:\n", variant[v].what);
        msg("    fluid step alone            %8.4f s (interleaved)\n", t_fluid);
        msg("    fluid step with the spheres %8.4f s (difference %.4f s)\n", t_both, t_both - t_fluid);
        msg("    cost of the spheres         %8.1f %% of the fluid step  (the difference; target <= 25 %%)\n",
            100 * (t_both - t_fluid) / t_fluid);
        msg("    immersed-boundary timers    %8.4f s = %.1f %%: alpha %.4f, forcing %.4f, integrals + update %.4f\n",
            w[3], 100 * w[3] / t_fluid, w[0], w[1], w[2]);
        msg("    node entries per sphere     %8.0f, %.1f %% at nodes shared with another sphere\n", nodes / count,
            100 * shared / nodes);
        /* one line per variant for bench/run.sh */
        msg("ibm_result case=%s N=%d spheres=%d dpd=%g ranks=%d viscous=%s fluid_step=%.4f with_ibm=%.4f ibm=%.4f "
            "alpha=%.4f forcing=%.4f integrals=%.4f fraction=%.3f timers_fraction=%.3f\n",
            variant[v].name, N, count, dpd, g->nranks, implicit ? "implicit" : "explicit", t_fluid, t_both, w[3], w[0],
            w[1], w[2], (t_both - t_fluid) / t_fluid, w[3] / t_fluid);
        free(dir);
        ibm_free(ibm);
    }
    if (entries > 0) {
        /* what any data structure must at least spend on this rank (the
         * slowest rank's time) for the moved external spheres: one α per
         * entry, three forcings, one pass of sums */
        double tf[3];
        ibm_floor(entries, distinct, steps, tf);
        MPI_Allreduce(MPI_IN_PLACE, tf, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        double tot = tf[0] + tf[1] + tf[2];
        msg("  floor (flat arrays, %ld entries and %ld forced nodes on rank 0): alpha %.4f s, three forcings %.4f s, "
            "sums %.4f s: %.4f s per step = %.1f %% of the fluid step\n",
            entries, distinct, tf[0], tf[1], tf[2], tot, 100 * tot / t_fluid0);
        msg("ibm_result case=floor N=%d spheres=%d dpd=%g ranks=%d viscous=%s fluid_step=%.4f ibm=%.4f alpha=%.4f "
            "forcing=%.4f integrals=%.4f fraction=%.3f\n",
            N, count, dpd, g->nranks, implicit ? "implicit" : "explicit", t_fluid0, tot, tf[0], tf[1], tf[2],
            tot / t_fluid0);
    }
    free(s);
    fluid_free(f);
    grid_free(g);
    MPI_Finalize();
    return 0;
}
