/* bench_dem.c — the DEM benchmark scene of ../shared/bench/dem/README.md run
 * by ibmdem: N spheres d = 2 mm in a box walled on all six faces, linear
 * spring–dashpot with the LIGGGHTS hooke/stiffness constants (k_n = 5419.27738987
 * N/m, γ_n/m* = 13862.9436112 1/s, k_t = 2/7 k_n, μ = 0.5, no tangential
 * damping, no rolling resistance, normal force not clipped as in LIGGGHTS'
 * default), dt = 2e-6 s, skin 0.1 d, gravity −9.81 z.
 *
 * usage: bench_dem DATA NSTEPS TAG [OUT.data] [replicated|split] [THREADS]
 * Prints one line "BENCH tag ..." with the loop time (wall and CPU time of rank 0's
 * process: on a shared machine the CPU time is the robust measure), particle-steps/s and the
 * fingerprint of the final state (as the LIGGGHTS input computes it:
 * centre-of-mass height, packing fraction N V_p/(L_x L_y 2 z̄), mean
 * coordination number 2 × overlapping pairs / N), and the memory per particle.
 */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "dem.h"
#include "modules.h"
#include "util.h"

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    if (argc < 4) {
        msg("usage: bench_dem DATA NSTEPS TAG [OUT.data] [replicated|split] [THREADS]\n");
        MPI_Finalize();
        return 1;
    }
    modules_register_keys();
    const char *data = argv[1];
    const long nsteps = atol(argv[2]);
    const char *tag = argv[3];
    const char *out = argc > 4 && strcmp(argv[4], "-") ? argv[4] : NULL;
    const char *par = argc > 5 ? argv[5] : "auto";
    const int threads = argc > 6 ? atoi(argv[6]) : 1;
    char text[2048];
    snprintf(text, sizeof text,
             "[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\nz_lo = noslip\nz_hi = noslip\n"
             "[particles]\nsource = lammps_data\nfile = %s\n"
             "[contact]\nlaw = linear\nparameters = stiffness\nkn = 5419.27738987\ngamma_n = 13862.9436112\n"
             "kt_ratio = 0.285714285714285714\nfriction = 0.5\nnormal_clip = false\n"
             "[dem]\ngravity = 0 0 -9.81\ndt = 2e-6\nskin = 0.1\nmax_overlap = 0.2\nparallel = %s\nthreads = %d\n",
             data, par, threads);
    cfg_t *cfg = cfg_load_string("bench_dem", text, 0, NULL);
    if (!cfg) die("bench_dem: bad configuration");
    const long rss0 = peak_rss_bytes();
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    const int n = dem_count(d);
    dem_status_t st = dem_run_steps(d, 0); /* set up: lists and forces of the initial state */
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = wtime(), c0 = cputime();
    if (st == DEM_OK) st = dem_run_steps(d, nsteps);
    const double cpu = cputime() - c0;
    MPI_Barrier(MPI_COMM_WORLD);
    const double loop = wtime() - t0;
    if (st != DEM_OK) die("bench_dem: %s", dem_error(d));
    dem_diag_t g;
    dem_diag(d, &g);
    const double *x = dem_positions(d);
    double zmax = -1e300, L[3] = {0, 0, 0}, lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int i = 0; i < n; i++) zmax = fmax(zmax, x[3 * i + 2]);
    {
        /* box size from the data file header, as LIGGGHTS' lx, ly */
        FILE *fp = fopen(data, "r");
        char line[512];
        while (fp && fgets(line, sizeof line, fp)) {
            double a, b;
            char s1[16];
            if (sscanf(line, "%lf %lf %15s", &a, &b, s1) == 3) {
                const int ax = !strcmp(s1, "xlo") ? 0 : !strcmp(s1, "ylo") ? 1 : !strcmp(s1, "zlo") ? 2 : -1;
                if (ax >= 0) {
                    lo[ax] = a;
                    hi[ax] = b;
                }
            }
            if (strstr(line, "Atoms")) break;
        }
        if (fp) fclose(fp);
        for (int a = 0; a < 3; a++) L[a] = hi[a] - lo[a];
    }
    const double vp = M_PI / 6.0 * 0.002 * 0.002 * 0.002;
    const double phi = n * vp / (L[0] * L[1] * 2.0 * g.com[2]);
    const double zmean = 2.0 * g.n_contacts / n;
    const double pps = loop > 0 ? (double)n * nsteps / loop : 0;
    const double cpu_pps = cpu > 0 ? (double)n * nsteps / cpu : 0;
    const long rss = peak_rss_bytes();
    msg("BENCH %s: ranks= %d threads= %d N= %d steps= %ld loop= %.4f s particle_steps_per_s= %.6g cpu= %.4f s cpu_particle_steps_per_s= %.6g zbar= %.10g zmax= %.10g "
        "phi_com= %.6f Zmean= %.5f ke= %.6g mem_alloc_per_particle= %.1f B peak_rss_per_particle= %.1f B "
        "(rss growth %.1f B) rebuilds= %ld\n",
        tag, mpi_size(), threads, n, nsteps, loop, pps, cpu, cpu_pps, g.com[2], zmax, phi, zmean, g.ke_trans, dem_memory_per_particle(d),
        (double)rss / n, (double)(rss - rss0) / n, g.rebuilds);
    dem_print_timers(d);
    if (out) dem_write_lammps_data(d, out);
    dem_free(d);
    cfg_free(cfg);
    MPI_Finalize();
    return 0;
}
