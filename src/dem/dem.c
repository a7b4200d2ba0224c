/* dem.c — particle storage and time integration of the DEM (its diagnostics: dem_diag.c).
 *
 * Integration: velocity Verlet (kick–drift–kick) for translation and
 * rotation,
 *     v(t+dt/2) = v(t) + dt/2 a(t),  x(t+dt) = x(t) + dt v(t+dt/2),
 *     forces at t+dt,                v(t+dt) = v(t+dt/2) + dt/2 a(t+dt),
 * with a = (F_contact + F_ext)/m + g and the same for ω with the torque
 * and I = (2/5) m R².  The closing kick of a step and the opening kick of the
 * next are fused in one pass over the particles while sub-cycling
 * (dem_advance); v and ω are brought to the full step when the call returns.
 * The dashpots see the predicted velocity v(t+dt/2) + dt/2 a(t), see
 * dem_kernel.inc.
 *
 * Time step: dt = t_c / n_c ([dem] steps_per_contact, ≥ 20), t_c the
 * shortest contact duration of the law; a given [dem] dt must not exceed
 * t_c/20.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "util.h"

/* ---- random numbers (xoshiro256**, seeded by splitmix64) ---- */

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

void dem_rng_seed(dem_rng_t *g, uint64_t seed)
{
    for (int i = 0; i < 4; i++) g->s[i] = splitmix64(&seed);
}

static inline uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

double dem_rng_uniform(dem_rng_t *g)
{
    uint64_t *s = g->s;
    const uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return (double)(result >> 11) * 0x1.0p-53;
}

/* ---- storage ---- */

static void *grow_array(void *p, size_t old_bytes, size_t new_bytes)
{
    void *q = xcalloc(1, new_bytes);
    if (p) {
        memcpy(q, p, old_bytes);
        free(p);
    }
    return q;
}

void dem_grow(dem_t *d, int need)
{
    if (need <= d->cap) return;
    int cap = d->cap ? d->cap : 64;
    while (cap < need) cap *= 2;
    const size_t o = (size_t)d->cap, c = (size_t)cap;
    double **v3[] = {&d->x, &d->v, &d->w, &d->f, &d->t, &d->dv, &d->dw, &d->fext, &d->text, &d->flub};
    for (size_t a = 0; a < sizeof v3 / sizeof v3[0]; a++)
        *v3[a] = grow_array(*v3[a], 3 * o * sizeof(double), 3 * c * sizeof(double));
    double **v1[] = {&d->r, &d->invm, &d->invI, &d->rho};
    for (size_t a = 0; a < sizeof v1 / sizeof v1[0]; a++)
        *v1[a] = grow_array(*v1[a], o * sizeof(double), c * sizeof(double));
    d->id = grow_array(d->id, o * sizeof(long), c * sizeof(long));
    d->fixed = grow_array(d->fixed, o, c);
    d->cap = cap;
}

int dem_add_particle(dem_t *d, const double x[3], const double v[3], double radius, double density, int fixed)
{
    if (!(radius > 0) || !(density > 0)) die("dem_add_particle: radius and density must be positive");
    dem_sync_velocities(d);
    dem_grow(d, d->n + 1);
    const int i = d->n++;
    const double m = density * dem_sphere_volume(radius);
    for (int a = 0; a < 3; a++) {
        d->x[3 * i + a] = x[a];
        d->v[3 * i + a] = fixed ? 0.0 : v[a];
        d->w[3 * i + a] = d->f[3 * i + a] = d->t[3 * i + a] = 0.0;
        d->dv[3 * i + a] = d->dw[3 * i + a] = d->fext[3 * i + a] = d->text[3 * i + a] = d->flub[3 * i + a] = 0.0;
    }
    d->r[i] = radius;
    d->rho[i] = density;
    d->invm[i] = fixed ? 0.0 : 1.0 / m;
    d->invI[i] = fixed ? 0.0 : 1.0 / (0.4 * m * radius * radius);
    d->id[i] = d->next_id++;
    d->fixed[i] = (unsigned char)(fixed != 0);
    d->ready = 0; /* lists and forces must be rebuilt */
    return i;
}

void dem_set_omega(dem_t *d, long id, const double w[3])
{
    for (int i = 0; i < d->n; i++)
        if (d->id[i] == id && !d->fixed[i])
            for (int a = 0; a < 3; a++) d->w[3 * i + a] = w[a];
    d->ready = 0;
}

void dem_add_wall(dem_t *d, const char *name, const double p[3], const double n[3], const double vel[3],
                  double remove_time)
{
    if (d->nwall == DEM_MAX_WALLS) die("dem: too many walls (max %d)", DEM_MAX_WALLS);
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(nn > 0)) die("dem: wall %s has a zero normal", name);
    dem_wall_t *W = &d->wall[d->nwall++];
    memset(W, 0, sizeof *W);
    snprintf(W->name, sizeof W->name, "%s", name);
    for (int a = 0; a < 3; a++) {
        W->p[a] = p[a];
        W->n[a] = n[a] / nn;
        W->vel[a] = vel ? vel[a] : 0.0;
    }
    W->remove_time = remove_time;
    W->active = 1;
    d->ready = 0;
}

void dem_free(dem_t *d)
{
    if (!d) return;
    dem_neigh_free(d);
    void *arr[] = {d->x, d->v, d->w, d->f, d->t, d->dv, d->dw, d->fext, d->text, d->flub,
                   d->r, d->invm, d->invI, d->rho, d->id, d->fixed};
    for (size_t a = 0; a < sizeof arr / sizeof arr[0]; a++) free(arr[a]);
    free(d->kernel_block);
    dem_lubrication_free(d);
    for (int q = 0; q < DEM_MAX_THREADS; q++) {
        free(d->tblock[q]);
        free(d->tforce[q]);
    }
    free(d->snap_t);
    free(d->snap_n);
    free(d->snap_index);
    dem_drag_free(d);
    free(d);
}

/* ---- time step ---- */

double dem_lightest_mass(const dem_t *d, double *rmin)
{
    double mmin = INFINITY, r = INFINITY;
    for (int i = 0; i < d->n; i++) {
        if (d->invm[i] > 0.0 && 1.0 / d->invm[i] < mmin) mmin = 1.0 / d->invm[i];
        if (d->r[i] < r) r = d->r[i];
    }
    if (rmin) *rmin = r;
    return mmin;
}

dem_status_t dem_set_dt(dem_t *d)
{
    d->tc = d->law->contact_time(d);
    if (d->dt_user > 0) {
        d->dt = d->dt_user;
        if (d->dt_user > d->tc / 20.0 * (1 + 1e-12)) {
            snprintf(d->errmsg, sizeof d->errmsg,
                     "dem.dt = %g s is too large for the contact time t_c = %g s of these particles: it must not "
                     "exceed t_c/20 = %g s (set dem.dt = 0 to use t_c/steps_per_contact)",
                     d->dt_user, d->tc, d->tc / 20.0);
            return DEM_ERR_TIMESTEP;
        }
    } else {
        if (!isfinite(d->tc)) die("dem: no mobile particle: cannot derive the time step from the contact time");
        d->dt = d->tc / d->n_c;
    }
    /* the tangential lubrication is explicit: its damping rate times the step must stay small
     * (0.5: the velocity it removes in one step is at most half of what it acts on) */
    for (int i = 0; i < d->n; i++) {
        if (d->fixed[i] || d->invm[i] == 0) continue;
        const double rate = dem_lubrication_tangential_rate(d, d->r[i], 1.0 / d->invm[i]);
        if (rate * d->dt > 0.5) {
            snprintf(d->errmsg, sizeof d->errmsg,
                     "the tangential lubrication of particle %ld damps at %.4g /s: the DEM step %g s must be below "
                     "%g s (more dem.steps_per_contact, or a larger lubrication.roughness)",
                     d->id[i], rate, d->dt, 0.5 / rate);
            return DEM_ERR_TIMESTEP;
        }
    }
    return DEM_OK;
}

/* Checks that need the particles: periodic lengths, skin. */
void dem_check_scene(dem_t *d)
{
    double rmax = 0, dmean = 0;
    for (int i = 0; i < d->n; i++) {
        if (d->r[i] > rmax) rmax = d->r[i];
        dmean += 2 * d->r[i];
    }
    d->rmax = rmax;
    /* lubrication: the lists also hold every pair within Δ_lub (lubrication.c) */
    d->lub.reach = dem_lub_reach(&d->lub, rmax);
    if (d->skin_rel > 0)
        d->skin = d->skin_rel * 2 * rmax + d->lub.reach;
    else
        d->skin += d->lub.reach - d->skin_lub_added;
    d->skin_lub_added = d->lub.reach;
    for (int a = 0; a < 3; a++)
        if (d->periodic[a] && d->L[a] < 4 * rmax)
            die("dem: the periodic length in %c (%g m) must be at least twice the largest diameter (%g m)", "xyz"[a],
                d->L[a], 2 * rmax);
    for (int k = 0; k < 27; k++) {
        const int s[3] = {k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1};
        for (int a = 0; a < 3; a++) d->shift[k][a] = s[a] * d->L[a];
    }
}

/* Replicated: every rank computes everything (no communication); split: the
 * pairs are shared among the ranks and the forces summed.  Decided once. */
void dem_decide_split(dem_t *d)
{
    if (d->split_decided) return;
    d->split = d->nranks > 1 && (d->parallel_mode == 2 || (d->parallel_mode == 0 && d->n >= 4000));
    d->split_decided = 1;
}

/* ---- forces ---- */

void dem_compute_forces(dem_t *d)
{
    double t0 = wtime();
    if (d->nthreads < 1) d->nthreads = 1;
    for (int q = 0; q < d->nthreads; q++) {
        if (!d->tblock[q]) d->tblock[q] = xcalloc(1, DEM_KERNEL_BLOCK_BYTES);
        if (q > 0 && d->tforce_cap < d->cap) {
            free(d->tforce[q]);
            d->tforce[q] = xcalloc(6 * (size_t)d->cap, sizeof(double));
        }
    }
    if (d->tforce_cap < d->cap) d->tforce_cap = d->cap;
    memset(d->f, 0, 3 * (size_t)d->n * sizeof(double));
    memset(d->t, 0, 3 * (size_t)d->n * sizeof(double));
    d->n_contacts = d->n_wall_contacts = 0;
    d->max_overlap = 0.0;
    d->law->pair_forces(d);
    if (d->fstat.on) d->fstat.contacts += (double)d->n_contacts;
    double t1 = wtime();
    d->t_pair += t1 - t0;
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        if (W->active)
            d->law->wall_forces(d, W);
        else
            W->force[0] = W->force[1] = W->force[2] = 0.0;
    }
    double t2 = wtime();
    d->t_wall += t2 - t1;
    if (d->fstat.on) {
        d->fstat.steps++;
        d->fstat.contacts += (double)d->n_wall_contacts;
    }
    if (d->split) {
        MPI_Allreduce(MPI_IN_PLACE, d->f, 3 * d->n, MPI_DOUBLE, MPI_SUM, d->comm);
        MPI_Allreduce(MPI_IN_PLACE, d->t, 3 * d->n, MPI_DOUBLE, MPI_SUM, d->comm);
        double extra[3 * DEM_MAX_WALLS + 3];
        for (int w = 0; w < d->nwall; w++)
            for (int a = 0; a < 3; a++) extra[3 * w + a] = d->wall[w].force[a];
        extra[3 * d->nwall] = (double)d->n_contacts;
        extra[3 * d->nwall + 1] = (double)d->n_wall_contacts;
        extra[3 * d->nwall + 2] = d->max_overlap > d->max_overlap_allowed ? 1.0 : 0.0;
        MPI_Allreduce(MPI_IN_PLACE, extra, 3 * d->nwall + 3, MPI_DOUBLE, MPI_SUM, d->comm);
        for (int w = 0; w < d->nwall; w++)
            for (int a = 0; a < 3; a++) d->wall[w].force[a] = extra[3 * w + a];
        d->n_contacts = (long)extra[3 * d->nwall];
        d->n_wall_contacts = (long)extra[3 * d->nwall + 1];
        /* every rank must see the overlap error: share the maximum */
        if (extra[3 * d->nwall + 2] > 0)
            MPI_Allreduce(MPI_IN_PLACE, &d->max_overlap, 1, MPI_DOUBLE, MPI_MAX, d->comm);
        d->t_comm += wtime() - t2;
    }
}

/* ---- integration ---- */

/* F − α|F| sgn(v) (local non-viscous damping, sgn(0) = 0) */
static inline double local_damping(double F, double v, double alpha)
{
    return v > 0 ? F - alpha * fabs(F) : v < 0 ? F + alpha * fabs(F) : F;
}

/* Opening kick and drift (with the pending closing kick of the previous
 * step fused in); returns max |v|² over the mobile particles. */
static double kick_drift(dem_t *d)
{
    const int impulses = d->lub.on || d->drag.on;
    const double dt = impulses ? 0.0 : d->dt, h = 0.5 * d->dt; /* lubrication, drag: drift after their impulses */
    const double gx = d->gravity[0], gy = d->gravity[1], gz = d->gravity[2];
    const double kick = d->pending_kick ? 2.0 : 1.0; /* closing kick of the last step + opening kick */
    double *restrict x = d->x, *restrict v = d->v, *restrict w = d->w, *restrict dv = d->dv, *restrict dw = d->dw;
    const double *restrict f = d->f, *restrict t = d->t, *restrict invm = d->invm, *restrict invI = d->invI;
    const unsigned char *restrict fixed = d->fixed;
    const int n = d->n;
    double vmax2 = 0.0;
    if (d->use_ext || d->damping > 0) {
        /* local non-viscous damping (Cundall & Strack 1979; Yade's
         * NewtonIntegrator): each component of the resultant force (gravity
         * and external forces included) and torque becomes F − α|F| sgn(v),
         * v the half-step velocity.  It removes a fraction of the kinetic
         * energy of every oscillation (amplitude ratio √((1−α)/(1+α)) per
         * half-cycle of a linear oscillator) and vanishes at equilibrium, so
         * it changes neither the static state nor a quasi-static path. */
        const double alpha = d->damping;
        const double *restrict fe = d->use_ext ? d->fext : NULL, *restrict te = d->use_ext ? d->text : NULL;
#pragma omp parallel for num_threads(d->nthreads) if (d->nthreads > 1) reduction(max : vmax2) schedule(static)
        for (int i = 0; i < n; i++) {
            if (fixed[i]) continue;
            const double im = invm[i], ii = invI[i];
            const double g[3] = {gx, gy, gz};
            double v2 = 0;
            for (int c = 0; c < 3; c++) {
                const double F = f[3 * i + c] + (fe ? fe[3 * i + c] : 0.0);
                const double T = t[3 * i + c] + (te ? te[3 * i + c] : 0.0);
                const double hv = alpha > 0 ? h * im * local_damping(F + g[c] / im, v[3 * i + c], alpha)
                                            : h * (F * im + g[c]);
                const double hw = alpha > 0 ? h * ii * local_damping(T, w[3 * i + c], alpha) : h * T * ii;
                v[3 * i + c] += kick * hv;
                dv[3 * i + c] = hv;
                x[3 * i + c] += dt * v[3 * i + c];
                w[3 * i + c] += kick * hw;
                dw[3 * i + c] = hw;
                v2 += v[3 * i + c] * v[3 * i + c];
            }
            if (v2 > vmax2) vmax2 = v2;
        }
    } else {
#pragma omp parallel for num_threads(d->nthreads) if (d->nthreads > 1) reduction(max : vmax2) schedule(static)
        for (int i = 0; i < n; i++) {
            if (fixed[i]) continue;
            const double im = h * invm[i], ii = h * invI[i];
            const double hvx = f[3 * i] * im + h * gx, hvy = f[3 * i + 1] * im + h * gy,
                         hvz = f[3 * i + 2] * im + h * gz;
            const double vx = v[3 * i] + kick * hvx, vy = v[3 * i + 1] + kick * hvy, vz = v[3 * i + 2] + kick * hvz;
            v[3 * i] = vx;
            v[3 * i + 1] = vy;
            v[3 * i + 2] = vz;
            dv[3 * i] = hvx;
            dv[3 * i + 1] = hvy;
            dv[3 * i + 2] = hvz;
            x[3 * i] += dt * vx;
            x[3 * i + 1] += dt * vy;
            x[3 * i + 2] += dt * vz;
            const double hwx = t[3 * i] * ii, hwy = t[3 * i + 1] * ii, hwz = t[3 * i + 2] * ii;
            w[3 * i] += kick * hwx;
            w[3 * i + 1] += kick * hwy;
            w[3 * i + 2] += kick * hwz;
            dw[3 * i] = hwx;
            dw[3 * i + 1] = hwy;
            dw[3 * i + 2] = hwz;
            const double v2 = vx * vx + vy * vy + vz * vz;
            if (v2 > vmax2) vmax2 = v2;
        }
    }
    d->pending_kick = 1;
    if (impulses) {
        /* the drag (implicit in the velocity) and the lubrication impulses of
         * this drift (implicit in the gap it produces), then the drift */
        if (d->drag.on) dem_drag_impulses(d, d->dt);
        if (d->lub.on) {
            const double wl = wtime();
            dem_lubrication_impulses(d, d->dt);
            d->t_lub += wtime() - wl;
        }
        vmax2 = 0.0;
        for (int i = 0; i < n; i++) {
            if (fixed[i]) continue;
            double v2 = 0;
            for (int c = 0; c < 3; c++) {
                x[3 * i + c] += d->dt * v[3 * i + c];
                v2 += v[3 * i + c] * v[3 * i + c];
            }
            if (v2 > vmax2) vmax2 = v2;
        }
    }
    return vmax2;
}

void dem_sync_velocities(dem_t *d)
{
    if (!d->pending_kick) return;
    const double h = 0.5 * d->dt;
#pragma omp parallel for num_threads(d->nthreads) if (d->nthreads > 1) schedule(static)
    for (int i = 0; i < d->n; i++) {
        if (d->fixed[i]) continue;
        const double im = h * d->invm[i], ii = h * d->invI[i];
        for (int c = 0; c < 3; c++) {
            double fa = d->f[3 * i + c], ta = d->t[3 * i + c];
            if (d->use_ext) {
                fa += d->fext[3 * i + c];
                ta += d->text[3 * i + c];
            }
            if (d->damping > 0) {
                /* the same damped resultant as kick_drift, bit for bit (m g as g / invm there) */
                d->v[3 * i + c] += im * local_damping(fa + d->gravity[c] / d->invm[i], d->v[3 * i + c], d->damping);
                d->w[3 * i + c] += ii * local_damping(ta, d->w[3 * i + c], d->damping);
                continue;
            }
            d->v[3 * i + c] += fa * im + h * d->gravity[c];
            d->w[3 * i + c] += ta * ii;
        }
    }
    d->pending_kick = 0;
}

static dem_status_t overlap_check(dem_t *d)
{
    if (d->max_overlap > d->max_overlap_allowed) {
        snprintf(d->errmsg, sizeof d->errmsg,
                 "maximum overlap %.4g %% of the smaller diameter exceeds dem.max_overlap = %.4g %% at t = %g s "
                 "(step %ld): the contacts are too soft for the load or the time step too large",
                 100 * d->max_overlap, 100 * d->max_overlap_allowed, d->time, d->step);
        return DEM_ERR_OVERLAP;
    }
    return DEM_OK;
}

/* Lists and forces of the current state (first step, or after particles were
 * added or the state was replaced). */
static dem_status_t dem_setup(dem_t *d)
{
    dem_sync_velocities(d);
    dem_check_scene(d);
    if (d->dt <= 0) {
        const dem_status_t st = dem_set_dt(d);
        if (st != DEM_OK) return st;
    }
    dem_decide_split(d);
    dem_status_t st = dem_neigh_build(d);
    if (st != DEM_OK) return st;
    memset(d->dv, 0, 3 * (size_t)d->n * sizeof(double));
    memset(d->dw, 0, 3 * (size_t)d->n * sizeof(double));
    d->hist_update = 0;
    dem_compute_forces(d);
    d->hist_update = 1;
    d->ready = 1;
    return overlap_check(d);
}

static dem_status_t step_once(dem_t *d)
{
    dem_status_t st;
    if (!d->ready && (st = dem_setup(d)) != DEM_OK) return st;
    const double dt = d->dt;
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        if (W->active && d->time >= W->remove_time - 0.5 * dt) {
            W->active = 0;
            W->nlist = 0;
            msg("dem: wall %s removed at t = %g s\n", W->name, d->time);
        }
    }
    double t0 = wtime();
    const double vmax2 = kick_drift(d);
    d->time += dt;
    d->step++;
    d->disp_bound += dt * sqrt(vmax2);
    double wmoved = 0.0;
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        if (!W->active) continue;
        if (W->mass > 0) {
            /* a load-controlled wall: leap-frog like the particles, with the
             * particles' force on it from the last force computation and the
             * same local damping */
            double vn = 0, fn = W->push;
            for (int a = 0; a < 3; a++) vn += W->vel[a] * W->n[a], fn += W->force[a] * W->n[a];
            if (d->damping > 0) fn = local_damping(fn, vn, d->damping);
            vn += dt * fn / W->mass;
            for (int a = 0; a < 3; a++) W->vel[a] = vn * W->n[a];
        }
        const double s = sqrt(W->vel[0] * W->vel[0] + W->vel[1] * W->vel[1] + W->vel[2] * W->vel[2]);
        if (s > 0) {
            for (int a = 0; a < 3; a++) W->p[a] += dt * W->vel[a];
            W->moved += dt * s;
            if (W->moved > wmoved) wmoved = W->moved;
        }
    }
    d->t_integ += wtime() - t0;
    if (d->disp_bound + wmoved > 0.5 * (d->skin - d->lub.reach)) {
        if ((st = dem_neigh_build(d)) != DEM_OK) return st;
    }
    dem_compute_forces(d);
    if (d->observer) d->observer(d, d->observer_ctx);
    return overlap_check(d);
}

void dem_full_velocity(const dem_t *d, int i, double vel[3])
{
    const double h = d->pending_kick ? 0.5 * d->dt : 0.0;
    for (int c = 0; c < 3; c++) {
        double fa = d->f[3 * i + c];
        if (d->use_ext) fa += d->fext[3 * i + c];
        if (d->damping > 0 && !d->fixed[i]) /* the damped resultant of the closing kick */
            vel[c] = d->v[3 * i + c] +
                     h * d->invm[i] * local_damping(fa + d->gravity[c] / d->invm[i], d->v[3 * i + c], d->damping);
        else
            vel[c] = d->v[3 * i + c] + (d->fixed[i] ? 0.0 : h * (fa * d->invm[i] + d->gravity[c]));
    }
}

void dem_set_step_observer(dem_t *d, void (*fn)(dem_t *d, void *ctx), void *ctx)
{
    d->observer = fn;
    d->observer_ctx = ctx;
}

dem_status_t dem_step(dem_t *d)
{
    dem_status_t st = step_once(d);
    double t0 = wtime();
    dem_sync_velocities(d);
    d->t_integ += wtime() - t0;
    return st;
}

dem_status_t dem_advance(dem_t *d, double t_target)
{
    dem_status_t st = DEM_OK;
    if (!d->ready && (st = dem_setup(d)) != DEM_OK) return st;
    const double span = t_target - d->time;
    if (span <= 0) return DEM_OK;
    /* a whole number of steps (to round-off, e.g. a driver step of `substeps`
     * DEM steps) is done with the step itself, so that the run does not
     * depend on the round-off of the caller's time; else equal shorter steps */
    const double ratio = span / d->dt;
    long nsteps = lround(ratio);
    const double dt_save = d->dt;
    if (nsteps < 1 || fabs(ratio - (double)nsteps) > 1e-6) {
        nsteps = (long)ceil(ratio * (1 - 1e-12));
        if (nsteps < 1) nsteps = 1;
        d->dt = span / (double)nsteps;
    }
    for (long s = 0; s < nsteps && st == DEM_OK; s++) st = step_once(d);
    double t0 = wtime();
    dem_sync_velocities(d);
    d->t_integ += wtime() - t0;
    d->dt = dt_save;
    if (st == DEM_OK) d->time = t_target;
    return st;
}

dem_status_t dem_run_steps(dem_t *d, long nsteps)
{
    dem_status_t st = DEM_OK;
    if (!d->ready && (st = dem_setup(d)) != DEM_OK) return st;
    for (long s = 0; s < nsteps && st == DEM_OK; s++) st = step_once(d);
    double t0 = wtime();
    dem_sync_velocities(d);
    d->t_integ += wtime() - t0;
    return st;
}

/* ---- accessors ---- */

const char *dem_error(const dem_t *d) { return d->errmsg; }
double dem_dt(const dem_t *d) { return d->dt; }
double dem_time(const dem_t *d) { return d->time; }
double dem_contact_time(const dem_t *d) { return d->tc; }
void dem_set_time(dem_t *d, double t) { d->time = t; }
void dem_get_gravity(const dem_t *d, double g[3]) { memcpy(g, d->gravity, 3 * sizeof(double)); }
double dem_dry_restitution(const dem_t *d) { return d->cp.restitution; }
void dem_set_gravity(dem_t *d, const double g[3])
{
    dem_sync_velocities(d);
    for (int a = 0; a < 3; a++) d->gravity[a] = g[a];
}
int dem_count(const dem_t *d) { return d->n; }
long dem_id_bound(const dem_t *d) { return d->next_id; }
const double *dem_positions(const dem_t *d) { return d->x; }
const double *dem_velocities(const dem_t *d) { return d->v; }
const double *dem_omegas(const dem_t *d) { return d->w; }
const double *dem_radii(const dem_t *d) { return d->r; }
const long *dem_ids(const dem_t *d) { return d->id; }
const unsigned char *dem_fixed(const dem_t *d) { return d->fixed; }
double dem_mass(const dem_t *d, int i) { return d->invm[i] > 0 ? 1.0 / d->invm[i] : INFINITY; }
double dem_density(const dem_t *d, int i) { return d->rho[i]; }
void dem_set_added_mass(dem_t *d, int i, double added_mass)
{
    const double invm = 1.0 / (d->rho[i] * dem_sphere_volume(d->r[i]) + added_mass);
    if (d->fixed[i] || invm == d->invm[i]) return;
    dem_sync_velocities(d); /* the pending half kick belongs to the old mass */
    d->invm[i] = invm; /* forces already computed keep the old mass until the next step (a restart continues exactly) */
}
double *dem_ext_force(dem_t *d)
{
    d->use_ext = 1;
    return d->fext;
}
double *dem_ext_torque(dem_t *d)
{
    d->use_ext = 1;
    return d->text;
}
const double *dem_contact_forces(const dem_t *d) { return d->f; }
int dem_wall_count(const dem_t *d) { return d->nwall; }
void dem_wall_force(const dem_t *d, int w, double f[3])
{
    for (int a = 0; a < 3; a++) f[a] = d->wall[w].force[a];
}
int dem_wall_active(const dem_t *d, int w) { return d->wall[w].active; }
double dem_wall_gap_min(const dem_t *d, int i)
{
    double g = INFINITY, u;
    for (int w = 0; w < d->nwall; w++)
        if (d->wall[w].active) g = fmin(g, dem_wall_gap(d, &d->wall[w], i, &u));
    return g;
}

void dem_wall_position(const dem_t *d, int w, double p[3])
{
    for (int a = 0; a < 3; a++) p[a] = d->wall[w].p[a];
}
void dem_set_damping(dem_t *d, double alpha) { d->damping = alpha; }
void dem_wall_set_point(dem_t *d, int w, const double p[3])
{
    for (int a = 0; a < 3; a++) d->wall[w].p[a] = p[a];
    d->ready = 0; /* the wall's contact list */
}
void dem_wall_set_load(dem_t *d, int w, double push, double mass)
{
    d->wall[w].push = push;
    d->wall[w].mass = mass;
}
int dem_wall_find(const dem_t *d, const char *name)
{
    for (int w = 0; w < d->nwall; w++)
        if (!strcmp(d->wall[w].name, name)) return w;
    return -1;
}
const char *dem_wall_name(const dem_t *d, int w) { return d->wall[w].name; }
