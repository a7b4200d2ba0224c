/* dem_state.c — a copy of the whole state of the DEM and its exact return
 * (dem.h: dem_state_save, dem_state_restore), for the rollback of a
 * diverged step (time.rollback): the particles, their forces, the contact
 * springs, the pair and wall lists, the walls, the time and the step. */
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "util.h"

/* The scalars are a copy of the whole structure (its pointers unused); the
 * arrays are copies of the particles (n), the pair list (nb_n entries) and
 * the walls' contact lists. */
struct dem_state {
    dem_t s;
    double *v3[11];
    double *v1[4];
    long *id;
    unsigned char *fixed;
    int *nb_start, *nb_j;
    unsigned char *nb_img, *nb_on;
    double *nb_hist;
    int *widx[DEM_MAX_WALLS];
    unsigned char *won[DEM_MAX_WALLS];
    double *whist[DEM_MAX_WALLS];
};

/* The per-particle arrays of d: 3-vectors and scalars. */
static void particle_arrays(dem_t *d, double **v3[11], double **v1[4])
{
    double **a3[11] = {&d->x, &d->v, &d->w, &d->f, &d->t, &d->dv, &d->dw, &d->fext, &d->text, &d->flub, &d->fc};
    double **a1[4] = {&d->r, &d->invm, &d->invI, &d->rho};
    memcpy(v3, a3, sizeof a3);
    memcpy(v1, a1, sizeof a1);
}

static void *grow(void *p, size_t bytes)
{
    p = realloc(p, bytes ? bytes : 1);
    if (!p) die_local("out of memory (%zu bytes)", bytes);
    return p;
}

static void *grow_copy(void *dst, const void *src, size_t bytes)
{
    dst = grow(dst, bytes);
    if (bytes) memcpy(dst, src, bytes);
    return dst;
}

dem_state_t *dem_state_save(const dem_t *d, dem_state_t *st)
{
    if (!st) st = xcalloc(1, sizeof *st);
    dem_t *dd = (dem_t *)d; /* read only */
    st->s = *d;
    double **v3[11], **v1[4];
    particle_arrays(dd, v3, v1);
    const size_t n = (size_t)d->n;
    for (int a = 0; a < 11; a++) st->v3[a] = *v3[a] ? grow_copy(st->v3[a], *v3[a], 3 * n * sizeof(double)) : NULL;
    for (int a = 0; a < 4; a++) st->v1[a] = grow_copy(st->v1[a], *v1[a], n * sizeof(double));
    st->id = grow_copy(st->id, d->id, n * sizeof(long));
    st->fixed = grow_copy(st->fixed, d->fixed, n);
    const size_t rows = d->nb_start ? (size_t)d->nb_n_rows + 1 : 0, m = (size_t)d->nb_n;
    st->nb_start = d->nb_start ? grow_copy(st->nb_start, d->nb_start, rows * sizeof(int)) : NULL;
    if (m) {
        st->nb_j = grow_copy(st->nb_j, d->nb_j, m * sizeof(int));
        st->nb_img = d->nb_img ? grow_copy(st->nb_img, d->nb_img, m) : NULL;
        st->nb_on = grow_copy(st->nb_on, d->nb_on, m);
        st->nb_hist = grow_copy(st->nb_hist, d->nb_hist, 3 * m * sizeof(double));
    }
    for (int w = 0; w < d->nwall; w++) {
        const dem_wall_t *W = &d->wall[w];
        const size_t k = (size_t)W->nlist;
        if (!k) continue;
        st->widx[w] = grow_copy(st->widx[w], W->idx, k * sizeof(int));
        st->won[w] = grow_copy(st->won[w], W->on, k);
        st->whist[w] = grow_copy(st->whist[w], W->hist, 3 * k * sizeof(double));
    }
    return st;
}

void dem_state_restore(dem_t *d, const dem_state_t *st)
{
    const dem_t *s = &st->s;
    const size_t n = (size_t)s->n, m = (size_t)s->nb_n;
    dem_grow(d, s->n);
    /* the arrays of d keep their buffers; their contents come back */
    double **v3[11], **v1[4];
    particle_arrays(d, v3, v1);
    for (int a = 0; a < 11; a++)
        if (st->v3[a] && *v3[a]) memcpy(*v3[a], st->v3[a], 3 * n * sizeof(double));
    for (int a = 0; a < 4; a++) memcpy(*v1[a], st->v1[a], n * sizeof(double));
    memcpy(d->id, st->id, n * sizeof(long));
    memcpy(d->fixed, st->fixed, n);
    int *nb_start = d->nb_start;
    if (st->nb_start) {
        nb_start = grow_copy(nb_start, st->nb_start, ((size_t)s->nb_n_rows + 1) * sizeof(int));
    }
    if (m > (size_t)d->nb_cap) {
        d->nb_j = grow(d->nb_j, m * sizeof(int));
        d->nb_img = grow(d->nb_img, m);
        d->nb_on = grow(d->nb_on, m);
        d->nb_hist = grow(d->nb_hist, 3 * m * sizeof(double));
        d->nb_cap = (long)m;
    }
    if (m) {
        memcpy(d->nb_j, st->nb_j, m * sizeof(int));
        if (st->nb_img) memcpy(d->nb_img, st->nb_img, m);
        memcpy(d->nb_on, st->nb_on, m);
        memcpy(d->nb_hist, st->nb_hist, 3 * m * sizeof(double));
    }
    for (int w = 0; w < s->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        const int k = s->wall[w].nlist;
        if (k > W->cap) {
            W->idx = grow(W->idx, (size_t)k * sizeof(int));
            W->on = grow(W->on, (size_t)k);
            W->hist = grow(W->hist, 3 * (size_t)k * sizeof(double));
            W->cap = k;
        }
        if (k) {
            memcpy(W->idx, st->widx[w], (size_t)k * sizeof(int));
            memcpy(W->on, st->won[w], (size_t)k);
            memcpy(W->hist, st->whist[w], 3 * (size_t)k * sizeof(double));
        }
    }
    /* the scalars: everything saved, except what belongs to the buffers of d
     * (pointers, capacities), the cell grid of the next build (scratch), the
     * snapshots written, the observer and the timers */
    dem_t keep = *d;
    *d = *s;
    double **k3[11], **k1[4];
    particle_arrays(&keep, k3, k1);
    particle_arrays(d, v3, v1);
    for (int a = 0; a < 11; a++) *v3[a] = *k3[a];
    for (int a = 0; a < 4; a++) *v1[a] = *k1[a];
#define KEEP(field) d->field = keep.field
    KEEP(id), KEEP(fixed), KEEP(cap);
    d->nb_start = st->nb_start ? nb_start : keep.nb_start;
    KEEP(nb_j), KEEP(nb_img), KEEP(nb_on), KEEP(nb_hist), KEEP(nb_cap);
    for (int w = 0; w < DEM_MAX_WALLS; w++) KEEP(wall[w].idx), KEEP(wall[w].on), KEEP(wall[w].hist), KEEP(wall[w].cap);
    memcpy(d->nc, keep.nc, sizeof d->nc);
    memcpy(d->csize, keep.csize, sizeof d->csize);
    KEEP(ncell), KEEP(cell_start), KEEP(cell_of), KEEP(perm);
    KEEP(kernel_block), KEEP(tforce_cap), KEEP(lub_work), KEEP(lub_work_cap);
    memcpy(d->tblock, keep.tblock, sizeof d->tblock);
    memcpy(d->tforce, keep.tforce, sizeof d->tforce);
    KEEP(observer), KEEP(observer_ctx);
    KEEP(nsnap), KEEP(snap_cap), KEEP(snap_t), KEEP(snap_n), KEEP(snap_index);
    KEEP(t_pair), KEEP(t_wall), KEEP(t_build), KEEP(t_integ), KEEP(t_comm), KEEP(t_lub);
#undef KEEP
}

void dem_state_free(dem_state_t *st)
{
    if (!st) return;
    for (int a = 0; a < 11; a++) free(st->v3[a]);
    for (int a = 0; a < 4; a++) free(st->v1[a]);
    free(st->id);
    free(st->fixed);
    free(st->nb_start);
    free(st->nb_j);
    free(st->nb_img);
    free(st->nb_on);
    free(st->nb_hist);
    for (int w = 0; w < DEM_MAX_WALLS; w++) {
        free(st->widx[w]);
        free(st->won[w]);
        free(st->whist[w]);
    }
    free(st);
}
