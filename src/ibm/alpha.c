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
double ibm_band_halfwidth(void)
{
    static double band = 0.0; /* computed once: it is asked for per sphere and grid plane */
    if (band == 0.0) band = atanh(1.0 - 2.0 * IBM_ALPHA_CUT) * 0.46335 * M_SQRT2;
    return band;
}

/* ½[1 − tanh t] with the cut, tabulated: f(t) for t = d/(σλΔ) in [0, T]
 * (f(−t) = 1 − f(t)), T = atanh(1 − 2ε) where f reaches 0, sampled at
 * ALPHA_TABLE + 1 points and interpolated linearly — a continuous,
 * monotone profile within 4e-9 of the formula (|f''| ≤ 0.2, spacing
 * 4.2e-4), at a fraction of the cost of tanh for the many band nodes. */
#define ALPHA_TABLE 8192
static double alpha_table[ALPHA_TABLE + 2], alpha_tmax, alpha_scale;

static double alpha_exact(double t)
{
    double a = (0.5 * (1.0 - tanh(t)) - IBM_ALPHA_CUT) / (1.0 - 2.0 * IBM_ALPHA_CUT);
    return a < 0.0 ? 0.0 : (a > 1.0 ? 1.0 : a);
}

static void alpha_table_init(void)
{
    alpha_tmax = atanh(1.0 - 2.0 * IBM_ALPHA_CUT);
    alpha_scale = ALPHA_TABLE / alpha_tmax;
    for (int i = 0; i <= ALPHA_TABLE; i++) alpha_table[i] = alpha_exact(i / alpha_scale);
    alpha_table[ALPHA_TABLE] = alpha_table[ALPHA_TABLE + 1] = 0.0;
}

static inline double alpha_of_t(double t)
{
    double x = (t < 0 ? -t : t) * alpha_scale;
    if (x >= ALPHA_TABLE) return t < 0 ? 1.0 : 0.0;
    int i = (int)x;
    double w = x - i, f = alpha_table[i] + w * (alpha_table[i + 1] - alpha_table[i]);
    return t < 0 ? 1.0 - f : f;
}

double ibm_alpha(double d, const double n[3], double h)
{
    if (alpha_tmax == 0.0) alpha_table_init();
    double lam = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
    double sigma = 0.065 * (1.0 - lam * lam) + 0.39;
    return alpha_of_t(d / (sigma * lam * M_SQRT2 * h));
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

/* i modulo n in [0, n) (i is within a few periods of the domain) */
static inline int wrap(int i, int n)
{
    while (i < 0) i += n;
    while (i >= n) i -= n;
    return i;
}

/* First global index whose node coordinate is >= x (non-periodic x). */
int ibm_lower_index(const grid_t *g, int c, double x)
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
        *lo = ibm_lower_index(g, c, a);
        *hi = ibm_lower_index(g, c, b) - 1;
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
    double band = ibm_band(ibm);
    double hmax = g->dy;
    if (g->dim == 3) hmax = fmax(hmax, g->dz);
    /* x spacing near the sphere, then over the whole x range of the box
     * (stretched grids: the margin must cover the largest cell in it) */
    int ic = ibm_lower_index(g, -1, s->xa[0]);
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

/* Cell size h of the nodes of component c (−1: cell centres) in the grid
 * plane of local x index il: the cube root of the control-volume extents
 * in 3-D, the square root in 2-D (as hcell of ibm.c). */
static double plane_cell_size(const grid_t *g, int c, int il)
{
    double hx = c == 0 ? g->dxc[il] : g->dxf[il];
    return g->dim == 3 ? cbrt(hx * g->dy * g->dz) : sqrt(hx * g->dy);
}

/* ---- radius_correction = gaps: the margin (the neighbours and the thickening: alpha_gaps.c) */

/* The most the forced radius grows beyond ibm_forced_radius(), in cells. */
static inline double gap_margin(const ibm_t *ibm)
{
    return ibm->prm.radius_calibrated == IBM_RADIUS_GAPS ? IBM_GAP_MAX : 0.0;
}

/* Most segments plane_segments() writes for a box lo..hi: two per grid
 * line (a line of the box is split at most once by a periodic face, the
 * box being narrower than the period). */
static inline long plane_segments_max(const grid_t *g, const int lo[3], const int hi[3])
{
    return g->dim == 3 ? 2L * (hi[1] - lo[1] + 1) : 2L;
}

/* The segments of the nodes of component c (−1: cell centres) of sphere p
 * (box lo..hi from sphere_box) in the grid plane of unwrapped x index ii
 * (cell size h of plane_cell_size()), if that plane is on this rank, that
 * lie within R_eff + band h of its centre (R_eff = ibm_forced_radius(R, h)): the
 * grid lines along the run direction (z in 3-D, y in 2-D) through the box,
 * in storage order, each cut to the chord of that ball and split where a
 * periodic face crosses it.  Written to out (room for plane_segments_max())
 * as runs of sphere p: storage index m0 of the first node, count len,
 * offset r0 of the first from the sphere's centre, grid line `line` (the
 * y index in 3-D, 0 in 2-D); a0 and u0 are left to the caller.  Returns
 * their number.  The cost is that of the nodes returned plus one test per
 * grid line of the box: no call per segment (a few hundred thousand per
 * build). */
static int plane_segments(const ibm_t *ibm, int p, int c, int ii, const int lo[3], const int hi[3], double h,
                          ibm_run_t *restrict out)
{
    const grid_t *g = ibm->g;
    const ibm_sphere_t *s = &ibm->s[p];
    int three = g->dim == 3, rd = three ? 2 : 1;
    int nr = g->n[rd], prd = g->periodic[rd], py = three && g->periodic[1];
    double hr = three ? g->dz : g->dy, offr = c == rd ? 1.0 : 0.5, band = ibm_band(ibm);
    int jlo = three ? lo[1] : 0, jhi = three ? hi[1] : 0;
    int iw = g->periodic[0] ? wrap(ii, g->n[0]) : ii;
    int il = iw - g->ix0, nout = 0;
    if (il < 0 || il >= g->nxl) return 0;
    double r[3] = {0, 0, 0};
    r[0] = node_coord(g, 0, c, iw) + (ii - iw) / g->n[0] * g->L[0] - s->xa[0];
    double Rout = ibm_forced_radius(ibm, s->radius, h) + (band + gap_margin(ibm)) * h, Rout2 = Rout * Rout;
    double xs = s->xa[rd] - g->x0[rd], perp0 = r[0] * r[0];
    if (perp0 >= Rout2) return 0; /* the plane misses the ball */
    if (three) {
        /* the lines that may reach the ball, with a line of margin either
         * side (each is still tested below, as if all were visited) */
        double half = sqrt(Rout2 - perp0), ys = (s->xa[1] - g->x0[1]) / g->dy - (c == 1 ? 1.0 : 0.5);
        double ja = floor(ys - half / g->dy) - 1, jb = ceil(ys + half / g->dy) + 1;
        if (ja > jlo) jlo = (int)ja;
        if (jb < jhi) jhi = (int)jb;
    }
    /* the wrapped jj and the number of periods (jj − jw)/n_y, carried
     * along (no integer division per line) */
    int jw = py ? wrap(jlo, g->n[1]) : jlo, jper = (jlo - jw) / g->n[1];
    for (int jj = jlo; jj <= jhi; jj++, jper += py && jw == g->n[1] - 1, jw = py && jw == g->n[1] - 1 ? 0 : jw + 1) {
        double perp2 = perp0;
        if (three) {
            r[1] = node_coord(g, 1, c, jw) + jper * g->L[1] - s->xa[1];
            perp2 += r[1] * r[1];
        }
        if (perp2 >= Rout2) continue;
        /* the chord |r_run| < √(R_out² − r_perp²), within the box */
        double half = sqrt(Rout2 - perp2);
        int a = (int)ceil((xs - half) / hr - offr), b = (int)floor((xs + half) / hr - offr);
        if (a < lo[rd]) a = lo[rd];
        if (b > hi[rd]) b = hi[rd];
        while (a <= b) {
            /* one segment: up to the next periodic face */
            int aw = prd ? wrap(a, nr) : a, len = b - a + 1;
            if (prd && aw + len > nr) len = nr - aw;
            ibm_run_t *o = &out[nout++];
            o->r0[0] = r[0];
            o->r0[1] = r[1];
            o->r0[2] = r[2];
            o->r0[rd] = g->x0[rd] + (a + offr) * hr - s->xa[rd];
            o->m0 = (int32_t)(three ? G_IDX(g, il, jw, aw) : G_IDX(g, il, aw, 0));
            o->len = (int16_t)len;
            o->c = (uint8_t)c;
            o->p = p;
            o->line = three ? jw : 0;
            a += len;
        }
    }
    return nout;
}

/* ---- node runs ------------------------------------------------------------------ */

/* α of the node at offset r from the centre of a sphere of forced radius R
 * (ibm_forced_radius): the profile of ibm_alpha() with its smoothing length
 * s times the seed's (band_width; band: its half-width in cells, s
 * included) — the cell-centre fraction of the snapshots. */
static inline double alpha_at(double R, double band, const double r[3], double h, double s)
{
    double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    double Rin = R - band * h;
    if (Rin > 0 && r2 <= Rin * Rin) return 1.0;
    double rr = sqrt(r2), d = rr - R;
    if (d >= band * h) return 0.0;
    if (d <= -band * h) return 1.0;
    double lam = fabs(r[0] / rr) + fabs(r[1] / rr) + fabs(r[2] / rr);
    double sigma = 0.065 * (1.0 - lam * lam) + 0.39;
    return alpha_of_t(d / (s * sigma * lam * M_SQRT2 * h));
}

/* α of the nodes of consecutive runs of one plane (cell size h), their α
 * contiguous from al: the profile of alpha_at() for a sphere of radius
 * R_eff = ibm_forced_radius(R, h).  The nodes are gathered in batches of
 * ALPHA_BATCH (their run coordinate z and their run's constants), so that
 * the two loops of alpha_batch() run over many nodes at a time, whatever
 * the length of the runs (about 10 at D/Δx = 10).  Node k of a run is at
 * z = r0 + k step (for k ≥ 64: (r0 + k0 step) + (k − k0) step, k0 the
 * multiple of 64 below k) and λ takes one division, so the α differ from
 * alpha_at() by round-off. */
enum { ALPHA_BATCH = 256 };

/* Runs of at most RUN_SHORT nodes (nearly all at D/Δx ≲ 12) are gathered
 * in a loop of that fixed length, the values beyond the run's end
 * overwritten by the next run: a loop whose length varies from run to run
 * ends in a mispredicted branch, which costs more than the few extra
 * iterations. */
enum { RUN_SHORT = 16 };

/* The batch: the first loop (square root, divisions) without branches so
 * that the compiler vectorises it, the second the table look-up; the table
 * is 0 beyond its end, and a node at the centre, where λ is 0/0, takes its
 * end too (α = 1). */
static void alpha_batch(int n, const double *z, const double *p2, const double *pa, const double *reff,
                        double tscale, double s, double *restrict al)
{
    double x[ALPHA_BATCH];
    for (int k = 0; k < n; k++) {
        double rr = sqrt(p2[k] + z[k] * z[k]), d = rr - reff[k];
        double lam = (pa[k] + fabs(z[k])) / rr, sigma = 0.065 * (1.0 - lam * lam) + 0.39;
        double t = d * tscale / (sigma * lam * s); /* t of alpha_at() times alpha_scale */
        x[k] = t < -ALPHA_TABLE ? -ALPHA_TABLE : (t > ALPHA_TABLE ? ALPHA_TABLE : t);
        x[k] = rr > 0.0 ? x[k] : -ALPHA_TABLE;
    }
    for (int k = 0; k < n; k++) {
        double xa = fabs(x[k]);
        int i = (int)xa;
        double f = alpha_table[i] + (xa - i) * (alpha_table[i + 1] - alpha_table[i]);
        al[k] = x[k] < 0.0 ? 1.0 - f : f;
    }
}

/* α of the runs of one plane (cell size h), contiguous from al, and for
 * each of these node entries its forced node relative to the plane's
 * first (nid: u0 − n0 + k; room for RUN_SHORT more).  Sets each run's a0
 * (its α from a0_first on). */
static void alpha_runs(const ibm_t *ibm, ibm_run_t *runs, long nr, double h, long n0, long a0_first,
                       double *restrict al, int32_t *restrict nid)
{
    const ibm_priv_t *q = ibm_priv(ibm);
    double z[ALPHA_BATCH + RUN_SHORT], p2[ALPHA_BATCH + RUN_SHORT], pa[ALPHA_BATCH + RUN_SHORT],
        reff[ALPHA_BATCH + RUN_SHORT], kstep[RUN_SHORT];
    double step = q->rstep, tscale = alpha_scale / (M_SQRT2 * h);
    int rd = q->rdir, e = 0; /* nodes in the batch */
    const int gaps = ibm->prm.radius_calibrated == IBM_RADIUS_GAPS;
    long ep = 0;             /* nodes of the plane so far */
    for (int k = 0; k < RUN_SHORT; k++) kstep[k] = k * step;
    for (long ir = 0; ir < nr; ir++) {
        ibm_run_t *run = &runs[ir];
        double P2 = 0.0, PA = 0.0, R = ibm_forced_radius(ibm, ibm->s[run->p].radius, h), z0 = run->r0[rd];
        int len = run->len;
        int32_t u = (int32_t)(run->u0 - n0);
        run->a0 = (int32_t)(a0_first + ep);
        for (int d = 0; d < 3; d++)
            if (d != rd) P2 += run->r0[d] * run->r0[d], PA += fabs(run->r0[d]);
        if (len <= RUN_SHORT && e + len <= ALPHA_BATCH) {
            /* the common case, without tests: RUN_SHORT values, those
             * beyond len overwritten by the next runs */
            for (int k = 0; k < RUN_SHORT; k++) {
                z[e + k] = (z0 + 0 * step) + kstep[k]; /* the formula below at k < 64 */
                p2[e + k] = P2;
                pa[e + k] = PA;
                reff[e + k] = R;
                nid[ep + k] = u + k;
            }
            if (gaps)
                for (int k = 0; k < len; k++) {
                    double r[3] = {run->r0[0], run->r0[1], run->r0[2]};
                    r[rd] = z[e + k];
                    reff[e + k] += ibm_gap_extra(ibm, run->p, r, h);
                }
            e += len;
            ep += len;
            continue;
        }
        for (int k = 0; k < len; k++) nid[ep + k] = u + k;
        ep += len;
        for (int k = 0; k < len; k++) {
            if (e == ALPHA_BATCH) {
                alpha_batch(e, z, p2, pa, reff, tscale, ibm->prm.band_width, al);
                al += e;
                e = 0;
            }
            z[e] = (z0 + (k & ~63) * step) + (k & 63) * step;
            p2[e] = P2;
            pa[e] = PA;
            reff[e] = R;
            if (gaps) {
                double r[3] = {run->r0[0], run->r0[1], run->r0[2]};
                r[rd] = z[e];
                reff[e] += ibm_gap_extra(ibm, run->p, r, h);
            }
            e++;
        }
    }
    if (e) alpha_batch(e, z, p2, pa, reff, tscale, ibm->prm.band_width, al);
}

/* Room for need elements of size sz in *ptr (capacity *cap, doubled). */
static void grow(void **ptr, long *cap, long need, size_t sz, const char *what)
{
    if (need <= *cap && *ptr) return;
    long c = *cap > 0 ? *cap : 1024;
    while (c < need) c *= 2;
    void *p = realloc(*ptr, (size_t)c * sz);
    if (!p) die_local("immersed boundary: out of memory for %ld %s", c, what);
    *ptr = p;
    *cap = c;
}

/* Storage order of two runs of a grid line: by first node, then by sphere. */
static inline int run_after(const ibm_run_t *a, const ibm_run_t *b)
{
    return a->m0 > b->m0 || (a->m0 == b->m0 && a->p > b->p);
}

/* Sort the runs generated in one grid plane into storage order (by grid
 * line, each line's runs by m0, then by sphere) and append them to the
 * runs, merged into forced nodes: the runs of a line that overlap or touch
 * become one node run, each node once; every sphere run gets the index of
 * its first node (u0).  All of it on the plane's few thousand runs, in
 * cache, moving the runs themselves (no index array to follow). */
static void sort_and_merge_plane(ibm_t *ibm)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    long st = q->rstride, nlines = g->dim == 3 ? g->n[1] : 1;
    int32_t *head = q->line_head;
    grow((void **)&q->runs, &q->cap_runs, q->nruns + q->ntmp, sizeof *q->runs, "runs");
    /* room for a node run per sphere run (no more node runs than runs) */
    grow((void **)&q->nruns_f, &q->cap_nruns, q->n_nruns + q->ntmp, sizeof *q->nruns_f, "node runs");
    /* counting sort by line into runs[head[l] .. head[l+1]), then each
     * line's few runs by m0 and sphere (insertion sort; the spheres were
     * visited by their run coordinate, so that the runs come nearly
     * sorted) */
    ibm_run_t *R = q->runs + q->nruns;
    memset(head, 0, (size_t)(nlines + 1) * sizeof *head);
    for (long ir = 0; ir < q->ntmp; ir++) head[q->tmp[ir].line + 1]++;
    for (long l = 0; l < nlines; l++) head[l + 1] += head[l];
    for (long ir = 0; ir < q->ntmp; ir++) R[head[q->tmp[ir].line]++] = q->tmp[ir];
    for (long l = nlines; l > 0; l--) head[l] = head[l - 1];
    head[0] = 0;
    for (long l = 0; l < nlines; l++) {
        ibm_run_t *o = R + head[l];
        int cnt = head[l + 1] - head[l];
        for (int i = 1; i < cnt; i++) {
            if (!run_after(&o[i - 1], &o[i])) continue;
            ibm_run_t v = o[i];
            int j = i;
            for (; j > 0 && run_after(&o[j - 1], &v); j--) o[j] = o[j - 1];
            o[j] = v;
        }
    }
    /* merge, line by line (the runs of a line are contiguous now) */
    long e = 0, end = q->ntmp;
    while (e < end) {
        long ms = R[e].m0, me = ms - st, n0 = q->nnodes; /* first and last node */
        int32_t line = R[e].line;
        for (; e < end && R[e].line == line && R[e].m0 <= me + st; e++) {
            ibm_run_t *o = &R[e];
            o->u0 = (int32_t)(n0 + (st == 1 ? o->m0 - ms : (o->m0 - ms) / st));
            long oe = o->m0 + (o->len - 1) * st;
            if (oe > me) me = oe;
        }
        ibm_node_run_t *n = &q->nruns_f[q->n_nruns++];
        n->m0 = (int32_t)ms;
        n->n0 = (int32_t)n0;
        n->len = (int32_t)(st == 1 ? me - ms + 1 : (me - ms) / st + 1);
        n->c = R[e - 1].c;
        q->nnodes += n->len;
    }
    q->nruns += q->ntmp;
}

/* α of the runs r0 .. r1−1 (one plane, forced nodes n0 .. n1−1), Σ_p α_p
 * at each of its forced nodes and the count of entries at shared nodes
 * (nshared).  The sums go entry by entry in storage order (each node's
 * terms in the order of its runs, as a pass run by run adds them), in one
 * loop over all the plane's entries rather than one short loop per run
 * (about 10 nodes at D/Δx = 10), whose varying length costs a mispredicted
 * branch per run. */
static void plane_alpha(ibm_t *ibm, long r0, long r1, long n0, long n1)
{
    ibm_priv_t *q = ibm_priv(ibm);
    const grid_t *g = ibm->g;
    long n = 0, nn = n1 - n0;
    for (long ir = r0; ir < r1; ir++) n += q->runs[ir].len;
    grow((void **)&q->alpha, &q->cap_alpha, q->nalpha + n, sizeof *q->alpha, "solid fractions");
    if (n1 > q->cap_nodes) {
        long cap = q->cap_nodes, cap2 = cap, cap3 = cap;
        grow((void **)&q->node_asum, &cap, n1, sizeof(double), "nodes");
        grow((void **)&q->node_target, &cap2, n1, sizeof(double), "nodes");
        grow((void **)&q->node_imp, &cap3, n1, sizeof(double), "nodes");
        q->cap_nodes = cap;
    }
    /* scratch: the forced node of each entry (in entry_node[]), the number of
     * spheres at each node (cnt[]) */
    grow((void **)&q->entry_node, &q->cap_entry_node, n + RUN_SHORT, sizeof *q->entry_node, "nodes");
    grow((void **)&q->cnt, &q->cap_cnt, nn, sizeof *q->cnt, "nodes");
    const double *al = q->alpha + q->nalpha;
    /* the cell size h is that of the plane */
    alpha_runs(ibm, q->runs + r0, r1 - r0, q->hcell[q->runs[r0].c][ibm_node_i(g, q->runs[r0].m0)], n0, q->nalpha,
               q->alpha + q->nalpha, q->entry_node);
    q->nalpha += n;
    double *restrict A = q->node_asum + n0;
    int32_t *restrict cnt = q->cnt;
    const int32_t *restrict nid = q->entry_node;
    memset(A, 0, (size_t)nn * sizeof *A);
    memset(cnt, 0, (size_t)nn * sizeof *cnt);
    for (long e = 0; e < n; e++) {
        A[nid[e]] += al[e];
        cnt[nid[e]]++;
    }
    long shared = 0;
    for (long j = 0; j < nn; j++) shared += cnt[j] > 1 ? cnt[j] : 0;
    q->nshared += shared;
}

typedef struct {
    double z;  /* centre along the run direction */
    int32_t p;
} zkey_t;

static int by_run_coordinate(const void *a, const void *b)
{
    const zkey_t *i = a, *j = b;
    return i->z < j->z ? -1 : i->z > j->z ? 1 : (i->p > j->p) - (i->p < j->p);
}

/* The node runs of each (component c, local x plane i): plane_nrun[c (nxl
 * + 1) + i] .. plane_nrun[c (nxl + 1) + i + 1] − 1 (the build appends them
 * by component, then by plane), found by bisection at the end of each build (the plane hook forces a
 * plane's node runs). */
static void index_planes(ibm_t *ibm)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    long np = (long)g->nxl + 1;
    for (int c = 0; c < g->dim; c++)
        for (int i = 0; i <= g->nxl; i++) {
            /* first node run whose (component, plane) is not below (c, i) */
            long lo = 0, hi = q->n_nruns, key = c * np + i;
            while (lo < hi) {
                long mid = (lo + hi) / 2;
                const ibm_node_run_t *nr = &q->nruns_f[mid];
                if (nr->c * np + ibm_node_i(g, nr->m0) < key)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            q->plane_nrun[c * np + i] = lo;
        }
}

/* The node lists, plane by plane (component c, local x index i) in
 * storage order: the spheres whose box reaches the plane generate their
 * runs there, which are sorted, merged and given their α, and, while they
 * are in cache, the targets of the forcing (targets != 0: from the
 * spheres' current velocities, as set_targets() in forcing.c) and the
 * momentum integrals of each sphere (mom != NULL: into its
 * IBM_MOM..IBM_ANG+2, as ibm_momentum()). */
void ibm_build_nodes(ibm_t *ibm, double *mom, int targets)
{
    const grid_t *g = ibm->g;
    ibm_priv_t *q = ibm_priv(ibm);
    if (alpha_tmax == 0.0) alpha_table_init();
    q->nruns = q->n_nruns = q->nnodes = q->nalpha = q->nshared = 0;
    if (ibm->prm.radius_calibrated == IBM_RADIUS_GAPS) ibm_gap_neighbours(ibm);
    if (mom) ibm_sums_zero(ibm, mom, 0, 1);
    if (targets) ibm_targets_note(ibm);
    int *box = xcalloc(7 * (size_t)(ibm->n > 0 ? ibm->n : 1), sizeof *box); /* lo[3], hi[3], in the domain */
    int32_t *head = xcalloc((size_t)g->nxl + 1, sizeof *head), *pair = NULL;
    /* the spheres by their coordinate along the run direction */
    zkey_t *zord = xcalloc((size_t)(ibm->n > 0 ? ibm->n : 1), sizeof *zord);
    for (int p = 0; p < ibm->n; p++) zord[p] = (zkey_t){ibm->s[p].xa[q->rdir], p};
    qsort(zord, (size_t)ibm->n, sizeof *zord, by_run_coordinate);
    long npair = 0, cap_pair = 0;
    for (int c = 0; c < g->dim; c++) {
        /* the (sphere, unwrapped x index) pairs of each plane of this rank,
         * the spheres of a plane by their run coordinate */
        memset(head, 0, ((size_t)g->nxl + 1) * sizeof *head);
        npair = 0;
        for (int p = 0; p < ibm->n; p++) {
            int *bx = box + 7 * p;
            bx[6] = sphere_box(ibm, &ibm->s[p], c, bx, bx + 3);
            if (!bx[6]) continue;
            for (int ii = bx[0]; ii <= bx[3]; ii++) {
                int il = (g->periodic[0] ? wrap(ii, g->n[0]) : ii) - g->ix0;
                if (il >= 0 && il < g->nxl) head[il + 1]++, npair++;
            }
        }
        grow((void **)&pair, &cap_pair, 2 * npair, sizeof *pair, "planes");
        for (int i = 0; i < g->nxl; i++) head[i + 1] += head[i];
        for (int o = 0; o < ibm->n; o++) {
            int p = zord[o].p;
            const int *bx = box + 7 * p;
            if (!bx[6]) continue;
            for (int ii = bx[0]; ii <= bx[3]; ii++) {
                int il = (g->periodic[0] ? wrap(ii, g->n[0]) : ii) - g->ix0;
                if (il >= 0 && il < g->nxl) pair[2 * head[il]] = p, pair[2 * head[il]++ + 1] = ii;
            }
        }
        for (int i = g->nxl; i > 0; i--) head[i] = head[i - 1];
        head[0] = 0;
        for (int i = 0; i < g->nxl; i++) {
            long r0 = q->nruns, n0 = q->nnodes;
            double h = q->hcell[c][i];
            q->ntmp = 0;
            for (int k = head[i]; k < head[i + 1]; k++) {
                int p = pair[2 * k];
                const int *bx = box + 7 * p;
                long need = q->ntmp + plane_segments_max(g, bx, bx + 3);
                if (need > q->cap_tmp) grow((void **)&q->tmp, &q->cap_tmp, need, sizeof *q->tmp, "runs");
                q->ntmp += plane_segments(ibm, p, c, pair[2 * k + 1], bx, bx + 3, h, q->tmp + q->ntmp);
            }
            if (q->ntmp == 0) continue;
            sort_and_merge_plane(ibm);
            plane_alpha(ibm, r0, q->nruns, n0, q->nnodes);
            if (targets) ibm_targets_of(ibm, r0, q->nruns, n0, q->nnodes);
            if (mom) ibm_sums_of(ibm, mom, r0, q->nruns, 0, 1);
        }
    }
    free(box);
    free(zord);
    free(head);
    free(pair);
    q->built = 1;
    q->targets_valid = targets;
    ibm->nodes_forced = q->nalpha;
    ibm->nodes_distinct = q->nnodes;
    ibm->nodes_shared = q->nshared;
    index_planes(ibm);
}

/* ---- solid fraction fields --------------------------------------------------------- */

void ibm_solid_fraction_face(const ibm_t *ibm, int c, double *out)
{
    /* min(1, Σ_p α_p) of each forced node: node_asum, summed by the build */
    const ibm_priv_t *q = ibm_priv(ibm);
    field_zero(ibm->g, out);
    for (long r = 0; r < q->n_nruns; r++) {
        const ibm_node_run_t *nr = &q->nruns_f[r];
        if (nr->c != c) continue;
        const double *A = q->node_asum + nr->n0;
        for (int k = 0; k < nr->len; k++) out[nr->m0 + k * q->rstride] = A[k] < 1.0 ? A[k] : 1.0;
    }
}

void ibm_solid_fraction_cell(const ibm_t *ibm, double *out)
{
    const grid_t *g = ibm->g;
    const ibm_priv_t *q = ibm_priv(ibm);
    double band = ibm_band(ibm);
    ibm_run_t *seg = NULL;
    long cap = 0;
    field_zero(g, out);
    for (int p = 0; p < ibm->n; p++) {
        int lo[3], hi[3];
        if (!sphere_box(ibm, &ibm->s[p], -1, lo, hi)) continue;
        grow((void **)&seg, &cap, plane_segments_max(g, lo, hi), sizeof *seg, "runs");
        for (int ii = lo[0]; ii <= hi[0]; ii++) {
            int il = (g->periodic[0] ? wrap(ii, g->n[0]) : ii) - g->ix0;
            if (il < 0 || il >= g->nxl) continue;
            double h = plane_cell_size(g, -1, il);
            int nseg = plane_segments(ibm, p, -1, ii, lo, hi, h, seg);
            for (int e = 0; e < nseg; e++) {
                double r[3] = {seg[e].r0[0], seg[e].r0[1], seg[e].r0[2]};
                for (int k = 0; k < seg[e].len; k++, r[q->rdir] += q->rstep) {
                    long m = seg[e].m0 + k * q->rstride;
                    double Rf = ibm_forced_radius(ibm, ibm->s[p].radius, h);
                    if (ibm->prm.radius_calibrated == IBM_RADIUS_GAPS) Rf += ibm_gap_extra(ibm, p, r, h);
                    double a = out[m] + alpha_at(Rf, band, r, h, ibm->prm.band_width);
                    out[m] = a > 1.0 ? 1.0 : a;
                }
            }
        }
    }
    free(seg);
}
