/* dem_neigh.c — neighbour search in O(N): linked cells and a half Verlet
 * list with a skin.
 *
 * Cells have a side ≥ 2 R_max + skin, so every pair that can touch before
 * the next rebuild lies in the same or an adjacent cell.  The list keeps each
 * pair (i, j) once, in the row of i: j > i in the cell of i, and every j of
 * the 13 cells of a half stencil (the other 13 are covered by the rows of
 * their particles).  Periodic directions wrap the cell index; the pair then
 * carries the image shift of j (27 possible), so a box only a few cells
 * across is handled exactly — each image of a pair is a separate entry.
 * The list is rebuilt when a bound of the largest displacement since the
 * build (Σ dt max|v|) plus the largest wall displacement exceeds skin/2.
 *
 * At a rebuild the particles are reordered by cell (counting sort, stable),
 * which keeps neighbours close in memory, and the tangential spring of every
 * active contact is carried over to the new list (matched by partner).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "util.h"

static void *xrealloc(void *p, size_t bytes)
{
    void *q = realloc(p, bytes ? bytes : 1);
    if (!q) die_local("out of memory (%zu bytes)", bytes);
    return q;
}

static void nb_reserve(dem_t *d, long need)
{
    if (need <= d->nb_cap) return;
    long cap = d->nb_cap ? d->nb_cap : 1024;
    while (cap < need) cap *= 2;
    d->nb_j = xrealloc(d->nb_j, (size_t)cap * sizeof(int));
    d->nb_img = xrealloc(d->nb_img, (size_t)cap);
    d->nb_on = xrealloc(d->nb_on, (size_t)cap);
    d->nb_hist = xrealloc(d->nb_hist, (size_t)cap * 3 * sizeof(double));
    d->nb_cap = cap;
}

static void wall_reserve(dem_wall_t *W, int need)
{
    if (need <= W->cap) return;
    int cap = W->cap ? W->cap : 256;
    while (cap < need) cap *= 2;
    W->idx = xrealloc(W->idx, (size_t)cap * sizeof(int));
    W->on = xrealloc(W->on, (size_t)cap);
    W->hist = xrealloc(W->hist, (size_t)cap * 3 * sizeof(double));
    W->cap = cap;
}

/* Rows [lo, hi) of rank q so that the pair counts are balanced. */
static void partition_of(const dem_t *d, int q, int *lo, int *hi)
{
    if (!d->split) {
        *lo = 0;
        *hi = d->n;
        return;
    }
    const long total = d->nb_start ? d->nb_start[d->n] : 0;
    int bounds[2];
    for (int b = 0; b < 2; b++) {
        const long target = total * (long)(q + b) / d->nranks;
        if (q + b == d->nranks) {
            bounds[b] = d->n;
            continue;
        }
        if (q + b == 0) {
            bounds[b] = 0;
            continue;
        }
        /* first row whose start reaches the target */
        int a = 0, z = d->n;
        while (a < z) {
            const int m = (a + z) / 2;
            if (d->nb_start[m] < target)
                a = m + 1;
            else
                z = m;
        }
        bounds[b] = a;
    }
    *lo = bounds[0];
    *hi = bounds[1];
}

void dem_neigh_partition(dem_t *d)
{
    partition_of(d, d->rank, &d->row_lo, &d->row_hi);
    /* the threads' shares of the rank's rows, balanced by pair count */
    const int nt = d->nthreads > 0 ? d->nthreads : 1;
    const long p0 = d->nb_start ? d->nb_start[d->row_lo] : 0, p1 = d->nb_start ? d->nb_start[d->row_hi] : 0;
    d->trow[0] = d->row_lo;
    d->trow[nt] = d->row_hi;
    for (int q = 1; q < nt; q++) {
        const long target = p0 + (p1 - p0) * q / nt;
        int a = d->trow[q - 1], z = d->row_hi;
        while (a < z) {
            const int mid = (a + z) / 2;
            if (d->nb_start[mid] < target)
                a = mid + 1;
            else
                z = mid;
        }
        d->trow[q] = a;
    }
}

/* Every rank updated the histories of its own rows only: share them. */
void dem_neigh_gather(dem_t *d)
{
    const int P = d->nranks;
    int *cnt = calloc(2 * (size_t)P + 2, sizeof(int)), *dsp = cnt + P;
    for (int q = 0; q < P; q++) {
        int lo, hi;
        partition_of(d, q, &lo, &hi);
        dsp[q] = d->nb_start[lo];
        cnt[q] = d->nb_start[hi] - d->nb_start[lo];
    }
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, d->nb_on, cnt, dsp, MPI_UNSIGNED_CHAR, d->comm);
    for (int q = 0; q < P; q++) {
        cnt[q] *= 3;
        dsp[q] *= 3;
    }
    MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, d->nb_hist, cnt, dsp, MPI_DOUBLE, d->comm);
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        for (int q = 0; q < P; q++) {
            int lo, hi;
            partition_of(d, q, &lo, &hi);
            int a = 0, b;
            while (a < W->nlist && W->idx[a] < lo) a++;
            b = a;
            while (b < W->nlist && W->idx[b] < hi) b++;
            dsp[q] = a;
            cnt[q] = b - a;
        }
        MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, W->on, cnt, dsp, MPI_UNSIGNED_CHAR, d->comm);
        for (int q = 0; q < P; q++) {
            cnt[q] *= 3;
            dsp[q] *= 3;
        }
        MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, W->hist, cnt, dsp, MPI_DOUBLE, d->comm);
    }
    free(cnt);
}

static void permute_d(double *a, const int *order, int n, int comp, double *tmp)
{
    for (int k = 0; k < n; k++)
        for (int c = 0; c < comp; c++) tmp[(size_t)comp * k + c] = a[(size_t)comp * order[k] + c];
    memcpy(a, tmp, (size_t)n * comp * sizeof(double));
}

static void permute_particles(dem_t *d, const int *order)
{
    const int n = d->n;
    double *tmp = malloc((size_t)(3 * n + 1) * sizeof(double));
    double *v3[] = {d->x, d->v, d->w, d->f, d->t, d->dv, d->dw, d->fext, d->text, d->flub};
    for (size_t a = 0; a < sizeof v3 / sizeof v3[0]; a++) permute_d(v3[a], order, n, 3, tmp);
    double *v1[] = {d->r, d->invm, d->invI, d->rho};
    for (size_t a = 0; a < sizeof v1 / sizeof v1[0]; a++) permute_d(v1[a], order, n, 1, tmp);
    long *lt = (long *)tmp;
    for (int k = 0; k < n; k++) lt[k] = d->id[order[k]];
    memcpy(d->id, lt, (size_t)n * sizeof(long));
    unsigned char *ct = (unsigned char *)tmp;
    for (int k = 0; k < n; k++) ct[k] = d->fixed[order[k]];
    memcpy(d->fixed, ct, (size_t)n);
    free(tmp);
}

static void half_stencil(int off[13][3])
{
    int m = 0;
    for (int oz = -1; oz <= 1; oz++)
        for (int oy = -1; oy <= 1; oy++)
            for (int ox = -1; ox <= 1; ox++) {
                /* keep the offsets that are lexicographically positive in (z, y, x) */
                if (oz > 0 || (oz == 0 && (oy > 0 || (oy == 0 && ox > 0)))) {
                    off[m][0] = ox;
                    off[m][1] = oy;
                    off[m][2] = oz;
                    m++;
                }
            }
}

dem_status_t dem_neigh_build(dem_t *d)
{
    const double t0 = wtime();
    const int n = d->n;
    if (d->split && d->nb_start) dem_neigh_gather(d);

    /* 1. wrap periodic coordinates, check the domain */
    for (int i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) {
            double *xa = &d->x[3 * i + a];
            if (!isfinite(*xa) || !isfinite(d->v[3 * i + a])) {
                snprintf(d->errmsg, sizeof d->errmsg, "particle %ld: non-finite position or velocity at t = %g s",
                         d->id[i], d->time);
                return DEM_ERR_NAN;
            }
            if (d->periodic[a]) {
                if (*xa < d->lo[a] || *xa >= d->hi[a]) {
                    *xa -= d->L[a] * floor((*xa - d->lo[a]) / d->L[a]);
                    if (*xa >= d->hi[a]) *xa = d->lo[a]; /* round-off at the face */
                }
            } else if (*xa < d->lo[a] || *xa > d->hi[a]) {
                static const char *ax = "xyz";
                snprintf(d->errmsg, sizeof d->errmsg,
                         "particle %ld left the domain through the %c %s face at t = %g s (%c = %g m, domain [%g, %g])",
                         d->id[i], ax[a], *xa < d->lo[a] ? "low" : "high", d->time, ax[a], *xa, d->lo[a], d->hi[a]);
                return DEM_ERR_LEFT_DOMAIN;
            }
        }
    }

    /* 2. cell grid: side ≥ 2 R_max + skin, at most ~4 cells per particle */
    double rmax = 0.0;
    for (int i = 0; i < n; i++)
        if (d->r[i] > rmax) rmax = d->r[i];
    d->rmax = rmax;
    const double cut = 2.0 * rmax + d->skin;
    for (int a = 0; a < 3; a++) {
        int m = cut > 0 ? (int)floor(d->L[a] / cut) : 1;
        if (m < 1) m = 1;
        if (m > 1 << 20) m = 1 << 20;
        d->nc[a] = m;
    }
    while ((double)d->nc[0] * d->nc[1] * d->nc[2] > 4.0 * n + 64) {
        int a = 0;
        for (int b = 1; b < 3; b++)
            if (d->nc[b] > d->nc[a]) a = b;
        if (d->nc[a] == 1) break;
        d->nc[a] = (d->nc[a] + 1) / 2;
    }
    for (int a = 0; a < 3; a++) d->csize[a] = d->L[a] / d->nc[a];
    const long ncell = (long)d->nc[0] * d->nc[1] * d->nc[2];
    if (ncell != d->ncell) {
        free(d->cell_start);
        d->cell_start = xcalloc((size_t)ncell + 1, sizeof(int));
        d->ncell = ncell;
    }
    free(d->cell_of);
    free(d->perm);
    d->cell_of = xcalloc((size_t)n + 1, sizeof(int));
    d->perm = xcalloc((size_t)n + 1, sizeof(int));
    int *cell_of = d->cell_of, *order = d->perm, *cstart = d->cell_start;
    memset(cstart, 0, ((size_t)ncell + 1) * sizeof(int));
    for (int i = 0; i < n; i++) {
        int c[3];
        for (int a = 0; a < 3; a++) {
            int m = (int)((d->x[3 * i + a] - d->lo[a]) / d->csize[a]);
            if (m < 0) m = 0;
            if (m >= d->nc[a]) m = d->nc[a] - 1;
            c[a] = m;
        }
        cell_of[i] = (c[2] * d->nc[1] + c[1]) * d->nc[0] + c[0];
        cstart[cell_of[i] + 1]++;
    }
    for (long c = 0; c < ncell; c++) cstart[c + 1] += cstart[c];
    {
        int *fill = xcalloc((size_t)ncell + 1, sizeof(int));
        memcpy(fill, cstart, (size_t)ncell * sizeof(int));
        for (int i = 0; i < n; i++) order[fill[cell_of[i]]++] = i;
        free(fill);
    }

    /* 3. contact histories of the old list, indexed by the old particle index */
    int *ht_start = xcalloc((size_t)n + 1, sizeof(int));
    int *ht_j = NULL;
    double *ht_xi = NULL;
    const int old_n = d->nb_start ? d->nb_n_rows : 0;
    if (old_n > 0) {
        for (int i = 0; i < old_n; i++)
            for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++)
                if (d->nb_on[k]) {
                    ht_start[i + 1]++;
                    ht_start[d->nb_j[k] + 1]++;
                }
        for (int i = 0; i < n; i++) ht_start[i + 1] += ht_start[i];
        ht_j = xcalloc((size_t)ht_start[n] + 1, sizeof(int));
        ht_xi = xcalloc(3 * (size_t)ht_start[n] + 1, sizeof(double));
        int *fill = xcalloc((size_t)n + 1, sizeof(int));
        memcpy(fill, ht_start, (size_t)n * sizeof(int));
        for (int i = 0; i < old_n; i++)
            for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++)
                if (d->nb_on[k]) {
                    const int j = d->nb_j[k];
                    int e = fill[i]++;
                    ht_j[e] = j;
                    for (int c = 0; c < 3; c++) ht_xi[3 * e + c] = d->nb_hist[3 * k + c];
                    e = fill[j]++;
                    ht_j[e] = i;
                    for (int c = 0; c < 3; c++) ht_xi[3 * e + c] = -d->nb_hist[3 * k + c];
                }
        free(fill);
    }

    /* 4. reorder the particles by cell (if due); old_of[new] and new_of[old] */
    int *old_of = xcalloc((size_t)n + 1, sizeof(int)), *new_of = xcalloc((size_t)n + 1, sizeof(int));
    const int sort = d->sort_every > 0 && ++d->builds_since_sort >= d->sort_every;
    if (sort) {
        d->builds_since_sort = 0;
        permute_particles(d, order);
        for (int k = 0; k < n; k++) {
            old_of[k] = order[k];
            new_of[order[k]] = k;
        }
        int *tmp = xcalloc((size_t)n + 1, sizeof(int));
        for (int k = 0; k < n; k++) tmp[k] = cell_of[order[k]];
        memcpy(cell_of, tmp, (size_t)n * sizeof(int));
        free(tmp);
        for (int k = 0; k < n; k++) order[k] = k;
    } else {
        for (int k = 0; k < n; k++) old_of[k] = new_of[k] = k;
    }

    /* 5. the half list */
    int off[13][3];
    half_stencil(off);
    free(d->nb_start);
    d->nb_start = xcalloc((size_t)n + 1, sizeof(int));
    long m = 0;
    nb_reserve(d, 8L * n + 16);
    const double skin = d->skin;
    for (int i = 0; i < n; i++) {
        d->nb_start[i] = (int)m;
        const int ci = cell_of[i];
        const int cx = ci % d->nc[0], cy = (ci / d->nc[0]) % d->nc[1], cz = ci / (d->nc[0] * d->nc[1]);
        const double xi = d->x[3 * i], yi = d->x[3 * i + 1], zi = d->x[3 * i + 2], ri = d->r[i];
        const int fi = d->fixed[i];
        const int oi = old_of[i];
        for (int s = -1; s < 13; s++) {
            int o[3] = {0, 0, 0}, img[3] = {0, 0, 0};
            int cc[3] = {cx, cy, cz};
            if (s >= 0) {
                int skip = 0;
                for (int a = 0; a < 3; a++) {
                    o[a] = off[s][a];
                    cc[a] += o[a];
                    if (cc[a] < 0 || cc[a] >= d->nc[a]) {
                        if (!d->periodic[a]) {
                            skip = 1;
                            break;
                        }
                        img[a] = cc[a] < 0 ? -1 : 1;
                        cc[a] -= img[a] * d->nc[a];
                    }
                }
                if (skip) continue;
            }
            const int code = (img[0] + 1) + 3 * (img[1] + 1) + 9 * (img[2] + 1);
            const double *sh = d->shift[code];
            const long c = ((long)cc[2] * d->nc[1] + cc[1]) * d->nc[0] + cc[0];
            for (int q = cstart[c]; q < cstart[c + 1]; q++) {
                const int j = order[q];
                if (s < 0 && j <= i) continue;
                if (j == i) continue;
                if (fi && d->fixed[j]) continue;
                const double dx = xi - d->x[3 * j] - sh[0], dy = yi - d->x[3 * j + 1] - sh[1],
                             dz = zi - d->x[3 * j + 2] - sh[2];
                const double rc = ri + d->r[j] + skin;
                if (dx * dx + dy * dy + dz * dz >= rc * rc) continue;
                if (m == d->nb_cap) nb_reserve(d, m + 1);
                d->nb_j[m] = j;
                d->nb_img[m] = (unsigned char)code;
                d->nb_on[m] = 0;
                d->nb_hist[3 * m] = d->nb_hist[3 * m + 1] = d->nb_hist[3 * m + 2] = 0.0;
                if (ht_j) {
                    const int oj = old_of[j];
                    for (int e = ht_start[oi]; e < ht_start[oi + 1]; e++)
                        if (ht_j[e] == oj) {
                            d->nb_on[m] = 1;
                            for (int cc3 = 0; cc3 < 3; cc3++) d->nb_hist[3 * m + cc3] = ht_xi[3 * e + cc3];
                            break;
                        }
                }
                m++;
            }
        }
    }
    d->nb_start[n] = (int)m;
    d->nb_n = m;
    d->nb_n_rows = n;
    free(ht_start);
    free(ht_j);
    free(ht_xi);

    /* 6. wall lists, keeping the wall histories */
    unsigned char *wflag = xcalloc((size_t)n + 1, 1);
    double *wxi = xcalloc(3 * (size_t)n + 1, sizeof(double));
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        for (int e = 0; e < W->nlist; e++)
            if (W->on[e] && W->idx[e] < n) {
                const int k = new_of[W->idx[e]];
                wflag[k] = 1;
                for (int c = 0; c < 3; c++) wxi[3 * k + c] = W->hist[3 * e + c];
            }
        int nl = 0;
        if (W->active) {
            for (int i = 0; i < n; i++) {
                if (d->fixed[i]) continue;
                const double dist = (d->x[3 * i] - W->p[0]) * W->n[0] + (d->x[3 * i + 1] - W->p[1]) * W->n[1] +
                                    (d->x[3 * i + 2] - W->p[2]) * W->n[2];
                if (dist >= d->r[i] + skin || dist <= -d->r[i]) continue;
                wall_reserve(W, nl + 1);
                W->idx[nl] = i;
                W->on[nl] = wflag[i];
                for (int c = 0; c < 3; c++) W->hist[3 * nl + c] = wflag[i] ? wxi[3 * i + c] : 0.0;
                wflag[i] = 0;
                nl++;
            }
        }
        for (int e = 0; e < W->nlist; e++)
            if (W->idx[e] < n) wflag[new_of[W->idx[e]]] = 0;
        W->nlist = nl;
        W->moved = 0.0;
    }
    free(wflag);
    free(wxi);
    free(old_of);
    free(new_of);

    d->disp_bound = 0.0;
    d->rebuilds++;
    dem_neigh_partition(d);
    d->t_build += wtime() - t0;
    return DEM_OK;
}

void dem_neigh_free(dem_t *d)
{
    free(d->nb_start);
    free(d->nb_j);
    free(d->nb_img);
    free(d->nb_on);
    free(d->nb_hist);
    free(d->cell_start);
    free(d->cell_of);
    free(d->perm);
    for (int w = 0; w < d->nwall; w++) {
        free(d->wall[w].idx);
        free(d->wall[w].on);
        free(d->wall[w].hist);
    }
}
