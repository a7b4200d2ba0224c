/* overlap.c — overlapping spheres in a box (overlap.h). */
#include "overlap.h"

#include <math.h>
#include <stdlib.h>

#include "util.h"

int overlap_find(const overlap_box_t *box, int n, const double *x, const double *r, const unsigned char *active,
                 double frac, int *pi, int *pj, double *depth)
{
    if (n < 2) return 0;
    double rmax = 0;
    for (int i = 0; i < n; i++) rmax = fmax(rmax, r[i]);
    /* cells of at least 2 r_max (overlapping pairs are in neighbouring
     * cells), at most 128 along a direction and about n in all */
    int nc[3] = {1, 1, 1};
    double cs[3];
    const int nd = box->dim == 2 ? 2 : 3;
    const double cap = fmax(1.0, cbrt((double)n) + 1);
    for (int a = 0; a < 3; a++) {
        if (a < nd) nc[a] = (int)fmin(fmin(floor(box->L[a] / (2 * rmax)), 128.0), cap);
        if (nc[a] < 1) nc[a] = 1;
        cs[a] = box->L[a] / nc[a];
    }
    const long ncell = (long)nc[0] * nc[1] * nc[2];
    int *head = xcalloc((size_t)ncell, sizeof(int)), *next = xcalloc((size_t)n, sizeof(int));
    int *cell = xcalloc(3 * (size_t)n, sizeof(int));
    for (long c = 0; c < ncell; c++) head[c] = -1;
    /* sphere i in its cell's list, last index first: walked in reverse below */
    for (int i = n - 1; i >= 0; i--) {
        for (int a = 0; a < 3; a++) {
            double u = a < nd ? (x[3 * i + a] - box->lo[a]) / cs[a] : 0.0;
            if (box->periodic[a]) u -= nc[a] * floor(u / nc[a]);
            int m = (int)floor(u);
            cell[3 * i + a] = m < 0 ? 0 : m >= nc[a] ? nc[a] - 1 : m;
        }
        const long c = ((long)cell[3 * i + 2] * nc[1] + cell[3 * i + 1]) * nc[0] + cell[3 * i];
        next[i] = head[c];
        head[c] = i;
    }
    int found = 0;
    for (int i = 0; i < n && !found; i++) {
        /* the neighbouring cells, each once (a direction of fewer than 3 cells: all of them) */
        int lo3[3], cnt[3];
        for (int a = 0; a < 3; a++) {
            const int wrap = box->periodic[a] && nc[a] >= 3;
            lo3[a] = nc[a] < 3 ? 0 : wrap ? cell[3 * i + a] - 1 : (cell[3 * i + a] > 0 ? cell[3 * i + a] - 1 : 0);
            const int hi = nc[a] < 3 ? nc[a] - 1 : wrap ? cell[3 * i + a] + 1
                                                        : (cell[3 * i + a] < nc[a] - 1 ? cell[3 * i + a] + 1 : nc[a] - 1);
            cnt[a] = hi - lo3[a] + 1;
        }
        int best = -1;
        double best_depth = 0;
        for (int oz = 0; oz < cnt[2]; oz++)
            for (int oy = 0; oy < cnt[1]; oy++)
                for (int ox = 0; ox < cnt[0]; ox++) {
                    const int cc[3] = {(lo3[0] + ox + nc[0]) % nc[0], (lo3[1] + oy + nc[1]) % nc[1],
                                       (lo3[2] + oz + nc[2]) % nc[2]};
                    for (int j = head[((long)cc[2] * nc[1] + cc[1]) * nc[0] + cc[0]]; j >= 0; j = next[j]) {
                        if (j <= i || (best >= 0 && j > best)) continue;
                        if (active && !active[i] && !active[j]) continue;
                        double d2 = 0;
                        for (int a = 0; a < nd; a++) {
                            double e = x[3 * j + a] - x[3 * i + a];
                            if (box->periodic[a]) e -= box->L[a] * round(e / box->L[a]);
                            d2 += e * e;
                        }
                        const double delta = r[i] + r[j] - sqrt(d2);
                        if (delta > frac * 2 * fmin(r[i], r[j])) {
                            best = j;
                            best_depth = delta;
                        }
                    }
                }
        if (best >= 0) {
            *pi = i;
            *pj = best;
            *depth = best_depth;
            found = 1;
        }
    }
    free(head);
    free(next);
    free(cell);
    return found;
}
