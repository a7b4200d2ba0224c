/* porenet_packing.h — the relaxed random sphere packings of the pore-network
 * benchmarks (bench_porenet.c, bench_porenet_yade.c): N spheres, radii
 * 1 ± pd, random centres in a cubic box of the solid fraction phi, relaxed
 * with a cell list until the largest overlap is below 1e-3 r (the prototype's
 * procedure, catalano_pfv.md §6).  The box is periodic, or closed by six
 * walls that no sphere crosses (walls = 1: every centre at least its radius
 * from each face, the overlaps with the faces relaxed as well).
 * Header-only: each benchmark is a single translation unit. */
#ifndef IBMDEM_BENCH_PORENET_PACKING_H
#define IBMDEM_BENCH_PORENET_PACKING_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double urand(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* Returns the box length L (box [0, L]³); x: 3n centres, r: n radii. */
static double make_packing(int n, double phi, double pd, unsigned long long seed, int walls, double *x, double *r)
{
    double vs = 0;
    for (int i = 0; i < n; i++) {
        r[i] = 1 - pd + 2 * pd * urand(&seed);
        vs += 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];
    }
    double L = cbrt(vs / phi);
    for (int i = 0; i < 3 * n; i++) x[i] = L * urand(&seed);
    int nc = (int)(L / (2 * (1 + pd)));
    double h = L / nc;
    int *head = malloc((size_t)nc * nc * nc * sizeof *head), *next = malloc((size_t)n * sizeof *next);
    double *dx = malloc(3 * (size_t)n * sizeof *dx);
    for (int it = 0; it < 3000; it++) {
        for (int c = 0; c < nc * nc * nc; c++) head[c] = -1;
        for (int i = 0; i < n; i++) {
            int ci[3];
            for (int a = 0; a < 3; a++) ci[a] = ((int)(x[3 * i + a] / h)) % nc;
            int c = (ci[0] * nc + ci[1]) * nc + ci[2];
            next[i] = head[c];
            head[c] = i;
        }
        memset(dx, 0, 3 * (size_t)n * sizeof *dx);
        double worst = 0;
        for (int i = 0; i < n; i++) {
            int ci[3];
            for (int a = 0; a < 3; a++) ci[a] = ((int)(x[3 * i + a] / h)) % nc;
            for (int s = 0; s < 27; s++) {
                int cj[3] = {(ci[0] + s % 3 - 1 + nc) % nc, (ci[1] + (s / 3) % 3 - 1 + nc) % nc,
                             (ci[2] + s / 9 - 1 + nc) % nc};
                for (int j = head[(cj[0] * nc + cj[1]) * nc + cj[2]]; j >= 0; j = next[j]) {
                    if (j <= i) continue;
                    double d[3], dd = 0;
                    for (int a = 0; a < 3; a++) {
                        d[a] = x[3 * j + a] - x[3 * i + a];
                        if (!walls) d[a] -= L * round(d[a] / L); /* walls: the wrapped cells are far, rejected below */
                        dd += d[a] * d[a];
                    }
                    double sr = r[i] + r[j];
                    if (dd >= sr * sr) continue;
                    double dist = sqrt(dd), ov = sr - dist;
                    worst = fmax(worst, ov);
                    for (int a = 0; a < 3; a++) {
                        double f = 0.25 * ov * d[a] / dist;
                        dx[3 * i + a] -= f;
                        dx[3 * j + a] += f;
                    }
                }
            }
            if (walls) /* overlap with a face: pushed back by half of it, like a pair */
                for (int a = 0; a < 3; a++) {
                    double lo = r[i] - x[3 * i + a], hi = x[3 * i + a] + r[i] - L;
                    if (lo > 0) worst = fmax(worst, lo), dx[3 * i + a] += 0.5 * lo;
                    if (hi > 0) worst = fmax(worst, hi), dx[3 * i + a] -= 0.5 * hi;
                }
        }
        if (worst < 1e-3) break;
        for (int i = 0; i < 3 * n; i++) {
            x[i] += dx[i];
            if (walls) {
                x[i] = fmin(fmax(x[i], 0.0), L * (1 - 1e-12));
            } else {
                x[i] -= L * floor(x[i] / L);
                if (x[i] >= L) x[i] = 0;
            }
        }
    }
    free(head);
    free(next);
    free(dx);
    return L;
}

#endif
