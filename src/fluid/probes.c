/* probes.c — values of the fluid fields at given points (probes.h). */
#include "probes.h"

#include <stdlib.h>

#include "util.h"

/* one direction of a stencil: global cells lo, hi (wrapped) and the weight of hi */
typedef struct {
    int lo, hi;
    double w;
} axis_stencil_t;

struct probes {
    const grid_t *g;
    int n;
    axis_stencil_t (*st)[3]; /* [n][3] */
    double *buf;             /* n * 3 partial sums */
};

/* Centre of cell i (i = -1 .. n) along direction a. */
static double centre(const grid_t *g, int a, int i)
{
    return a == 0 ? g->gxc[i] : g->x0[a] + (i + 0.5) * (a == 1 ? g->dy : g->dz);
}

static axis_stencil_t axis_stencil(const grid_t *g, int a, double c)
{
    const int n = g->n[a];
    axis_stencil_t s = {0, 0, 0.0};
    if (n == 1) return s;
    int lo;
    if (c < centre(g, a, 0)) {
        if (!g->periodic[a]) return s; /* s = {0, 0, 0}: the first centre's value */
        lo = -1;
    } else if (c >= centre(g, a, n - 1)) {
        if (!g->periodic[a]) {
            s.lo = s.hi = n - 1;
            return s;
        }
        lo = n - 1;
    } else {
        int l = 0, h = n - 1; /* centre(l) <= c < centre(h) */
        while (h - l > 1) {
            const int m = (l + h) / 2;
            if (centre(g, a, m) <= c) l = m;
            else h = m;
        }
        lo = l;
    }
    const double c0 = centre(g, a, lo), c1 = centre(g, a, lo + 1);
    s.w = (c - c0) / (c1 - c0);
    s.lo = (lo + n) % n;
    s.hi = (lo + 1) % n;
    return s;
}

probes_t *probes_create(const grid_t *g, int n, const double *pts, int *bad)
{
    for (int i = 0; i < n; i++)
        for (int a = 0; a < g->dim; a++) {
            const double c = pts[3 * i + a];
            if (!(c >= g->x0[a] && c <= g->x0[a] + g->L[a])) {
                if (bad) *bad = i;
                return NULL;
            }
        }
    probes_t *pr = xcalloc(1, sizeof *pr);
    pr->g = g;
    pr->n = n;
    pr->st = xcalloc((size_t)(n > 0 ? n : 1), sizeof *pr->st);
    pr->buf = xcalloc((size_t)(n > 0 ? 3 * n : 1), sizeof *pr->buf);
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            pr->st[i][a] = a < g->dim ? axis_stencil(g, a, pts[3 * i + a]) : (axis_stencil_t){0, 0, 0.0};
    return pr;
}

int probes_count(const probes_t *pr) { return pr->n; }

/* This rank's part of the interpolation at probe p of the cell values of f
 * (back = 0), or of the means f[m] and f[m − back] (a face velocity at the
 * cell centre) */
static double partial(const probes_t *pr, int p, const double *f, long back)
{
    const grid_t *g = pr->g;
    const axis_stencil_t *s = pr->st[p];
    double sum = 0.0;
    for (int a = 0; a < 2; a++) {
        const int ig = a ? s[0].hi : s[0].lo;
        const double wa = a ? s[0].w : 1.0 - s[0].w;
        if (ig < g->ix0 || ig >= g->ix0 + g->nxl || wa == 0.0) continue;
        for (int b = 0; b < 2; b++) {
            const int j = b ? s[1].hi : s[1].lo;
            const double wb = b ? s[1].w : 1.0 - s[1].w;
            if (wb == 0.0) continue;
            for (int c = 0; c < 2; c++) {
                const int k = c ? s[2].hi : s[2].lo;
                const double wc = c ? s[2].w : 1.0 - s[2].w;
                if (wc == 0.0) continue;
                const long m = G_IDX(g, ig - g->ix0, j, k);
                const double v = back ? 0.5 * (f[m] + f[m - back]) : f[m];
                sum += wa * wb * wc * v;
            }
        }
    }
    return sum;
}

void probes_eval_cell(const probes_t *pr, const double *f, double *out)
{
    for (int p = 0; p < pr->n; p++) pr->buf[p] = partial(pr, p, f, 0);
    if (pr->n) MPI_Allreduce(pr->buf, out, pr->n, MPI_DOUBLE, MPI_SUM, pr->g->comm);
}

void probes_eval_velocity(const probes_t *pr, double *const u[3], double *out)
{
    const grid_t *g = pr->g;
    const long back[3] = {g->sx, g->sy, 1};
    for (int p = 0; p < pr->n; p++)
        for (int c = 0; c < g->dim; c++) pr->buf[p * g->dim + c] = partial(pr, p, u[c], back[c]);
    if (pr->n) MPI_Allreduce(pr->buf, out, pr->n * g->dim, MPI_DOUBLE, MPI_SUM, g->comm);
}

void probes_free(probes_t *pr)
{
    if (!pr) return;
    free(pr->st);
    free(pr->buf);
    free(pr);
}
