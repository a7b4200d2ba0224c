/* triangulate.c — regular (weighted Delaunay, weights r²) triangulation of
 * the spheres through qhull's 4-D lift (catalano_pfv.md §5.3 option 1).
 *
 * A sphere (c, r) is lifted to (c, |c|² − r²); the lower convex hull of the
 * lifted points projects onto the regular triangulation, and the hyperplane
 * of a lower facet, n·(x, h) + d = 0, gives the orthocentre (power centre)
 * P = −(n_x, n_y, n_z)/(2 n_h) of its tetrahedron.
 *
 * Images: every sphere closer than `margin` to a face is copied across it —
 * shifted by the period on a periodic axis, mirrored on a wall axis (edges
 * and corners get the combined copies) — so that the pores of the box are
 * complete and the wall planes are power bisectors (porenet.h).  The margin
 * is checked against what the tetrahedra of the box need (needed_margin: no
 * image left out can be in conflict with them) and widened until it holds.
 *
 * Degeneracies (co-spherical sets: lattices, and every mirror-symmetric set
 * at a wall): qhull merges the coplanar lifted facets and option Qt splits
 * them into simplices that share one hyperplane; some of those simplices are
 * flat (zero volume).  network.c merges the tetrahedra that share a power
 * centre into one pore, so the arbitrary split does not matter; the power
 * centre of a flat tetrahedron (whose 3×3 system is singular) is taken from
 * the hyperplane.  Facets are "lower" when n_h < −1e-4 (not < 0): the nearly
 * vertical facets at the rim of the cloud (note §6) are flat and outside the
 * kept region anyway.
 */
#include <malloc.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libqhull_r/qhull_ra.h>

#include "porenet.h"
#include "porenet_internal.h"
#include "util.h"

void pn_tri_free(pn_tri_t *t)
{
    free(t->x);
    free(t->r);
    free(t->id);
    free(t->img);
    free(t->xm);
    free(t->xo);
    free(t->tet);
    free(t->nbr);
    free(t->P);
    free(t->cond);
    free(t->grp);
    free(t->clear);
    memset(t, 0, sizeof *t);
}

/* A centre on the wall plane of axis a (within round-off of the box length). */
static int on_plane(const pn_domain_t *dom, int a, double v)
{
    const double tol = 1e-12 * (dom->hi[a] - dom->lo[a]);
    return fabs(v - dom->lo[a]) <= tol || fabs(dom->hi[a] - v) <= tol;
}

/* Image of coordinate v of a sphere on axis a, image index s. */
static double image_coord(const pn_domain_t *dom, int a, int s, double v)
{
    if (s == 0) return v;
    if (dom->periodic[a]) return v + s * (dom->hi[a] - dom->lo[a]);
    return s < 0 ? 2.0 * dom->lo[a] - v : 2.0 * dom->hi[a] - v;
}

void pn_tri_point(const pn_domain_t *dom, const pn_tri_t *t, const double *x, int p, double out[3])
{
    (void)dom;
    /* image_coord as an affine map: v + s L and 2 lo − v (or 2 hi − v) are
     * reproduced bit for bit by 1·v + s L and −1·v + 2 lo */
    const double *c = x + 3 * (size_t)t->id[p];
    for (int a = 0; a < 3; a++) out[a] = t->xm[3 * p + a] * c[a] + t->xo[3 * p + a];
}

/* Orthocentre of 4 weighted points: 2(c_k − c_0)·P = |c_k|² − |c_0|² − (r_k² − r_0²),
 * solved relative to c_0.  Returns the determinant relative to the scale³. */
static double orthocentre(const double c[4][3], const double r[4], double P[3])
{
    double A[3][3], b[3];
    for (int k = 1; k < 4; k++) {
        double e[3] = {c[k][0] - c[0][0], c[k][1] - c[0][1], c[k][2] - c[0][2]};
        for (int a = 0; a < 3; a++) A[k - 1][a] = 2.0 * e[a];
        b[k - 1] = e[0] * e[0] + e[1] * e[1] + e[2] * e[2] - (r[k] * r[k] - r[0] * r[0]);
    }
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                 A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    double s = 0;
    for (int k = 0; k < 3; k++) s = fmax(s, fabs(A[k][0]) + fabs(A[k][1]) + fabs(A[k][2]));
    double rel = s > 0 ? fabs(det) / (s * s * s) : 0;
    if (rel < 1e-10) return rel;
    /* Cramer's rule */
    double y[3];
    for (int a = 0; a < 3; a++) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int k = 0; k < 3; k++) M[k][a] = b[k];
        y[a] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) /
               det;
    }
    for (int a = 0; a < 3; a++) P[a] = c[0][a] + y[a];
    return rel;
}

static const double **sort_own;
static int cmp_own(const void *a, const void *b)
{
    const double *x = sort_own[*(const int *)a], *y = sort_own[*(const int *)b];
    return x < y ? -1 : x > y;
}

int pn_fail(char *err, size_t nerr, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, nerr, fmt, ap);
    va_end(ap);
    return -1;
}

/* The triangulation with the images within `margin` of the faces. */
static int triangulate_once(const pn_domain_t *dom, int n, const double *x, const double *r, double margin, double rmax,
                            pn_tri_kind_t kind, pn_tri_t *t, char *err, size_t nerr);

/* The margin the tetrahedra of the box need: a point left out of the image
 * layer (some coordinate beyond lo − m or hi + m) lies at least δ_a from the
 * power centre P of a tetrahedron along that axis, so its power distance is
 * at least δ_a² − r_max²; if that exceeds the tetrahedron's power radius² w,
 * no such point can be in conflict with it (the empty-orthosphere property of
 * a regular triangulation), and the tetrahedron is the one of the complete,
 * unbounded image set.  Checked for the tetrahedra whose power centre lies in
 * the box (the pores of the box, those on a wall plane included), widened
 * along the periodic axes by twice the largest power radius of those inside
 * (their neighbours across a periodic face: the throats to them are kept,
 * and they must exist; across a wall they are mirror copies, whose throats
 * are not, network.c).
 * The clear-fluid tetrahedra (dom->clear_h) are left out: their pores hold
 * the hydrostatic pressure, and only the facets they share with the pores of
 * the packing matter.
 * Returns the smallest margin meeting the condition for all of them. */
static int clear_tet(const pn_tri_t *t, int k) { return t->clear && t->clear[k]; }

static double needed_margin(const pn_domain_t *dom, const pn_tri_t *t, double rmax)
{
    double *w = malloc(((size_t)t->ntet + 1) * sizeof *w), hin = 0;
    for (int k = 0; k < t->ntet; k++) {
        const double *P = t->P + 3 * k, *c = t->x + 3 * (size_t)t->tet[4 * k];
        const double rr = t->r[t->tet[4 * k]];
        w[k] = (P[0] - c[0]) * (P[0] - c[0]) + (P[1] - c[1]) * (P[1] - c[1]) + (P[2] - c[2]) * (P[2] - c[2]) - rr * rr;
        int in = 1;
        for (int a = 0; a < 3; a++) in &= P[a] >= dom->lo[a] && P[a] <= dom->hi[a];
        if (in && w[k] > 0 && !clear_tet(t, k)) hin = fmax(hin, sqrt(w[k]));
    }
    /* across a periodic face the neighbours of the pores of the box must exist and be exact: copies
     * of pores of the box, their power centres lie within 2 hin of the face (two power radii from a
     * centre inside), their vertices within √(hin² + r_max²) of those */
    double need = 0;
    for (int a = 0; a < 3; a++)
        if (dom->periodic[a]) need = fmax(need, 2 * hin + sqrt(hin * hin + rmax * rmax));
    for (int k = 0; k < t->ntet; k++) {
        const double *P = t->P + 3 * k;
        int near = 1;
        for (int a = 0; a < 3; a++) {
            /* across a wall the pores are mirror copies (their throats are not kept); across a periodic
             * face the neighbours are copies of the pores at the other face, whose throats are kept */
            const double h = dom->periodic[a] ? 2 * hin : 1e-8 * (dom->hi[a] - dom->lo[a]);
            near &= P[a] >= dom->lo[a] - h && P[a] <= dom->hi[a] + h;
        }
        if (!near || clear_tet(t, k)) continue;
        /* δ_a = m + (distance from P to the nearer face, negative outside) ≥ √(w + r_max²) */
        const double reach = sqrt(fmax(w[k], 0.0) + rmax * rmax);
        for (int a = 0; a < 3; a++) need = fmax(need, reach - fmin(P[a] - dom->lo[a], dom->hi[a] - P[a]));
    }
    free(w);
    return need;
}

int pn_triangulate(const pn_domain_t *dom, int n, const double *x, const double *r, double margin, pn_tri_t *t,
                   char *err, size_t nerr)
{
    return pn_triangulate_with(dom, n, x, r, margin, PN_TRI_CGAL, t, err, nerr);
}

int pn_triangulate_with(const pn_domain_t *dom, int n, const double *x, const double *r, double margin,
                        pn_tri_kind_t kind, pn_tri_t *t, char *err, size_t nerr)
{
    /* A rebuild frees the triangulation's large blocks and allocates the network's and the
     * factor's: kept in the heap (not returned to the system and mapped again, page by page, at
     * the next first touch) they are reused — measured 1.5-2x on the network's build at 30 000
     * pores (docs/performance.md).  Process-wide, set once. */
    static int heap_set = 0;
    if (!heap_set) {
        mallopt(M_MMAP_THRESHOLD, 32 << 20);
        mallopt(M_TRIM_THRESHOLD, 64 << 20);
        heap_set = 1;
    }
    memset(t, 0, sizeof *t);
    if (n < 1) return pn_fail(err, nerr, "no spheres");
    double rmax = 0;
    for (int i = 0; i < n; i++) rmax = fmax(rmax, r[i]);
    /* auto: start from 2.75 r_max (a dense packing's pores at a face need about 2.6 r_max).  A margin too
     * narrow for the packing is widened to what the tetrahedra need (needed_margin), up to 6 r_max or
     * the margin asked, whichever is wider, and below the box length; the pores that would need more
     * (those of a sphere-free layer at a face: a fluid layer above a bed) are left as they are, and
     * t->margin_needed > t->margin tells the caller */
    double m = margin > 0 ? margin : 2.75 * rmax, cap = fmax(m, 6.0 * rmax);
    for (int a = 0; a < 3; a++) cap = fmin(cap, 0.999 * (dom->hi[a] - dom->lo[a]));
    for (int iter = 0;; iter++) {
        if (triangulate_once(dom, n, x, r, m, rmax, kind, t, err, nerr)) return -1;
        const double need = needed_margin(dom, t, rmax);
        t->margin_needed = need;
        if (need <= m || m >= cap || iter == 8) return 0;
        pn_tri_free(t);
        m = fmin(cap, fmax(1.05 * need, 1.25 * m));
    }
}

/* The tetrahedra of the point set by CGAL (regular_cgal.cpp): every cell has a
 * positive volume, its power centre CGAL's weighted circumcentre (cond 1: the
 * members of a merged pore agree to the merging tolerance, network.c). */
static int tets_cgal(pn_tri_t *t, char *err, size_t nerr)
{
    if (pn_cgal_regular(t->npts, t->x, t->r, &t->ntet, &t->tet, &t->nbr, &t->P, err, nerr)) return -1;
    const int nt = t->ntet;
    t->cond = malloc(((size_t)nt + 1) * sizeof *t->cond);
    t->grp = malloc(((size_t)nt + 1) * sizeof *t->grp);
    for (int k = 0; k < nt; k++) t->cond[k] = 1, t->grp[k] = -1;
    return 0;
}

/* The tetrahedra of the point set by qhull's 4-D lift (the lower hull). */
static int tets_qhull(const pn_domain_t *dom, pn_tri_t *t, double margin, char *err, size_t nerr)
{
    const double *X = t->x, *R = t->r;
    const size_t np = (size_t)t->npts;
    /* Lifted coordinates, centred on the box and scaled to O(1) so that qhull's
     * precision (relative to the largest coordinate) is not wasted. */
    double ctr[3], scale = 0;
    for (int a = 0; a < 3; a++) {
        ctr[a] = 0.5 * (dom->lo[a] + dom->hi[a]);
        scale = fmax(scale, 0.5 * (dom->hi[a] - dom->lo[a]) + margin);
    }
    coordT *pts = malloc(4 * np * sizeof *pts);
    for (size_t p = 0; p < np; p++) {
        double h = 0;
        for (int a = 0; a < 3; a++) {
            double v = (X[3 * p + a] - ctr[a]) / scale;
            pts[4 * p + a] = v;
            h += v * v;
        }
        double rs = R[p] / scale;
        pts[4 * p + 3] = h - rs * rs;
    }

    qhT qh_qh;
    qhT *qh = &qh_qh;
    QHULL_LIB_CHECK
    qh_zero(qh, stderr);
    char cmd[] = "qhull Qt";
    int code = qh_new_qhull(qh, 4, (int)np, pts, False, cmd, NULL, stderr);
    if (code) {
        qh_freeqhull(qh, !qh_ALL);
        int cl, tl;
        qh_memfreeshort(qh, &cl, &tl);
        free(pts);
        return pn_fail(err, nerr, "qhull failed (exit code %d) on %zu lifted points", code, np);
    }

    /* Number the lower facets. */
    facetT *facet, *neighbor, **neighborp;
    vertexT *vertex, **vertexp;
    int nt = 0;
    FORALLfacets {
        if (facet->normal[3] < -1e-4 && qh_setsize(qh, facet->vertices) == 4)
            facet->visitid = (unsigned)nt++;
        else
            facet->visitid = (unsigned)-1;
    }
    t->ntet = nt;
    t->tet = malloc(4 * (size_t)nt * sizeof *t->tet);
    t->nbr = malloc(4 * (size_t)nt * sizeof *t->nbr);
    t->P = malloc(3 * (size_t)nt * sizeof *t->P);
    t->cond = malloc((size_t)nt * sizeof *t->cond);
    t->grp = malloc((size_t)nt * sizeof *t->grp);
    /* tetrahedra split from one merged (co-spherical) facet share its normal */
    const double **own = malloc((size_t)nt * sizeof *own);
    FORALLfacets {
        if (facet->visitid == (unsigned)-1) continue;
        int k = (int)facet->visitid, v = 0;
        FOREACHvertex_(facet->vertices) t->tet[4 * k + v++] = qh_pointid(qh, vertex->point);
        /* neighbour opposite vertex v: the neighbour facet not containing it */
        for (v = 0; v < 4; v++) t->nbr[4 * k + v] = -1;
        FOREACHneighbor_(facet) {
            if (neighbor->visitid == (unsigned)-1) continue;
            int shared[4] = {0, 0, 0, 0}, ns = 0;
            vertexT *w, **wp;
            FOREACHsetelement_(vertexT, neighbor->vertices, w) {
                for (v = 0; v < 4; v++)
                    if (qh_pointid(qh, w->point) == t->tet[4 * k + v]) shared[v] = 1, ns++;
            }
            (void)wp;
            if (ns != 3) continue;
            for (v = 0; v < 4; v++)
                if (!shared[v]) t->nbr[4 * k + v] = (int)neighbor->visitid;
        }
        /* power centre: 3×3 solve when well conditioned, else the hyperplane */
        double c[4][3], rr[4], P[3];
        for (v = 0; v < 4; v++) {
            int p = t->tet[4 * k + v];
            for (int a = 0; a < 3; a++) c[v][a] = X[3 * p + a];
            rr[v] = R[p];
        }
        /* A badly shaped tetrahedron (found in the symmetric sets at walls)
         * loses digits in the 3×3 solve: below 1e-6 the hyperplane (shared by
         * the whole co-spherical set) is more accurate. */
        double cnd = orthocentre(c, rr, P);
        if (cnd < 1e-6) {
            for (int a = 0; a < 3; a++) P[a] = ctr[a] - scale * facet->normal[a] / (2.0 * facet->normal[3]);
            t->n_flat++;
            cnd = 0;
        }
        memcpy(t->P + 3 * k, P, sizeof P);
        t->cond[k] = cnd;
        own[k] = facet->tricoplanar ? facet->normal : NULL;
    }
    /* number the co-spherical groups: same normal pointer */
    {
        int *ord = malloc((size_t)nt * sizeof *ord);
        for (int k = 0; k < nt; k++) ord[k] = k;
        for (int k = 0; k < nt; k++) t->grp[k] = -1;
        /* sort indices by pointer (qsort with a file-scope key array) */
        sort_own = own;
        qsort(ord, (size_t)nt, sizeof *ord, cmp_own);
        int g = -1;
        for (int m = 0; m < nt; m++) {
            int k = ord[m];
            if (!own[k]) continue;
            if (m == 0 || own[ord[m - 1]] != own[k]) g++;
            t->grp[k] = g;
        }
        free(ord);
    }
    free(own);
    qh_freeqhull(qh, !qh_ALL);
    int cl, tl;
    qh_memfreeshort(qh, &cl, &tl);
    free(pts);
    return 0;
}

static int triangulate_once(const pn_domain_t *dom, int n, const double *x, const double *r, double margin, double rmax,
                            pn_tri_kind_t kind, pn_tri_t *t, char *err, size_t nerr)
{
    memset(t, 0, sizeof *t);
    for (int i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) {
            double v = x[3 * i + a];
            if (!(v >= dom->lo[a] && v <= dom->hi[a]))
                return pn_fail(err, nerr, "sphere %d: centre (%g, %g, %g) outside the box", i, x[3 * i], x[3 * i + 1],
                            x[3 * i + 2]);
            /* A centre inside its own mirror image would be a hidden point
             * (§1.2): the distance to a wall must exceed r/2, unless the centre is on the
             * wall plane (a half-sphere fixed on the wall: its own image, none is made). */
            if (!dom->periodic[a] && !on_plane(dom, a, v) &&
                (v - dom->lo[a] <= 0.5 * r[i] || dom->hi[a] - v <= 0.5 * r[i]))
                return pn_fail(err, nerr, "sphere %d: centre closer than r/2 to a wall of axis %c (overlap with the wall)",
                            i, 'x' + a);
        }
    }
    (void)rmax;
    t->margin = margin;
    for (int a = 0; a < 3; a++)
        if (margin >= dom->hi[a] - dom->lo[a])
            return pn_fail(err, nerr, "box length along %c (%g) is not larger than the image margin %g",
                        'x' + a, dom->hi[a] - dom->lo[a], margin);

    /* ---- extended point set ---- */
    size_t cap = (size_t)n * 2 + 64, np = 0;
    double *X = malloc(3 * cap * sizeof *X), *R = malloc(cap * sizeof *R);
    int *ID = malloc(cap * sizeof *ID);
    signed char *IMG = malloc(3 * cap);
    for (int s = 0; s < 27; s++) {
        int sh[3] = {s % 3 - 1, (s / 3) % 3 - 1, s / 9 - 1};
        for (int i = 0; i < n; i++) {
            double y[3];
            int ok = 1;
            for (int a = 0; a < 3 && ok; a++) {
                y[a] = image_coord(dom, a, sh[a], x[3 * i + a]);
                if (sh[a] != 0 && !(y[a] > dom->lo[a] - margin && y[a] < dom->hi[a] + margin)) ok = 0;
                /* a centre on a wall plane is its own mirror image across it */
                if (sh[a] != 0 && !dom->periodic[a] && on_plane(dom, a, x[3 * i + a]) &&
                    fabs(y[a] - x[3 * i + a]) <= 1e-12 * (dom->hi[a] - dom->lo[a]))
                    ok = 0;
            }
            if (!ok) continue;
            if (np == cap) {
                cap *= 2;
                X = realloc(X, 3 * cap * sizeof *X);
                R = realloc(R, cap * sizeof *R);
                ID = realloc(ID, cap * sizeof *ID);
                IMG = realloc(IMG, 3 * cap);
            }
            memcpy(X + 3 * np, y, sizeof y);
            R[np] = r[i];
            ID[np] = i;
            for (int a = 0; a < 3; a++) IMG[3 * np + a] = (signed char)sh[a];
            np++;
        }
    }
    t->npts = (int)np;
    t->xm = malloc(3 * np * sizeof *t->xm);
    t->xo = malloc(3 * np * sizeof *t->xo);
    for (size_t p = 0; p < np; p++)
        for (int a = 0; a < 3; a++) {
            const int s = IMG[3 * p + a];
            t->xm[3 * p + a] = (s != 0 && !dom->periodic[a]) ? -1.0 : 1.0;
            t->xo[3 * p + a] = s == 0 ? 0.0 : dom->periodic[a] ? s * (dom->hi[a] - dom->lo[a]) : s < 0 ? 2.0 * dom->lo[a] : 2.0 * dom->hi[a];
        }
    t->x = X;
    t->r = R;
    t->id = ID;
    t->img = IMG;

    const int rc = kind == PN_TRI_CGAL ? tets_cgal(t, err, nerr) : tets_qhull(dom, t, margin, err, nerr);
    if (rc == 0) pn_mark_clear(dom, t);
    return rc;
}

