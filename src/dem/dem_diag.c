/* dem_diag.c — what the DEM reports about itself: memory per particle, the
 * shares of contact and lubrication force (dem_force_stats_*), timers, the
 * elastic energy stored in the contacts, the diagnostics of summary.json and
 * series.csv (dem_diag, dem_diag_light) and the time to the next contact
 * (dem_time_to_contact, the coupled step's limit for particles from rest).
 * Storage and time integration are in dem.c.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "util.h"

double dem_memory_per_particle(const dem_t *d)
{
    const double n = d->n > 0 ? d->n : 1;
    double bytes = (double)d->cap * (9 * 3 * sizeof(double) + 4 * sizeof(double) + sizeof(long) + 1);
    bytes += (double)d->nb_cap * (sizeof(int) + 2 + 3 * sizeof(double)) + (double)(d->n + 1) * sizeof(int);
    bytes += (double)(d->ncell + 1) * sizeof(int) + 2.0 * (d->n + 1) * sizeof(int);
    for (int w = 0; w < d->nwall; w++) bytes += (double)d->wall[w].cap * (sizeof(int) + 1 + 3 * sizeof(double));
    bytes += (double)d->lub_work_cap * dem_lubrication_work_bytes();
    return bytes / n;
}

void dem_force_stats_enable(dem_t *d, int on) { d->fstat.on = on; }

void dem_force_stats_take(dem_t *d, dem_force_stats_t *out)
{
    double c[2] = {d->fstat.contact_norm, d->fstat.contacts};
    if (d->split) MPI_Allreduce(MPI_IN_PLACE, c, 2, MPI_DOUBLE, MPI_SUM, d->comm);
    out->steps = d->fstat.steps;
    out->contact_norm = c[0];
    out->contacts = c[1];
    out->lub_norm = d->fstat.lub_norm;
    out->lubricated = d->fstat.lubricated;
    d->fstat.steps = 0;
    d->fstat.contact_norm = d->fstat.contacts = d->fstat.lub_norm = d->fstat.lubricated = 0.0;
}

double dem_lubrication_seconds(const dem_t *d) { return d->t_lub; }

void dem_print_timers(const dem_t *d)
{
    msg("dem timers: pairs %.3f s, walls %.3f s, lists %.3f s (%ld builds), integration %.3f s, communication %.3f s\n",
        d->t_pair, d->t_wall, d->t_build, d->rebuilds, d->t_integ, d->t_comm);
}

/* ---- diagnostics ---- */

double dem_elastic_energy(const dem_t *d)
{
    double e = 0.0;
    const int lo = d->split ? d->row_lo : 0, hi = d->split ? d->row_hi : d->n;
    for (int i = lo; i < d->nb_n_rows && i < hi; i++)
        for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++) {
            const int j = d->nb_j[k];
            const double *s = d->shift[d->nb_img[k]];
            double r2 = 0;
            for (int a = 0; a < 3; a++) {
                const double dx = d->x[3 * i + a] - d->x[3 * j + a] - (d->any_periodic ? s[a] : 0.0);
                r2 += dx * dx;
            }
            const double delta = d->r[i] + d->r[j] - sqrt(r2);
            if (delta <= 0) continue;
            const double *xi = d->nb_hist + 3 * k;
            e += d->law->energy(&d->cp, delta, 1.0 / (d->invm[i] + d->invm[j]), d->r[i] * d->r[j] / (d->r[i] + d->r[j]),
                                xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
        }
    for (int w = 0; w < d->nwall; w++) {
        const dem_wall_t *W = &d->wall[w];
        if (!W->active) continue;
        for (int e2 = 0; e2 < W->nlist; e2++) {
            const int i = W->idx[e2];
            if (i < lo || i >= hi) continue;
            double dist = 0;
            for (int a = 0; a < 3; a++) dist += (d->x[3 * i + a] - W->p[a]) * W->n[a];
            const double delta = d->r[i] - dist;
            if (delta <= 0) continue;
            const double *xi = W->hist + 3 * e2;
            e += d->law->energy(&d->cp, delta, 1.0 / d->invm[i], d->r[i], xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
        }
    }
    return e;
}

int dem_snapshot_count(const dem_t *d) { return d->nsnap ? d->snap_index[d->nsnap - 1] + 1 : 0; }

void dem_diag(dem_t *d, dem_diag_t *o)
{
    dem_diag_light(d, o);
    o->e_elastic = d->ready ? dem_elastic_energy(d) : 0.0;
    if (d->split) MPI_Allreduce(MPI_IN_PLACE, &o->e_elastic, 1, MPI_DOUBLE, MPI_SUM, d->comm);
}

void dem_diag_light(dem_t *d, dem_diag_t *o)
{
    dem_sync_velocities(d);
    memset(o, 0, sizeof *o);
    o->time = d->time;
    o->step = d->step;
    o->n_particles = d->n;
    double m_tot = 0;
    for (int i = 0; i < d->n; i++) {
        if (d->fixed[i]) continue;
        o->n_mobile++;
        const double m = 1.0 / d->invm[i], I = 1.0 / d->invI[i];
        double v2 = 0, w2 = 0;
        for (int a = 0; a < 3; a++) {
            v2 += d->v[3 * i + a] * d->v[3 * i + a];
            w2 += d->w[3 * i + a] * d->w[3 * i + a];
            o->momentum[a] += m * d->v[3 * i + a];
            o->ke_axis[a] += 0.5 * m * d->v[3 * i + a] * d->v[3 * i + a];
            o->com[a] += m * d->x[3 * i + a];
        }
        m_tot += m;
        o->ke_trans += 0.5 * m * v2;
        o->ke_rot += 0.5 * I * w2;
    }
    for (int a = 0; a < 3; a++) o->com[a] = m_tot > 0 ? o->com[a] / m_tot : 0.0;
    o->n_contacts = d->n_contacts;
    o->n_wall_contacts = d->n_wall_contacts;
    o->max_overlap = d->max_overlap;
    if (d->split) MPI_Allreduce(MPI_IN_PLACE, &o->max_overlap, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    o->rebuilds = d->rebuilds;
    o->contacts_started = d->n_starts;
    if (d->split) MPI_Allreduce(MPI_IN_PLACE, &o->contacts_started, 1, MPI_LONG, MPI_SUM, d->comm);
}

/* Acceleration of particle i between contacts: gravity and the external
 * (held hydrodynamic) force. */
static void free_acceleration(const dem_t *d, int i, double acc[3])
{
    for (int a = 0; a < 3; a++)
        acc[a] = d->fixed[i] ? 0.0 : d->gravity[a] + (d->use_ext ? d->fext[3 * i + a] * d->invm[i] : 0.0);
}

/* The time for a gap to close: at constant velocity, or, when the pair is
 * lubricated, along the lubricated approach with the pair's free
 * acceleration a (dem_lub_approach_time), whose slow-down the constant
 * velocity misses.  The lubrication only slows the approach, so the time
 * without it, t₀ (u t + a t²/2 = gap), is a lower bound: a pair whose t₀ is
 * beyond `horizon` or not below `best` (the earliest contact found so far)
 * is not integrated. */
static double closing_time(const dem_t *d, int lub, double R, double reff, double m, double gap, double u, double a,
                           double horizon, double best)
{
    if (u <= 0) return INFINITY; /* not approaching now: a later step predicts its contact */
    if (!lub) return gap / u;
    const double disc = u * u + 2.0 * a * gap;
    if (disc < 0) return INFINITY; /* decelerated to rest before the gap closes, even without lubrication */
    const double t0 = 2.0 * gap / (u + sqrt(disc)); /* the root of u t + a t²/2 = gap, without cancellation */
    if (t0 > horizon || t0 >= best) return t0; /* not the first contact within the horizon */
    return dem_lub_approach_time(d, R, reff, m, gap, u, a);
}

double dem_time_to_contact(const dem_t *d, double horizon)
{
    /* pairs from the neighbour lists (every pair that can touch before the next rebuild),
     * walls directly; the minimum over the ranks of a split DEM */
    double tmin = INFINITY;
    const int lub = d->lub.on;
    if (d->nb_start)
        for (int i = 0; i < d->nb_n_rows; i++)
            for (long e = d->nb_start[i]; e < d->nb_start[i + 1]; e++) {
                const int j = d->nb_j[e];
                double n[3], ai[3], aj[3];
                const double gap = dem_pair_normal(d, i, e, n) - d->r[i] - d->r[j];
                if (gap <= 0) {
                    tmin = 0.0;
                    goto reduce;
                }
                const double u = dem_pair_approach(d, i, j, n);
                if (d->invm[i] == 0 && d->invm[j] == 0) continue;
                free_acceleration(d, i, ai);
                free_acceleration(d, j, aj);
                const double a = (ai[0] - aj[0]) * n[0] + (ai[1] - aj[1]) * n[1] + (ai[2] - aj[2]) * n[2];
                const double R = d->r[i] < d->r[j] ? d->r[i] : d->r[j], reff = d->r[i] * d->r[j] / (d->r[i] + d->r[j]);
                const double t = closing_time(d, lub, R, reff, 1.0 / (d->invm[i] + d->invm[j]), gap, u, a, horizon, tmin);
                if (t < tmin) tmin = t;
            }
    for (int w = 0; w < d->nwall; w++) {
        const dem_wall_t *W = &d->wall[w];
        if (!W->active) continue;
        for (int i = 0; i < d->n; i++) {
            if (d->fixed[i]) continue;
            double u, acc[3];
            const double gap = dem_wall_gap(d, W, i, &u);
            if (gap <= 0) {
                tmin = 0.0;
                goto reduce;
            }
            free_acceleration(d, i, acc);
            const double a = -(acc[0] * W->n[0] + acc[1] * W->n[1] + acc[2] * W->n[2]);
            const double t = closing_time(d, lub && d->lub.walls, d->r[i], d->r[i], 1.0 / d->invm[i], gap, u, a, horizon, tmin);
            if (t < tmin) tmin = t;
        }
    }
reduce: /* a split DEM: every rank must take the same fluid step */
    if (d->split) MPI_Allreduce(MPI_IN_PLACE, &tmin, 1, MPI_DOUBLE, MPI_MIN, d->comm);
    return tmin;
}
