/* dem_bed.c — the rough bed of fixed half-grains under a granular flow: a
 * random (sequential insertion), dense (random, relaxed) or hexagonal layer of
 * fixed grains with centres on a plane, and the freezing of the grains below a
 * height after a packing preparation. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dem_private.h"
#include "util.h"

/* A disc centre back into the plane: periodic wrap, or inside the walls. */
static void bed_wrap(const dem_t *d, int a1, int a2, double *p1, double *p2, double r)
{
    const double L1 = d->L[a1], L2 = d->L[a2];
    if (d->periodic[a1]) *p1 = d->lo[a1] + fmod(fmod(*p1 - d->lo[a1], L1) + L1, L1);
    else *p1 = fmin(fmax(*p1, d->lo[a1] + r), d->hi[a1] - r);
    if (d->periodic[a2]) *p2 = d->lo[a2] + fmod(fmod(*p2 - d->lo[a2], L2) + L2, L2);
    else *p2 = fmin(fmax(*p2, d->lo[a2] + r), d->hi[a2] - r);
}

/* Dense random monolayer: discs drawn until they cover `cover` of the plane,
 * dropped at random positions, then pushed apart (each overlapping pair moves
 * apart by its overlap, half each, pair after pair) until no two overlap by
 * more than 1e-9 of a radius.  Polydisperse discs jam near a coverage of 0.84;
 * the relaxation gives up (bad input) when it cannot remove the overlaps. */
static int bed_dense(const dem_t *d, int a1, int a2, double R, double poly, double cover, uint64_t seed,
                     double **c1o, double **c2o, double **cro, double *covered)
{
    const double L1 = d->L[a1], L2 = d->L[a2], area = L1 * L2;
    dem_rng_t g;
    dem_rng_seed(&g, seed);
    int nb = 0, cap = 64;
    double *c1 = malloc(cap * sizeof(double)), *c2 = malloc(cap * sizeof(double)), *cr = malloc(cap * sizeof(double));
    double cov = 0, rmax = 0;
    while (cov < cover * area) {
        if (nb == cap) {
            cap *= 2;
            c1 = realloc(c1, cap * sizeof(double));
            c2 = realloc(c2, cap * sizeof(double));
            cr = realloc(cr, cap * sizeof(double));
        }
        cr[nb] = R * (1 + poly * (2 * dem_rng_uniform(&g) - 1));
        c1[nb] = d->lo[a1] + dem_rng_uniform(&g) * L1;
        c2[nb] = d->lo[a2] + dem_rng_uniform(&g) * L2;
        cov += M_PI * cr[nb] * cr[nb];
        rmax = fmax(rmax, cr[nb]);
        nb++;
    }
    /* cells of at least the largest diameter; every cell when a direction has fewer than 3 */
    const int m1 = (int)fmax(1.0, floor(L1 / (2 * rmax))), m2 = (int)fmax(1.0, floor(L2 / (2 * rmax)));
    int *head = malloc((size_t)m1 * m2 * sizeof(int)), *next = malloc(nb * sizeof(int));
    double worst = HUGE_VAL;
    for (int sweep = 0; sweep < 50000 && worst > 1e-9 * R; sweep++) {
        for (long c = 0; c < (long)m1 * m2; c++) head[c] = -1;
        for (int k = 0; k < nb; k++) {
            const int q1 = (int)fmin(m1 - 1, floor((c1[k] - d->lo[a1]) / L1 * m1)),
                      q2 = (int)fmin(m2 - 1, floor((c2[k] - d->lo[a2]) / L2 * m2));
            next[k] = head[(long)q2 * m1 + q1];
            head[(long)q2 * m1 + q1] = k;
        }
        worst = 0;
        for (int k = 0; k < nb; k++) {
            const int q1 = (int)fmin(m1 - 1, floor((c1[k] - d->lo[a1]) / L1 * m1)),
                      q2 = (int)fmin(m2 - 1, floor((c2[k] - d->lo[a2]) / L2 * m2));
            for (int o2 = m2 < 3 ? 0 : -1; o2 <= (m2 < 3 ? m2 - 1 : 1); o2++)
                for (int o1 = m1 < 3 ? 0 : -1; o1 <= (m1 < 3 ? m1 - 1 : 1); o1++) {
                    int k1 = m1 < 3 ? o1 : q1 + o1, k2 = m2 < 3 ? o2 : q2 + o2;
                    if (k1 < 0 || k1 >= m1) {
                        if (!d->periodic[a1]) continue;
                        k1 = (k1 + m1) % m1;
                    }
                    if (k2 < 0 || k2 >= m2) {
                        if (!d->periodic[a2]) continue;
                        k2 = (k2 + m2) % m2;
                    }
                    for (int j = head[(long)k2 * m1 + k1]; j >= 0; j = next[j]) {
                        if (j <= k) continue;
                        double e1 = c1[k] - c1[j], e2 = c2[k] - c2[j];
                        if (d->periodic[a1]) e1 -= L1 * round(e1 / L1);
                        if (d->periodic[a2]) e2 -= L2 * round(e2 / L2);
                        const double dist = sqrt(e1 * e1 + e2 * e2), ov = cr[k] + cr[j] - dist;
                        if (ov <= 0) continue;
                        worst = fmax(worst, ov);
                        /* coincident centres: apart along a1 (the lower index moves down) */
                        const double n1 = dist > 0 ? e1 / dist : (k < j ? -1.0 : 1.0), n2 = dist > 0 ? e2 / dist : 0.0;
                        /* each a little more than half the overlap, at once (Gauss-Seidel) */
                        const double h = 0.5 * (ov + 1e-12 * R);
                        c1[k] += h * n1;
                        c2[k] += h * n2;
                        c1[j] -= h * n1;
                        c2[j] -= h * n2;
                        bed_wrap(d, a1, a2, c1 + k, c2 + k, cr[k]);
                        bed_wrap(d, a1, a2, c1 + j, c2 + j, cr[j]);
                    }
                }
        }
    }
    free(head);
    free(next);
    *c1o = c1;
    *c2o = c2;
    *cro = cr;
    *covered = cov;
    return worst > 1e-9 * R ? -1 : nb;
}

/* The discs of a bed as fixed grains with centres on the plane; the arrays are freed. */
static void add_discs(dem_t *d, int ax, int a1, int a2, double pos, double rho, int nb, double *c1, double *c2,
                      double *cr)
{
    const double v0[3] = {0, 0, 0};
    for (int k = 0; k < nb; k++) {
        double x[3];
        x[ax] = pos;
        x[a1] = c1[k];
        x[a2] = c2[k];
        dem_add_particle(d, x, v0, cr[k], rho, 1);
    }
    free(c1);
    free(c2);
    free(cr);
}

/* 2-D random, dense or hexagonal layer of fixed grains with centres on a plane. */
void dem_config_bed(dem_t *d, cfg_t *cfg)
{
    const int type = cfg_enum(cfg, "bed", "type");
    if (type == 0) return;
    const int ax = cfg_enum(cfg, "bed", "axis");
    const int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
    const double pos = cfg_double(cfg, "bed", "position");
    const double R = cfg_double(cfg, "bed", "radius");
    const double poly = cfg_double(cfg, "bed", "polydispersity");
    const double rho = cfg_double(cfg, "particles", "density");
    if (pos < d->lo[ax] || pos > d->hi[ax]) cfg_fail(cfg, "bed", "position", "outside the domain");
    const double L1 = d->L[a1], L2 = d->L[a2];
    const double v0[3] = {0, 0, 0};
    /* grains no machine holds (the particle arrays take about 280 bytes a grain) */
    const double expect = type == 2 ? floor(L1 / (2 * R) + 1e-9) * floor(L2 / (sqrt(3.0) * R) + 1e-9)
                                    : cfg_double(cfg, "bed", "coverage") * L1 * L2 / (M_PI * R * R);
    if (expect * 280.0 > physical_memory_bytes())
        cfg_fail(cfg, "bed", "radius", "a bed of about %.3g grains needs more than the %.3g GB of memory of this machine",
                 expect, physical_memory_bytes() / 1e9);
    if (type == 2) {
        /* hexagonal: rows along a1 with spacing 2R, rows 2R sin 60° apart */
        const int n1 = (int)floor(L1 / (2 * R) + 1e-9);
        int n2 = (int)floor(L2 / (sqrt(3.0) * R) + 1e-9);
        /* across a periodic direction an odd count puts two unshifted rows side by side at the
         * seam: they would overlap closer than 2R apart, so the count becomes even */
        if (d->periodic[a2] && n2 > 1 && n2 % 2 && L2 / n2 < 2 * R) n2--;
        if (n1 < 1 || n2 < 1) cfg_fail(cfg, "bed", "radius", "larger than the bed plane");
        const double s1 = L1 / n1, s2 = L2 / n2;
        for (int j = 0; j < n2; j++)
            for (int i = 0; i < n1; i++) {
                double x[3];
                x[ax] = pos;
                x[a1] = d->lo[a1] + (i + 0.5 + 0.5 * (j % 2)) * s1;
                x[a2] = d->lo[a2] + (j + 0.5) * s2;
                if (x[a1] >= d->hi[a1]) {
                    if (!d->periodic[a1]) continue;
                    x[a1] -= L1;
                }
                dem_add_particle(d, x, v0, R, rho, 1);
            }
        msg("dem: hexagonal bed of %d x %d fixed grains (R = %g m) at %c = %g m\n", n1, n2, R, "xyz"[ax], pos);
        return;
    }
    if (type == 3) {
        double *c1, *c2, *cr, covered;
        const int nb = bed_dense(d, a1, a2, R, poly, cfg_double(cfg, "bed", "coverage"),
                                 (uint64_t)cfg_int(cfg, "bed", "seed") + 7777, &c1, &c2, &cr, &covered);
        if (nb < 0)
            cfg_fail(cfg, "bed", "coverage", "the discs of a dense bed at coverage %.3f could not be pushed apart "
                     "(a disordered monolayer jams near 0.82, earlier in a small periodic plane)", cfg_double(cfg, "bed", "coverage"));
        add_discs(d, ax, a1, a2, pos, rho, nb, c1, c2, cr);
        msg("dem: dense random bed of %d fixed grains (coverage %.3f) at %c = %g m\n", nb, covered / (L1 * L2),
            "xyz"[ax], pos);
        return;
    }
    /* random sequential insertion of discs in the plane until the coverage */
    const double cover = cfg_double(cfg, "bed", "coverage");
    dem_rng_t g;
    dem_rng_seed(&g, (uint64_t)cfg_int(cfg, "bed", "seed") + 7777);
    const double area = L1 * L2;
    double covered = 0;
    int nb = 0, maxcap = 1024;
    double *c1 = malloc(maxcap * sizeof(double)), *c2 = malloc(maxcap * sizeof(double)),
           *cr = malloc(maxcap * sizeof(double));
    /* a grid of cells of at least the largest diameter: a disc can only meet
     * the discs of its own and the 8 neighbouring cells (every cell when a
     * direction has fewer than 3) */
    const int m1 = (int)fmax(1.0, fmin(floor(L1 / (2 * R * (1 + poly))), fmax(1.0, sqrt(expect)))),
              m2 = (int)fmax(1.0, fmin(floor(L2 / (2 * R * (1 + poly))), fmax(1.0, sqrt(expect))));
    int *head = malloc((size_t)m1 * m2 * sizeof(int)), *next = malloc(maxcap * sizeof(int));
    for (long c = 0; c < (long)m1 * m2; c++) head[c] = -1;
    long fails = 0;
    while (covered < cover * area) {
        const double r = R * (1 + poly * (2 * dem_rng_uniform(&g) - 1));
        int placed = 0;
        for (int att = 0; att < 20000 && !placed; att++) {
            double p1 = d->lo[a1] + dem_rng_uniform(&g) * L1, p2 = d->lo[a2] + dem_rng_uniform(&g) * L2;
            if (!d->periodic[a1] && (p1 < d->lo[a1] + r || p1 > d->hi[a1] - r)) continue;
            if (!d->periodic[a2] && (p2 < d->lo[a2] + r || p2 > d->hi[a2] - r)) continue;
            const int q1 = (int)fmin(m1 - 1, floor((p1 - d->lo[a1]) / L1 * m1)),
                      q2 = (int)fmin(m2 - 1, floor((p2 - d->lo[a2]) / L2 * m2));
            int ok = 1;
            for (int o2 = m2 < 3 ? 0 : -1; o2 <= (m2 < 3 ? m2 - 1 : 1) && ok; o2++)
                for (int o1 = m1 < 3 ? 0 : -1; o1 <= (m1 < 3 ? m1 - 1 : 1) && ok; o1++) {
                    int k1 = m1 < 3 ? o1 : q1 + o1, k2 = m2 < 3 ? o2 : q2 + o2;
                    if (k1 < 0 || k1 >= m1) {
                        if (!d->periodic[a1]) continue;
                        k1 = (k1 + m1) % m1;
                    }
                    if (k2 < 0 || k2 >= m2) {
                        if (!d->periodic[a2]) continue;
                        k2 = (k2 + m2) % m2;
                    }
                    for (int k = head[(long)k2 * m1 + k1]; k >= 0 && ok; k = next[k]) {
                        double e1 = p1 - c1[k], e2 = p2 - c2[k];
                        if (d->periodic[a1]) e1 -= L1 * round(e1 / L1);
                        if (d->periodic[a2]) e2 -= L2 * round(e2 / L2);
                        const double rr = r + cr[k];
                        if (e1 * e1 + e2 * e2 < rr * rr) ok = 0;
                    }
                }
            if (!ok) continue;
            if (nb == maxcap) {
                maxcap *= 2;
                c1 = realloc(c1, maxcap * sizeof(double));
                c2 = realloc(c2, maxcap * sizeof(double));
                cr = realloc(cr, maxcap * sizeof(double));
                next = realloc(next, maxcap * sizeof(int));
            }
            c1[nb] = p1;
            c2[nb] = p2;
            cr[nb] = r;
            next[nb] = head[(long)q2 * m1 + q1];
            head[(long)q2 * m1 + q1] = nb;
            nb++;
            covered += M_PI * r * r;
            placed = 1;
        }
        if (!placed && ++fails > 5)
            cfg_fail(cfg, "bed", "coverage", "random insertion jammed at coverage %.3f (asked %.3f)", covered / area,
                     cover);
    }
    add_discs(d, ax, a1, a2, pos, rho, nb, c1, c2, cr);
    free(head);
    free(next);
    msg("dem: random bed of %d fixed grains (coverage %.3f) at %c = %g m\n", nb, covered / area, "xyz"[ax], pos);
}

void dem_freeze_below(dem_t *d, cfg_t *cfg)
{
    const double h = cfg_double(cfg, "bed", "freeze_below");
    if (h <= -1e299) return;
    const int ax = cfg_enum(cfg, "bed", "axis");
    dem_sync_velocities(d);
    int nf = 0;
    for (int i = 0; i < d->n; i++) {
        if (d->fixed[i] || d->x[3 * i + ax] >= h) continue;
        d->fixed[i] = 1;
        d->invm[i] = d->invI[i] = 0.0;
        for (int a = 0; a < 3; a++) d->v[3 * i + a] = d->w[3 * i + a] = 0.0;
        nf++;
    }
    d->ready = 0;
    msg("dem: %d particles below %c = %g m are now fixed (rough bed)\n", nf, "xyz"[ax], h);
}

