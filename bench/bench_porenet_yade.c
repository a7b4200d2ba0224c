/* bench_porenet_yade.c — the ibmdem half of the comparison with YADE's
 * FlowEngine (bench/porenet_vs_yade.sh, bench/porenet_yade.py).
 *
 * Writes the packing both codes use: N spheres, radii 1 ± 5 %, solid
 * fraction 0.58, relaxed in a cubic box [0, L]³ closed by six walls
 * (porenet_packing.h); the file has one "x y z r" line per sphere and the box
 * in a "# box 0 0 0 L L L" header line.  Then, on one rank:
 *
 *  1. permeability along z: p = 1 on z = 0, p = 0 on z = L, no flux through
 *     the four lateral walls (slip: symmetry planes, YADE's default
 *     slipBoundary), μ = 1, κ = μ Q L/(ΔP S) (pn_model_permeability);
 *  2. the coupled step: the DEM (linear spring–dashpot, gravity −z, walls)
 *     with the pore network coupled every step (pn_model_couple_dem, the
 *     driver's sequence), z = L at p = 0, no flux elsewhere, μ = 1.  The
 *     topology is built at the first coupled step and then kept for the timed
 *     steps (porenet.retriangulate large; YADE: meshUpdateInterval and
 *     defTolerance off): the time per step is that of a step on a fixed
 *     topology, the rebuild (triangulation + network + factorisation) is
 *     reported on its own.
 *
 * The permeability is computed with both models of the throats in the wall
 * planes (porenet.wall_throats = mirror, the default, and yade), with the CPU
 * time of each part (triangulation, network, factorisation, solve) and of the
 * whole; then once more with the mirror model and the earlier engine (qhull,
 * METIS ordering, images out to 6 r_max), whose kappa the default must give to
 * round-off.  The coupled step uses the default.  Times: CPU time of the
 * process (the machine is shared) and wall time.  Prints "RESULT ibmdem_perm ..." (one per model) and
 * "RESULT ibmdem_step ..." lines.  Extra "key = value" arguments go into
 * [porenet] of every part.
 *
 * usage: bench_porenet_yade N PACKING_OUT STEPS [key=value ...]
 * (REUSE=1 with PACKING_OUT present: the packing is read from it)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "config.h"
#include "dem.h"
#include "modules.h"
#include "porenet.h"
#include "porenet_packing.h"
#include "util.h"

/* A configuration text for the box [0, L]³ with the given [porenet] flow
 * lines and the extra [porenet] keys of the command line. */
static cfg_t *make_cfg(double L, const char *flow, int nextra, char **extra)
{
    char text[4096];
    int k = snprintf(text, sizeof text,
                     "[domain]\nlength = %.17g %.17g %.17g\n"
                     "[boundary]\nx_lo = noslip\nx_hi = noslip\ny_lo = noslip\ny_hi = noslip\nz_lo = noslip\n"
                     "z_hi = noslip\n"
                     "[particles]\nsource = none\ndensity = 2600\n"
                     "[contact]\nrestitution = 0.5\ncontact_time = 0.02\nfriction = 0.5\n"
                     "[dem]\ngravity = 0 0 -9.81\nsteps_per_contact = 20\nmax_overlap = 0.1\n"
                     "[porenet]\nviscosity = 1\nfluid_density = 1000\nretriangulate = 10\n%s",
                     L, L, L, flow);
    for (int i = 0; i < nextra && k < (int)sizeof text; i++) k += snprintf(text + k, sizeof text - k, "%s\n", extra[i]);
    cfg_t *cfg = cfg_load_string("bench_porenet_yade", text, 0, NULL);
    if (!cfg) die("bench_porenet_yade: bad configuration");
    return cfg;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    if (argc < 4) {
        msg("usage: bench_porenet_yade N PACKING_OUT STEPS [key=value ...]\n");
        MPI_Finalize();
        return 1;
    }
    modules_register_keys();
    const int n = atoi(argv[1]);
    const char *out = argv[2];
    const int steps = atoi(argv[3]);
    double *x = malloc(3 * (size_t)n * sizeof *x), *r = malloc((size_t)n * sizeof *r);
    /* REUSE=1 and the file exists: read the packing back (a repeated measurement, interleaved with
     * YADE's, without the cost of making it again) */
    FILE *in = getenv("REUSE") && atoi(getenv("REUSE")) ? fopen(out, "r") : NULL;
    double L = 0;
    if (in) {
        char line[512];
        int k = 0;
        while (fgets(line, sizeof line, in) && k <= n) {
            if (line[0] == '#') {
                double b0, b1, b2;
                if (sscanf(line, "# box %lf %lf %lf %lf", &b0, &b1, &b2, &L) != 4) continue;
            } else if (k < n && sscanf(line, "%lf %lf %lf %lf", x + 3 * k, x + 3 * k + 1, x + 3 * k + 2, r + k) == 4)
                k++;
        }
        fclose(in);
        if (k != n || !(L > 0)) die("%s: not a packing of %d spheres", out, n);
    } else {
        L = make_packing(n, 0.58, 0.05, 99 + n, 1, x, r);
    }
    double worst = 0;
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) worst = fmax(worst, fmax(r[i] - x[3 * i + a], x[3 * i + a] + r[i] - L));
    if (mpi_rank() == 0 && !in) {
        FILE *f = fopen(out, "w");
        if (!f) die("cannot write %s", out);
        fprintf(f, "# %d spheres, radii 1 +- 5 %%, solid fraction 0.58, walled box (bench_porenet_yade)\n", n);
        fprintf(f, "# box 0 0 0 %.17g %.17g %.17g\n", L, L, L);
        for (int i = 0; i < n; i++) fprintf(f, "%.17g %.17g %.17g %.17g\n", x[3 * i], x[3 * i + 1], x[3 * i + 2], r[i]);
        fclose(f);
    }

    /* 1. permeability of the fixed packing, with both models of the wall-plane throats; then the
     * mirror model again with the previous engine (qhull, METIS, images out to 6 r_max): the
     * same kappa to round-off */
    static const char *const model[3] = {"mirror", "yade", "mirror"};
    static const char *const engine[3] = {"", "", "triangulation = qhull\nordering = metis\nmargin = %.17g\n"};
    double kappa0 = 0, rmax = 0;
    for (int i = 0; i < n; i++) rmax = fmax(rmax, r[i]);
    for (int wm = 0; wm < 3; wm++) {
        char flow[1024], eng[256];
        snprintf(eng, sizeof eng, engine[wm], 6 * rmax);
        snprintf(flow, sizeof flow,
                 "z_lo_flow = pressure\nz_lo_value = 1\nz_hi_flow = pressure\nz_hi_value = 0\n"
                 "x_lo = slip\nx_hi = slip\ny_lo = slip\ny_hi = slip\nz_lo = slip\nz_hi = slip\nwall_throats = %s\n%s",
                 model[wm], eng);
        cfg_t *cfg = make_cfg(L, flow, argc - 4, argv + 4);
        pn_model_t m;
        pn_model_from_config(cfg, &m);
        const double c0 = cputime();
        if (pn_model_step(&m, n, x, r, 0.0)) die("porenet: %s", m.err);
        const double c_total = cputime() - c0;
        const double kappa = pn_model_permeability(&m, 2);
        if (wm == 0) kappa0 = kappa;
        double q[6];
        pn_face_fluxes(&m.dom, &m.net, m.p, q);
        /* CPU times of the parts: triangulation, network (geometry, conductances), factorisation
         * (assembly, ordering, Cholesky), solve (right-hand side, back-substitution) */
        if (mpi_rank() == 0)
            printf("RESULT ibmdem_perm N= %d wall_throats= %s engine= %s L= %.10g kappa= %.10e kappa/d2= %.10e Q_in= %.10e "
                   "Q_out= %.10e pores= %d throats= %d tri_s= %.4g net_s= %.4g factor_s= %.4g solve_s= %.4g total_s= %.4g "
                   "points= %d margin_rmax= %.3g wall_overlap= %.2e kappa_rel_to_first= %.2e\n",
                   n, model[wm], wm == 2 ? "qhull+metis+6rmax" : "default", L, kappa, kappa / 4.0, q[4], -q[5], m.net.npore,
                   m.net.nthroat, m.t_tri, m.t_net, m.t_factor, m.t_solve, c_total, m.tri.npts, m.tri.margin / rmax,
                   fmax(worst, 0), kappa / kappa0 - 1);
        fflush(stdout);
        pn_model_free(&m);
        cfg_free(cfg);
    }

    /* 2. the coupled step */
    cfg_t *cfg = make_cfg(L, "z_hi_flow = pressure\nz_hi_value = 0\n"
                      "x_lo = slip\nx_hi = slip\ny_lo = slip\ny_hi = slip\nz_lo = slip\nz_hi = slip\n",
                   argc - 4, argv + 4);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    const double v0[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) dem_add_particle(d, x + 3 * i, v0, r[i], 2600, 0);
    pn_model_t m;
    pn_model_from_config(cfg, &m);
    double g[3];
    cfg_vec3(cfg, "dem", "gravity", g);
    if (dem_advance(d, dem_time(d)) != DEM_OK) die("dem: %s", dem_error(d)); /* lists, forces of the initial state */
    double t0 = wtime(), c0 = cputime();
    if (pn_model_couple_dem(&m, d, g, 0.0)) die("porenet: %s", m.err);
    const double t_build = wtime() - t0, c_build = cputime() - c0;
    const double dt = dem_dt(d);
    double t_dem = 0, t_pn = 0, c_dem = 0, c_pn = 0;
    const long retri0 = m.n_retri;
    for (int s = 0; s < steps; s++) {
        const double a = wtime(), ca = cputime();
        if (dem_step(d) != DEM_OK) die("dem: %s", dem_error(d));
        const double b = wtime(), cb = cputime();
        if (pn_model_couple_dem(&m, d, g, dt)) die("porenet: %s", m.err);
        t_dem += b - a;
        t_pn += wtime() - b;
        c_dem += cb - ca;
        c_pn += cputime() - cb;
    }
    if (mpi_rank() == 0)
        printf("RESULT ibmdem_step N= %d steps= %d cpu_step_ms= %.5g cpu_dem_ms= %.5g cpu_flow_ms= %.5g cpu_first_s= %.4g "
               "wall_step_ms= %.5g wall_dem_ms= %.5g wall_flow_ms= %.5g wall_first_s= %.4g (tri %.4g net %.4g factor %.4g) "
               "retriangulations= %ld dt= %.3g pores= %d\n",
               n, steps, 1e3 * (c_dem + c_pn) / steps, 1e3 * c_dem / steps, 1e3 * c_pn / steps, c_build,
               1e3 * (t_dem + t_pn) / steps, 1e3 * t_dem / steps, 1e3 * t_pn / steps, t_build, m.t_tri, m.t_net,
               m.t_factor, m.n_retri - retri0, dt, m.net.npore);
    pn_model_free(&m);
    dem_free(d);
    cfg_free(cfg);
    free(x);
    free(r);
    MPI_Finalize();
    return 0;
}
