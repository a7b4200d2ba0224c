/* porenet_packings.h — fixed packings for the pore-network tests: the simple
 * cubic array, a seeded random packing relaxed in a box with walls, and the
 * reference prototype's packings read from tests/data/porenet/. */
#ifndef IBMDEM_PORENET_PACKINGS_H
#define IBMDEM_PORENET_PACKINGS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "porenet.h"

/* Deterministic generator (xorshift64*): the same packing on every machine. */
static inline double pk_rand(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

/* Simple cubic array of m³ touching spheres (radius r, spacing 2) in [0, 2m]³,
 * centres at 1, 3, ..., each moved by a uniform jitter of amplitude `jit`. */
static inline int pk_cubic(int m, double r, double jit, unsigned long long seed, double *x, double *rad)
{
    int n = 0;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++)
            for (int k = 0; k < m; k++, n++) {
                x[3 * n] = 2 * i + 1 + jit * (2 * pk_rand(&seed) - 1);
                x[3 * n + 1] = 2 * j + 1 + jit * (2 * pk_rand(&seed) - 1);
                x[3 * n + 2] = 2 * k + 1 + jit * (2 * pk_rand(&seed) - 1);
                rad[n] = r;
            }
    return n;
}

/* n spheres of radii uniform in [1 − pd, 1 + pd] at random positions in the
 * box [0, L]³ of solid fraction phi, overlaps (with each other and with the
 * walls, i.e. centre closer than r to a face) relaxed by pushing the pairs
 * apart until the largest overlap is below 1e-4 r — the prototype's
 * procedure (catalano_pfv_proto.py make_packing) with walls instead of
 * periodic faces.  Returns L. */
static inline double pk_random_walled(int n, double phi, double pd, unsigned long long seed, double *x, double *r)
{
    double vs = 0;
    for (int i = 0; i < n; i++) {
        r[i] = 1 - pd + 2 * pd * pk_rand(&seed);
        vs += 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];
    }
    double L = cbrt(vs / phi);
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) x[3 * i + a] = r[i] + (L - 2 * r[i]) * pk_rand(&seed);
    double *dx = malloc(3 * (size_t)n * sizeof *dx);
    for (int it = 0; it < 20000; it++) {
        memset(dx, 0, 3 * (size_t)n * sizeof *dx);
        double worst = 0;
        for (int i = 0; i < n; i++)
            for (int j = i + 1; j < n; j++) {
                double d[3], dd = 0;
                for (int a = 0; a < 3; a++) d[a] = x[3 * j + a] - x[3 * i + a], dd += d[a] * d[a];
                double s = r[i] + r[j];
                if (dd >= s * s) continue;
                double dist = sqrt(dd), ov = s - dist;
                worst = fmax(worst, ov / fmin(r[i], r[j]));
                for (int a = 0; a < 3; a++) {
                    double f = 0.25 * ov * d[a] / dist;
                    dx[3 * i + a] -= f;
                    dx[3 * j + a] += f;
                }
            }
        for (int i = 0; i < n; i++)
            for (int a = 0; a < 3; a++) {
                double lo = x[3 * i + a] - r[i], hi = L - x[3 * i + a] - r[i];
                if (lo < 0) dx[3 * i + a] -= lo, worst = fmax(worst, -lo / r[i]);
                if (hi < 0) dx[3 * i + a] += hi, worst = fmax(worst, -hi / r[i]);
            }
        if (worst < 1e-4) break;
        for (int i = 0; i < 3 * n; i++) x[i] += dx[i];
    }
    free(dx);
    return L;
}

/* A packing of tests/data/porenet/ (comment lines: prototype kappa and L).
 * Returns the count; *kappa_proto = the prototype's κ_z/d² on it. */
static inline int pk_read_proto(const char *path, int nmax, double *x, double *r, double *L, double *kappa_proto)
{
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    char line[512];
    int n = 0;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') {
            char *p = strstr(line, "kappa_z/d^2 = ");
            if (p) *kappa_proto = atof(p + 14);
            p = strstr(line, "L = ");
            if (p) *L = atof(p + 4);
            continue;
        }
        if (n < nmax && sscanf(line, "%lf %lf %lf %lf", x + 3 * n, x + 3 * n + 1, x + 3 * n + 2, r + n) == 4) n++;
    }
    fclose(f);
    return n;
}

/* A domain [0, L]³: periodic axes where per[a], walls (slip) elsewhere. */
static inline pn_domain_t pk_domain(double L, int px, int py, int pz)
{
    pn_domain_t d;
    memset(&d, 0, sizeof d);
    int per[3] = {px, py, pz};
    for (int a = 0; a < 3; a++) {
        d.lo[a] = 0;
        d.hi[a] = L;
        d.periodic[a] = per[a];
    }
    return d;
}

#endif
