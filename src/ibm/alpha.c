/* alpha.c — the smoothed solid fraction of each sphere at the staggered
 * velocity nodes (decision 1 of the reference notes), evaluated only in the
 * bounding box of each sphere, with periodic images and walls.
 *
 * For a node at x, with r = x − x_p, d = |r| − R the signed distance to the
 * surface and n = r/|r| the outward normal:
 *     α = ½[1 − tanh(d/(σ λ Δ))],  λ = |n_x| + |n_y| + |n_z|,
 *     σ = 0.065(1 − λ²) + 0.39,     Δ = √2 h,
 * (Izard 2014 eq. 3.4–3.6 with the 0.039 typo corrected; h is the cell size
 * of the node: the cube root of its control-volume extents in 3-D, the
 * square root in 2-D, so Δ = √2 Δx on a uniform grid).  σλ lies in
 * [0.39, 0.463], so the transition is nearly isotropic, about three cells
 * wide.  The tails are cut continuously: α = clamp((α − ε)/(1 − 2ε), 0, 1)
 * with ε = IBM_ALPHA_CUT, which is exactly 0 beyond d = 2.26 h and exactly
 * 1 below −2.26 h, without any jump (the reason the profile is smoothed:
 * a node entering the band must not make the force jump).
 *
 * In an axisymmetric grid (x = r, y = z) the sphere is on the axis and the
 * distance is taken in the meridian plane, |r| = √(r² + (z − z_p)²).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ibm_internal.h"
#include "util.h"

/* atanh(1 − 2ε) × max_λ σ(λ)λ × √2: beyond this many h from the surface
 * α is exactly 0 or 1.  max σλ = 0.4633 at λ = 1.528. */
double ibm_band_halfwidth(void) { return atanh(1.0 - 2.0 * IBM_ALPHA_CUT) * 0.46335 * M_SQRT2; }

double ibm_alpha(double d, const double n[3], double h)
{
    double lam = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
    double sigma = 0.065 * (1.0 - lam * lam) + 0.39;
    double a = 0.5 * (1.0 - tanh(d / (sigma * lam * M_SQRT2 * h)));
    a = (a - IBM_ALPHA_CUT) / (1.0 - 2.0 * IBM_ALPHA_CUT);
    return a < 0.0 ? 0.0 : (a > 1.0 ? 1.0 : a);
}

/* ---- the grid seen from a sphere -------------------------------------------- */

/* Coordinate along d of the node (global index idx, already wrapped) of
 * component c (c = −1: cell centre). */
static inline double node_coord(const grid_t *g, int d, int c, int idx)
{
    double off = c == d ? 1.0 : 0.5;
    switch (d) {
    case 0: return c == 0 ? g->gxf[idx] : g->gxc[idx];
    case 1: return g->x0[1] + (idx + off) * g->dy;
    default: return g->x0[2] + (idx + off) * g->dz;
    }
}

/* Number of unknowns of component c along d (c = −1: cells): a face on a
 * wall or on the axis at the high side is a boundary value (grid.h). */
static inline int n_unknowns(const grid_t *g, int c, int d) { return g->n[d] - (c == d && !g->periodic[d] ? 1 : 0); }

static inline int wrap(int i, int n) { return ((i % n) + n) % n; }

/* First global index whose node coordinate is >= x (non-periodic x). */
static int lower_index(const grid_t *g, int c, double x)
{
    const double *a = c == 0 ? g->gxf : g->gxc;
    int lo = 0, hi = n_unknowns(g, c, 0); /* answer in [lo, hi] */
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (a[mid] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Index range [lo, hi] along d of the nodes of component c with coordinate
 * in [a, b]: unwrapped (may leave [0, n)) in a periodic direction, clipped
 * to the unknowns otherwise.  Returns 0 if empty. */
static int index_range(const grid_t *g, int d, int c, double a, double b, int *lo, int *hi)
{
    if (d == 0 && !g->periodic[0]) {
        *lo = lower_index(g, c, a);
        *hi = lower_index(g, c, b) - 1;
        int nu = n_unknowns(g, c, 0);
        if (*hi >= nu) *hi = nu - 1;
    } else {
        double h = g->L[d] / g->n[d], off = c == d ? 1.0 : 0.5, x0 = g->x0[d];
        *lo = (int)ceil((a - x0) / h - off);
        *hi = (int)floor((b - x0) / h - off);
        if (!g->periodic[d]) {
            if (*lo < 0) *lo = 0;
            if (*hi > n_unknowns(g, c, d) - 1) *hi = n_unknowns(g, c, d) - 1;
        }
    }
    return *lo <= *hi;
}

/* The box of sphere s for component c: index ranges in every direction,
 * with a margin of the band half-width in units of the largest cell
 * spacing met in the box.  Returns 0 if the box misses the domain. */
static int sphere_box(const ibm_t *ibm, const ibm_sphere_t *s, int c, int lo[3], int hi[3])
{
    const grid_t *g = ibm->g;
    double band = ibm_band_halfwidth();
    double hmax = g->dy;
    if (g->dim == 3) hmax = fmax(hmax, g->dz);
    /* x spacing near the sphere, then over the whole x range of the box
     * (stretched grids: the margin must cover the largest cell in it) */
    int ic = lower_index(g, -1, s->xa[0]);
    if (ic >= g->n[0]) ic = g->n[0] - 1;
    if (g->periodic[0]) ic = 0;
    hmax = fmax(hmax, g->gdxf[ic]);
    for (int pass = 0; pass < 2; pass++) {
        double m = s->radius + (band + 0.5) * hmax;
        for (int d = 0; d < g->dim; d++)
            if (!index_range(g, d, c, s->xa[d] - m, s->xa[d] + m, &lo[d], &hi[d])) return 0;
        if (g->periodic[0]) break;
        double h2 = hmax;
        for (int i = lo[0]; i <= hi[0]; i++) h2 = fmax(h2, g->gdxf[i]);
        if (h2 <= hmax) break;
        hmax = h2;
    }
    if (g->dim == 2) lo[2] = hi[2] = 0;
    for (int d = 0; d < g->dim; d++)
        if (g->periodic[d] && hi[d] - lo[d] + 1 > g->n[d])
            die("immersed boundary: a sphere of radius %g with its band (%g cells) is wider than the periodic "
                "%c direction (%d cells): enlarge the domain",
                s->radius, band, "xyz"[d], g->n[d]);
    return 1;
}

/* Visit every node of component c (−1: cell centres) in the box of sphere
 * s on this rank: fn(ctx, m, img, r, h) with m the storage index, r the
 * offset of the node from the centre (periodic image applied) and h the
 * node's cell size. */
typedef void (*node_fn_t)(void *ctx, long m, const int8_t img[3], const double r[3], double h);

static inline void for_box_nodes(const ibm_t *ibm, const ibm_sphere_t *s, int c, node_fn_t fn, void *ctx)
{
    const grid_t *g = ibm->g;
    int lo[3], hi[3];
    if (!sphere_box(ibm, s, c, lo, hi)) return;
    int three = g->dim == 3;
    for (int ii = lo[0]; ii <= hi[0]; ii++) {
        int iw = g->periodic[0] ? wrap(ii, g->n[0]) : ii;
        int il = iw - g->ix0;
        if (il < 0 || il >= g->nxl) continue;
        int8_t img[3] = {(int8_t)((ii - iw) / g->n[0]), 0, 0};
        double r[3];
        r[0] = node_coord(g, 0, c, iw) + img[0] * g->L[0] - s->xa[0];
        double hx = c == 0 ? g->dxc[il] : g->dxf[il];
        double h = three ? cbrt(hx * g->dy * g->dz) : sqrt(hx * g->dy);
        for (int jj = lo[1]; jj <= hi[1]; jj++) {
            int jw = g->periodic[1] ? wrap(jj, g->n[1]) : jj;
            img[1] = (int8_t)((jj - jw) / g->n[1]);
            r[1] = node_coord(g, 1, c, jw) + img[1] * g->L[1] - s->xa[1];
            for (int kk = lo[2]; kk <= hi[2]; kk++) {
                int kw = kk;
                if (three) {
                    kw = g->periodic[2] ? wrap(kk, g->n[2]) : kk;
                    img[2] = (int8_t)((kk - kw) / g->n[2]);
                    r[2] = node_coord(g, 2, c, kw) + img[2] * g->L[2] - s->xa[2];
                } else {
                    r[2] = 0.0;
                }
                fn(ctx, G_IDX(g, il, jw, kw), img, r, h);
            }
        }
    }
}

/* ---- node lists ---------------------------------------------------------------- */

typedef struct {
    ibm_priv_t *q;
    double R, band, retraction;
    int c;
} build_ctx_t;

static void add_node(void *ctx, long m, const int8_t img[3], const double r[3], double h)
{
    build_ctx_t *b = ctx;
    double rr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]), d = rr - b->R + b->retraction * h;
    if (d >= b->band * h) return;
    double a = 1.0;
    if (d > -b->band * h) {
        double n[3] = {r[0] / rr, r[1] / rr, r[2] / rr};
        a = ibm_alpha(d, n, h);
        if (a <= 0.0) return;
    }
    ibm_priv_t *q = b->q;
    if (q->nnodes == q->cap) {
        q->cap = q->cap ? 2 * q->cap : 4096;
        q->nodes = realloc(q->nodes, (size_t)q->cap * sizeof *q->nodes);
        if (!q->nodes) die_local("immersed boundary: out of memory for %ld node entries", q->cap);
    }
    ibm_node_t *e = &q->nodes[q->nnodes++];
    e->alpha = a;
    e->m = (int32_t)m;
    e->c = (uint8_t)b->c;
    for (int d2 = 0; d2 < 3; d2++) e->img[d2] = img[d2];
}

void ibm_build_nodes(ibm_t *ibm)
{
    ibm_priv_t *q = ibm_priv(ibm);
    build_ctx_t b = {.q = q, .band = ibm_band_halfwidth(), .retraction = ibm->prm.retraction};
    q->nnodes = 0;
    for (int p = 0; p < ibm->n; p++) {
        q->start[p] = q->nnodes;
        b.R = ibm->s[p].radius;
        for (int c = 0; c < ibm->g->dim; c++) {
            b.c = c;
            for_box_nodes(ibm, &ibm->s[p], c, add_node, &b);
        }
    }
    q->start[ibm->n] = q->nnodes;
    ibm->nodes_forced = q->nnodes;
}

void ibm_node_offset(const ibm_t *ibm, const ibm_node_t *e, const ibm_sphere_t *s, double r[3])
{
    const grid_t *g = ibm->g;
    long m = e->m;
    int i = (int)(m / g->sx) - 1;
    long rem = m % g->sx;
    int j = (int)(rem / g->sy) - 1, k = (int)(rem % g->sy) - g->gz;
    int c = e->c;
    r[0] = (c == 0 ? g->xf[i] : g->xc[i]) + e->img[0] * g->L[0] - s->xa[0];
    r[1] = node_coord(g, 1, c, j) + e->img[1] * g->L[1] - s->xa[1];
    r[2] = g->dim == 3 ? node_coord(g, 2, c, k) + e->img[2] * g->L[2] - s->xa[2] : 0.0;
}

/* ---- solid fraction fields --------------------------------------------------------- */

void ibm_solid_fraction_face(const ibm_t *ibm, int c, double *out)
{
    const ibm_priv_t *q = ibm_priv(ibm);
    field_zero(ibm->g, out);
    for (long e = 0; e < q->nnodes; e++)
        if (q->nodes[e].c == c) out[q->nodes[e].m] += q->nodes[e].alpha;
    for (long e = 0; e < q->nnodes; e++)
        if (q->nodes[e].c == c && out[q->nodes[e].m] > 1.0) out[q->nodes[e].m] = 1.0;
}

typedef struct {
    double *out;
    double R, band, retraction;
} cell_ctx_t;

static void add_cell(void *ctx, long m, const int8_t img[3], const double r[3], double h)
{
    (void)img;
    cell_ctx_t *b = ctx;
    double rr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]), d = rr - b->R + b->retraction * h;
    if (d >= b->band * h) return;
    double a = 1.0;
    if (d > -b->band * h) {
        double n[3] = {r[0] / rr, r[1] / rr, r[2] / rr};
        a = ibm_alpha(d, n, h);
    }
    b->out[m] = fmin(1.0, b->out[m] + a);
}

void ibm_solid_fraction_cell(const ibm_t *ibm, double *out)
{
    field_zero(ibm->g, out);
    cell_ctx_t b = {.out = out, .band = ibm_band_halfwidth(), .retraction = ibm->prm.retraction};
    for (int p = 0; p < ibm->n; p++) {
        b.R = ibm->s[p].radius;
        for_box_nodes(ibm, &ibm->s[p], -1, add_cell, &b);
    }
}
