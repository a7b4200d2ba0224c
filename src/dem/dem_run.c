/* dem_run.c — packing preparation and the DEM-only run of a case file. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "util.h"

/* Mean mass and mean diameter of the mobile particles; their number. */
static long mobile_means(const dem_t *d, double *m, double *dia)
{
    double msum = 0, dsum = 0;
    long nm = 0;
    for (int i = 0; i < d->n; i++)
        if (!d->fixed[i]) {
            msum += 1.0 / d->invm[i];
            dsum += 2 * d->r[i];
            nm++;
        }
    *m = nm ? msum / nm : 0;
    *dia = nm ? dsum / nm : 0;
    return nm;
}

/* Rate of change of the grains: rms velocity / mean diameter (1/s) of the
 * mobile particles, INFINITY before `after` (time.steady_tol, as the fluid's
 * relative rate of change per unit time). */
double dem_rest_rate(dem_t *d, double after)
{
    if (d->time < after) return INFINITY;
    dem_diag_t g;
    dem_diag_light(d, &g);
    double m, dia;
    const long nm = mobile_means(d, &m, &dia);
    return nm ? sqrt(2 * g.ke_trans / (nm * m)) / dia : 0.0;
}

/* Kinetic energy per mobile particle relative to m̄ g d̄ (rest criterion). */
static double rest_measure(dem_t *d, const double g[3])
{
    dem_diag_t dg;
    dem_diag_light(d, &dg);
    double m, dia;
    const long nm = mobile_means(d, &m, &dia);
    const double gm = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    return nm ? (dg.ke_trans + dg.ke_rot) / nm / (m * (gm > 0 ? gm : 1.0) * dia) : 0.0;
}

int dem_prepare_packing(dem_t *d, cfg_t *cfg, const char *outdir)
{
    if (!cfg_bool(cfg, "packing", "prepare")) {
        dem_freeze_below(d, cfg);
        return 0;
    }
    const int variant = cfg_enum(cfg, "packing", "variant");
    const double tmax = cfg_double(cfg, "packing", "max_time");
    const double crit = cfg_double(cfg, "packing", "rest_energy");
    double g[3], g_run[3];
    for (int a = 0; a < 3; a++) g_run[a] = d->gravity[a];
    if (cfg_has(cfg, "packing", "gravity"))
        cfg_vec3(cfg, "packing", "gravity", g);
    else
        for (int a = 0; a < 3; a++) g[a] = g_run[a];
    const double mu = d->cp.mu, mu_w = d->cp.mu_wall;
    if (variant == 0) d->cp.mu = d->cp.mu_wall = 0.0;
    if (variant == 1) d->cp.mu = d->cp.mu_wall = cfg_double(cfg, "packing", "loose_friction");
    /* walls that will be removed during the run hold the packing meanwhile */
    double trem[DEM_MAX_WALLS];
    for (int w = 0; w < d->nwall; w++) {
        trem[w] = d->wall[w].remove_time;
        d->wall[w].remove_time = INFINITY;
    }
    dem_set_gravity(d, g);
    /* a dry preparation: no lubrication (its pairs are most of the cost of
     * settling a dense bed, and it only slows the settling down), no drag */
    const int lub_on = d->lub.on, drag_on = d->drag.on;
    d->lub.on = d->drag.on = 0;
    static const char *vname[] = {"dense (frictionless)", "loose (high friction)", "with the run's contact law"};
    msg("dem: settling the packing %s, gravity (%g, %g, %g)\n", vname[variant], g[0], g[1], g[2]);
    const double t0 = d->time, w0 = wtime();
    int rc = 1;
    double e = 0;
    dem_status_t st = dem_advance(d, d->time); /* set up: lists, forces, dt */
    const double chunk = 200 * d->dt;
    while (st == DEM_OK) {
        st = dem_advance(d, d->time + chunk);
        if (st != DEM_OK) {
            rc = 10 + (int)st;
            break;
        }
        e = rest_measure(d, g);
        if (d->time - t0 > 20 * d->tc && e < crit) {
            rc = 0;
            break;
        }
        if (d->time - t0 >= tmax) break;
    }
    if (st != DEM_OK) rc = 10 + (int)st;
    msg("dem: settling %s after %.4g s (%.1f s wall): kinetic energy %.3g m g d per particle\n",
        rc == 0 ? "at rest" : "stopped", d->time - t0, wtime() - w0, e);
    if (rc == 1) warn("dem: packing not at rest after packing.max_time = %g s\n", tmax);
    d->lub.on = lub_on;
    d->drag.on = drag_on;
    d->cp.mu = mu;
    d->cp.mu_wall = mu_w;
    for (int w = 0; w < d->nwall; w++) d->wall[w].remove_time = trem[w];
    dem_set_gravity(d, g_run);
    d->time = 0.0;
    d->step = 0;
    dem_freeze_below(d, cfg);
    if (rc < 10) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", outdir, cfg_string(cfg, "packing", "output"));
        dem_write_checkpoint(d, path);
        msg("dem: packing written to %s\n", path);
    }
    return rc;
}

static void series_header(dem_t *d, FILE *fp)
{
    fprintf(fp, "time,step,ke_trans,ke_rot,e_elastic,n_contacts,n_wall_contacts,max_overlap,com_x,com_y,com_z");
    for (int w = 0; w < d->nwall; w++) fprintf(fp, ",%s_fx,%s_fy,%s_fz", d->wall[w].name, d->wall[w].name, d->wall[w].name);
    fprintf(fp, "\n");
}

static void series_line(dem_t *d, FILE *fp)
{
    dem_diag_t g;
    dem_diag(d, &g);
    if (!fp) return;
    fprintf(fp, "%.10g,%ld,%.10g,%.10g,%.10g,%ld,%ld,%.6g,%.10g,%.10g,%.10g", g.time, g.step, g.ke_trans, g.ke_rot,
            g.e_elastic, g.n_contacts, g.n_wall_contacts, g.max_overlap, g.com[0], g.com[1], g.com[2]);
    for (int w = 0; w < d->nwall; w++)
        fprintf(fp, ",%.10g,%.10g,%.10g", d->wall[w].force[0], d->wall[w].force[1], d->wall[w].force[2]);
    if (fprintf(fp, "\n") < 0 || fflush(fp) != 0) io_error("cannot write dem_series.csv: %s", strerror(errno));
}

int dem_run_case(cfg_t *cfg, const char *outdir)
{
    if (mpi_rank() == 0 && mkdir_p(outdir) != 0) die("cannot create output directory %s", outdir);
    MPI_Barrier(MPI_COMM_WORLD);
    const double t_end = cfg_double(cfg, "time", "t_end");
    double out_dt = cfg_double(cfg, "output", "fields_every");
    double ser_dt = cfg_double(cfg, "dem", "series_interval");
    const double steady_tol = cfg_double(cfg, "time", "steady_tol");
    const double rest_after = cfg_double(cfg, "dem", "rest_after");
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    if (d->n == 0) die("dem: the scene has no particles");
    char path[4096];
    if (mpi_rank() == 0) {
        char tmp[4112];
        snprintf(path, sizeof path, "%s/resolved.ini", outdir);
        FILE *fp = atomic_open(path, tmp, sizeof tmp);
        if (fp) {
            cfg_write_resolved(cfg, fp);
            atomic_commit(fp, tmp, path);
        }
    }
    int rc = dem_prepare_packing(d, cfg, outdir);
    if (rc >= 10) {
        snprintf(path, sizeof path, "%s/checkpoint_error.h5", outdir);
        dem_write_checkpoint(d, path);
        msg("dem: error during the packing preparation: %s\ndem: checkpoint written to %s\n", dem_error(d), path);
        dem_free(d);
        return 1;
    }
    if (ser_dt <= 0) ser_dt = t_end / 500;
    if (out_dt <= 0) out_dt = t_end;
    FILE *ser = NULL;
    if (mpi_rank() == 0) {
        snprintf(path, sizeof path, "%s/dem_series.csv", outdir);
        ser = fopen(path, "w");
        if (!ser) die_local("cannot write %s", path);
        series_header(d, ser);
    }
    int snap = 0;
    dem_write_snapshot(d, outdir, snap++);
    dem_status_t st = dem_advance(d, d->time); /* set up: lists, forces, dt */
    series_line(d, ser);
    msg("dem: %s\n", d->cp.summary);
    msg("dem: %d particles, t_c = %.4g s, dt = %.4g s (t_c/dt = %.1f), run to t = %g s\n", d->n, d->tc, d->dt,
        d->tc / d->dt, t_end);
    const double w0 = wtime();
    const long s0 = d->step;
    double next_out = d->time + out_dt, next_ser = d->time + ser_dt;
    int at_rest = 0;
    while (st == DEM_OK && d->time < t_end * (1 - 1e-12) && !at_rest) {
        double target = fmin(t_end, fmin(next_out, next_ser));
        st = dem_advance(d, target);
        if (st != DEM_OK) break;
        if (d->time >= next_ser * (1 - 1e-12)) {
            series_line(d, ser);
            next_ser += ser_dt;
            if (steady_tol > 0 && dem_rest_rate(d, rest_after) < steady_tol) {
                at_rest = 1;
                msg("dem: at rest at t = %g s\n", d->time);
            }
        }
        if (d->time >= next_out * (1 - 1e-12) && d->time < t_end * (1 - 1e-12)) {
            dem_write_snapshot(d, outdir, snap++);
            next_out += out_dt;
        }
    }
    const double wall = wtime() - w0;
    const long steps = d->step - s0;
    if (st != DEM_OK) {
        snprintf(path, sizeof path, "%s/checkpoint_error.h5", outdir);
        dem_write_checkpoint(d, path);
        msg("dem: error: %s\ndem: checkpoint written to %s\n", dem_error(d), path);
        if (ser) fclose(ser);
        dem_free(d);
        return 1;
    }
    dem_write_snapshot(d, outdir, snap++);
    snprintf(path, sizeof path, "%s/dem_final.h5", outdir);
    dem_write_checkpoint(d, path);
    if (ser && fclose(ser) != 0) io_error("cannot write %s/dem_series.csv: %s", outdir, strerror(errno));
    const double pps = wall > 0 ? (double)d->n * steps / wall : 0;
    msg("dem: %ld steps in %.2f s: %.3g particle-steps/s (pairs %.2f s, walls %.2f s, lists %.2f s, integration "
        "%.2f s, communication %.2f s), %ld list builds, %.0f bytes/particle\n",
        steps, wall, pps, d->t_pair, d->t_wall, d->t_build, d->t_integ, d->t_comm, d->rebuilds,
        dem_memory_per_particle(d));
    if (mpi_rank() == 0) {
        char tmp[4112];
        snprintf(path, sizeof path, "%s/dem_summary.json", outdir);
        FILE *fp = atomic_open(path, tmp, sizeof tmp);
        if (fp) {
            dem_diag_t g;
            dem_diag(d, &g);
            fprintf(fp,
                    "{\n  \"particles\": %d,\n  \"steps\": %ld,\n  \"time\": %.10g,\n  \"dt\": %.10g,\n  "
                    "\"contact_time\": %.10g,\n  \"wall_seconds\": %.6g,\n  \"particle_steps_per_second\": %.6g,\n  "
                    "\"at_rest\": %s,\n  \"ke_trans\": %.10g,\n  \"n_contacts\": %ld,\n  \"max_overlap\": %.6g,\n  "
                    "\"bytes_per_particle\": %.1f,\n  \"ranks\": %d\n}\n",
                    d->n, steps, d->time, d->dt, d->tc, wall, pps, at_rest ? "true" : "false", g.ke_trans,
                    g.n_contacts, g.max_overlap, dem_memory_per_particle(d), d->nranks);
            atomic_commit(fp, tmp, path);
        }
    } else {
        dem_diag_t g;
        dem_diag(d, &g);
    }
    dem_free(d);
    /* a write failed on some rank: the run's outputs are not complete */
    int bad = io_error_message()[0] != 0;
    MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (bad) {
        if (io_error_message()[0]) fprintf(stderr, "error: %s\n", io_error_message());
        return 1;
    }
    return 0;
}
