/* dem_check.c — the geometry a DEM scene starts from, checked before the
 * run (docs/user-guide.md, "What the code refuses"), with the key each
 * particle came from in the messages. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dem_private.h"
#include "overlap.h"
#include "util.h"

/* Where the particles of a scene come from while it is built: particles
 * first..next first of the key section.key (the messages of the geometry
 * check point at it). */
#define MAX_ORIGINS 16
static struct {
    int first;
    const char *section;
    char key[24];
} origin[MAX_ORIGINS];
static int norigin;

void dem_origin_reset(void) { norigin = 0; }

void dem_origin_mark(const dem_t *d, const char *section, const char *key)
{
    if (norigin == MAX_ORIGINS) return;
    origin[norigin].first = d->n;
    origin[norigin].section = section;
    snprintf(origin[norigin].key, sizeof origin[norigin].key, "%s", key);
    norigin++;
}

/* The origin of particle i (its index at creation: before any reordering). */
static int origin_of(int i)
{
    int o = 0;
    for (int k = 0; k < norigin; k++)
        if (origin[k].first <= i) o = k;
    return o;
}

/* Stop on particle i with its key. */
#define GEOM_FAIL(i, ...)                                                                                         \
    do {                                                                                                          \
        const int o_ = origin_of(i);                                                                              \
        cfg_fail(cfg, origin[o_].section, origin[o_].key, __VA_ARGS__);                                          \
    } while (0)

/* The geometry the scene starts from must be possible (docs/user-guide.md,
 * "What the code refuses"): finite values, every centre in the domain, a
 * periodic length of at least two diameters, no mobile particle overlapping
 * another particle or a wall by more than dem.max_overlap of the smaller
 * diameter (the run would stop there at its first step: the contact law is
 * calibrated for small overlaps), and no particle so fast that it moves more
 * than its radius in one DEM step (no contact could be resolved). */
void dem_check_geometry(dem_t *d, cfg_t *cfg)
{
    const double frac = d->max_overlap_allowed;
    double rmax = 0;
    int imax = 0;
    for (int i = 0; i < d->n; i++) {
        const double *x = &d->x[3 * i], *v = &d->v[3 * i], *w = &d->w[3 * i];
        for (int a = 0; a < 3; a++)
            if (!isfinite(x[a]) || !isfinite(v[a]) || !isfinite(w[a]))
                GEOM_FAIL(i, "particle %d: a position, velocity or omega that is not a finite number", i + 1);
        if (!isfinite(d->r[i]) || !isfinite(d->rho[i]))
            GEOM_FAIL(i, "particle %d: the radius and density must be finite", i + 1);
        if (d->r[i] > rmax) rmax = d->r[i], imax = i;
        for (int a = 0; a < 3; a++)
            if (!(x[a] >= d->lo[a] && x[a] <= d->hi[a]))
                GEOM_FAIL(i, "particle %d: the centre (%g %g %g) is outside the domain [%g, %g] in %c", i + 1, x[0], x[1],
                          x[2], d->lo[a], d->hi[a], "xyz"[a]);
    }
    for (int a = 0; a < 3; a++)
        if (d->periodic[a] && d->L[a] < 4 * rmax)
            GEOM_FAIL(imax, "particle %d: its diameter (%g m) is more than half the periodic length in %c (%g m)",
                      imax + 1, 2 * rmax, "xyz"[a], d->L[a]);
    /* walls: a mobile particle cutting a wall's plane (one wholly behind an
     * extra wall does not touch it) */
    for (int wi = 0; wi < d->nwall; wi++) {
        const dem_wall_t *W = &d->wall[wi];
        for (int i = 0; i < d->n; i++) {
            if (d->fixed[i]) continue;
            double dist = 0;
            for (int a = 0; a < 3; a++) dist += (d->x[3 * i + a] - W->p[a]) * W->n[a];
            const double delta = d->r[i] - dist;
            if (dist > -d->r[i] && delta > frac * 2 * d->r[i])
                GEOM_FAIL(i, "particle %d (radius %g) overlaps the wall %s by %.3g %% of its diameter, more than "
                          "dem.max_overlap = %g %%", i + 1, d->r[i], W->name, 100 * delta / (2 * d->r[i]), 100 * frac);
        }
    }
    /* pairs with at least one mobile particle */
    unsigned char *mobile = xcalloc((size_t)d->n + 1, 1);
    for (int i = 0; i < d->n; i++) mobile[i] = !d->fixed[i];
    overlap_box_t box = {.dim = 3};
    for (int a = 0; a < 3; a++) {
        box.lo[a] = d->lo[a];
        box.L[a] = d->L[a];
        box.periodic[a] = d->periodic[a];
    }
    int i = 0, j = 0;
    double delta = 0;
    const int bad = overlap_find(&box, d->n, d->x, d->r, mobile, frac, &i, &j, &delta);
    free(mobile);
    if (bad) {
        const int oi = origin_of(i);
        GEOM_FAIL(j, "particle %d (radius %g, centre %g %g %g) overlaps particle %d (%s.%s; radius %g, centre %g %g %g) by "
                  "%.3g %% of the smaller diameter, more than dem.max_overlap = %g %%", j + 1, d->r[j], d->x[3 * j],
                  d->x[3 * j + 1], d->x[3 * j + 2], i + 1, origin[oi].section, origin[oi].key, d->r[i], d->x[3 * i],
                  d->x[3 * i + 1], d->x[3 * i + 2], 100 * delta / (2 * fmin(d->r[i], d->r[j])), 100 * frac);
    }
    /* speed: at most a radius per DEM step, from the start and under gravity alone */
    const double tc = d->law->contact_time(d);
    const double dt = d->dt_user > 0 ? d->dt_user : tc / d->n_c;
    if (!isfinite(dt)) return;
    const double fall = 0.5 * hypot(hypot(d->gravity[0], d->gravity[1]), d->gravity[2]) * dt * dt;
    /* the key that set the step */
    const char *dt_section = "contact", *dt_key = "contact_time";
    if (d->dt_user > 0)
        dt_section = "dem", dt_key = "dt";
    else if (cfg_has(cfg, "contact", "kn"))
        dt_key = "kn";
    else if (cfg_has(cfg, "contact", "youngs_modulus"))
        dt_key = "youngs_modulus";
    else if (!cfg_has(cfg, "contact", "contact_time"))
        dt_section = "dem", dt_key = "steps_per_contact";
    for (int k = 0; k < d->n; k++) {
        if (d->fixed[k]) continue;
        const double *v = &d->v[3 * k], *w = &d->w[3 * k];
        const double speed = hypot(hypot(v[0], v[1]), v[2]) + d->r[k] * hypot(hypot(w[0], w[1]), w[2]);
        if (speed * dt > d->r[k])
            GEOM_FAIL(k, "particle %d: a speed of %g m/s (|v| + R|omega|) moves it more than its radius (%g m) in one "
                      "DEM step of %g s: no contact could be resolved", k + 1, speed, d->r[k], dt);
        if (fall > d->r[k])
            cfg_fail(cfg, dt_section, dt_key,
                     "a DEM step of %g s, in which gravity alone moves particle %d %g m, more than its radius (%g m): "
                     "no contact could be resolved", dt, k + 1, fall, d->r[k]);
    }
}
