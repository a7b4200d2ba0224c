/* lubrication.c — Brenner (1961) normal lubrication with an effective
 * roughness η_e (Izard 2014 eq. 2.36/3.18; decision 5 of the reference notes):
 *
 *     F_lub = − 6π η_f (u_i − u_j)·n (R_i R_j/(R_i + R_j))² / (δ_n + η_e)  n,
 *
 * with R_i R_j/(R_i + R_j) → R_i against a wall, active for 0 < δ_n ≤ Δ_lub.
 * While the particles overlap (δ_n ≤ 0, where the contact law acts),
 * [lubrication] overlap chooses:
 *  - off (default; decision 5): no lubrication force;
 *  - saturated: the force keeps its δ_n = 0 value, F = −6π η_f R_eff² u_n/η_e
 *    (film thickness frozen at η_e), i.e. the contact gains the constant
 *    damping 6π η_f R²/η_e of eq. 3.26 of the seed.  The force is then
 *    continuous at δ_n = 0.
 * η_e = roughness × R and Δ_lub = range × R with R = min(R_i, R_j) (the
 * particle's radius against a wall).  Optionally the force at δ_n = Δ_lub is
 * subtracted (1/(δ + η_e) − 1/(Δ_lub + η_e)): that part of the film the grid
 * of a resolved simulation already carries.
 *
 * Integration.  With k = 6π η_f R_eff² and the approach speed u = −dδ/dt,
 * the force is F = −k u/(δ + η_e) = k d/dt ln(δ + η_e): its impulse over any
 * interval depends only on the gaps at its ends,
 *     J = −k [L(δ₁) − L(δ₀)],   L(δ) = ln(clamp(δ, 0, Δ_lub) + η_e)
 *                                       [− clamp(δ, 0, Δ_lub)/(Δ_lub + η_e)],
 * the clamp switching the force off outside (0, Δ_lub].  With overlap =
 * saturated L continues below δ = 0 along its tangent,
 *     L(δ) = ln η_e + δ (1/η_e [− 1/(Δ_lub + η_e)]),   δ < 0,
 * (C¹ at δ = 0, so the force is continuous there; unbounded below, which
 * only changes the bracket of the solve, see lub_solve).  The DEM applies
 * this impulse to the half-step velocities just before the drift, with δ₁
 * the gap the drift will produce, δ₁ = δ₀ − Δt u′ (u′ the approach speed
 * after the impulse): a scalar equation per pair,
 *     m* (u′ − u) + k [L(δ₀) − L(δ₀ − Δt u′)] = 0,
 * whose left side increases strictly with u′, so it has one root, found by
 * safeguarded Newton iterations in a bracket (lub_solve), or, when the drift
 * is small against the film, by the series of lub_drift_coef.  The scheme is
 * implicit (unconditionally stable: a pair can never be pushed through
 * δ = −η_e by its own lubrication, whatever η_e/R and Δt), and for a lone
 * pair it keeps u − (k/m*) L(δ) constant exactly, the first integral of the
 * lubrication-only motion (the stage-1 law behind eq. 3.25 of the seed).
 * Pairs sharing a particle are solved one after the other in list order
 * (a Gauss–Seidel sweep, deterministic): each solve minimises a convex
 * function of the velocities, so the sweep is dissipative and stable.  The
 * sweep first gathers the pairs it may lubricate and their constants
 * (lub_gather_pairs), then runs the chain of solves.  The
 * force reported for output is the impulse divided by Δt.
 *
 * The lists must hold every pair within Δ_lub: the skin is widened by the
 * largest Δ_lub (dem_check_scene), so the rebuild criterion of the contact
 * lists (displacement > skin/2 of the user's skin) still guarantees it.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "fluid_model.h"
#include "util.h"

typedef struct {
    double eta, range, sub; /* η_e, Δ_lub, 1/(Δ_lub + η_e) or 0 */
    int overlap;            /* overlap = saturated: L continues linearly below δ = 0 */
} lub_pair_t;

/* L(δ) of the header (continued linearly below δ = 0 with overlap = saturated). */
static inline double lub_potential(const lub_pair_t *p, double delta)
{
    if (delta < 0 && p->overlap) return log(p->eta) + delta * (1.0 / p->eta - p->sub);
    const double c = delta < 0 ? 0 : delta > p->range ? p->range : delta;
    return log(c + p->eta) - c * p->sub;
}

/* dL/dδ (0 outside the active range; its δ = 0 value below 0 with overlap = saturated). */
static inline double lub_potential_slope(const lub_pair_t *p, double delta)
{
    if (delta >= p->range || (delta <= 0 && !p->overlap)) return 0.0;
    if (delta <= 0) return 1.0 / p->eta - p->sub;
    return 1.0 / (delta + p->eta) - p->sub;
}

/* L(δ₀) − L(δ₀ − s), the change of the potential over a drift s.  Where both
 * gaps are inside (0, Δ_lub) it is ln(1 + ε) − s/(Δ_lub + η_e) with
 * ε = s/(δ₀ − s + η_e), summed as a series when |ε| < 1e-3 (the next term,
 * ε⁶/6, is below 2e-16 of the sum): the drift of a sub-step is small against
 * the gap, and the solve needs no logarithm.  Elsewhere from L itself, with
 * L(δ₀) computed once (*L0, NAN until needed). */
static inline double lub_delta_potential(const lub_pair_t *p, double gap0, double s, double *L0)
{
    const double d1 = gap0 - s;
    if (gap0 > 0 && gap0 < p->range && d1 > 0 && d1 < p->range) {
        const double e = s / (d1 + p->eta);
        const double l = fabs(e) < 1e-3 ? e * (1.0 - e * (0.5 - e * (1.0 / 3.0 - e * (0.25 - 0.2 * e)))) : log1p(e);
        return l - s * p->sub;
    }
    if (isnan(*L0)) *L0 = lub_potential(p, gap0);
    return *L0 - lub_potential(p, d1);
}

/* The root of lub_solve when both gaps stay inside (0, Δ_lub) and the drift
 * is small against the film, |Δt u|/(δ₀ + η_e) < 1e-3 (nearly every pair of a
 * sub-cycled bed).  With a = δ₀ + η_e, z = Δt u′/a and H(z) = −ln(1 − z) − z,
 * g of lub_solve reads
 *     g = M u′ − m u + k H(z),   M = m + k Δt (1/a − 1/(Δ_lub + η_e) [subtract]),
 * so z = z₀ − β H(z) with z₀ = γ u, γ = Δt m/(M a) (z₀ the linearly implicit
 * step) and β = k Δt/(M a).  Its series reversion
 *     z = z₀ + Σ_{n=2..7} c_n(β) z₀ⁿ,   c₂ = −β/2,  c₃ = β²/2 − β/3,
 *     c₄ = −5β³/8 + 5β²/6 − β/4,  c₅ = 7β⁴/8 − 7β³/4 + 13β²/12 − β/5,
 *     c₆ = −21β⁵/16 + 7β⁴/2 − 119β³/36 + 77β²/60 − β/6,
 *     c₇ = 33β⁶/16 − 55β⁵/8 + 35β⁴/4 − 236β³/45 + 29β²/20 − β/7,
 * is left at z₀⁷: with |z₀| and β|z₀| below 1e-3 the rest is below 1e-20 of
 * z.  The change of the approach speed is then a polynomial in u,
 *     u′ − u = u (d₀ + d₁ u + … + d₆ u⁶),
 *     d₀ = −k Δt (1/a [− 1/(Δ_lub + η_e)])/M,  d_{n−1} = (m/M) c_n γ^{n−1},
 * whose coefficients do not depend on u (lub_drift_coef): the Gauss–Seidel
 * sweep computes them before it starts and each of its solves is a few
 * multiplications (lub_drift_change). */
typedef struct {
    double ia, zmax; /* 1/a (0: δ₀ outside (0, Δ_lub)); the largest |Δt u/a| of the series */
    double d[7];     /* d₀ … d₆ */
} lub_drift_t;

/* The coefficients d₀ … d₆ times `scale` (1, or m* for the impulse) of a
 * pair of mass m, k Δt = kd, 1/a = ia, 1/(Δ_lub + η_e) or 0 = sub; returns
 * the bound of |Δt u/a| below which the series holds, 1e-3/max(1, β).
 * Without branches (the sweep's constants are computed by a vectorised loop). */
static inline double lub_series(double m, double kd, double ia, double sub, double dt, double scale, double d[7])
{
    const double iM = 1.0 / (m + kd * (ia - sub));
    const double b = kd * ia * iM, g = dt * m * iM * ia, mM = scale * m * iM;
    const double c2 = -0.5 * b, c3 = b * (0.5 * b - 1.0 / 3.0), c4 = b * (b * (5.0 / 6.0 - 0.625 * b) - 0.25);
    const double c5 = b * (b * (b * (0.875 * b - 1.75) + 13.0 / 12.0) - 0.2);
    const double c6 = b * (b * (b * (b * (3.5 - 1.3125 * b) - 119.0 / 36.0) + 77.0 / 60.0) - 1.0 / 6.0);
    const double c7 = b * (b * (b * (b * (b * (2.0625 * b - 6.875) + 8.75) - 236.0 / 45.0) + 29.0 / 20.0) - 1.0 / 7.0);
    const double g2 = g * g, g3 = g2 * g, g4 = g2 * g2;
    d[0] = -scale * kd * (ia - sub) * iM;
    d[1] = mM * c2 * g;
    d[2] = mM * c3 * g2;
    d[3] = mM * c4 * g3;
    d[4] = mM * c5 * g4;
    d[5] = mM * c6 * g4 * g;
    d[6] = mM * c7 * g3 * g3;
    return 1e-3 / (b > 1.0 ? b : 1.0);
}

/* u (d₀ + d₁ u + … + d₆ u⁶), in a short chain of operations. */
static inline double lub_series_eval(double u, double d0, double d1, double d2, double d3, double d4, double d5,
                                     double d6)
{
    const double u2 = u * u;
    return u * ((d0 + d1 * u) + u2 * (d2 + d3 * u) + u2 * u2 * ((d4 + d5 * u) + u2 * d6));
}

static inline void lub_drift_coef(const lub_pair_t *p, double m, double k, double dt, double gap0, lub_drift_t *c)
{
    if (!(gap0 > 0 && gap0 < p->range)) {
        c->ia = 0.0;
        return;
    }
    c->ia = 1.0 / (gap0 + p->eta);
    c->zmax = lub_series(m, k * dt, c->ia, p->sub, dt, 1.0, c->d);
}

/* 1 and (*du) the change of the approach speed u′ − u by the series above,
 * or 0 when its conditions do not hold (the general solve of lub_solve);
 * (d₀ … d₆ may be the d's times a constant: *du is then scaled by it). */
static inline int lub_drift_change(const lub_drift_t *c, const lub_pair_t *p, double dt, double gap0, double u,
                                   double *du)
{
    const double gap1 = gap0 - dt * u;
    if (!(c->ia > 0 && gap1 > 0 && gap1 < p->range && fabs(dt * u * c->ia) < c->zmax)) return 0;
    const double *d = c->d;
    *du = lub_series_eval(u, d[0], d[1], d[2], d[3], d[4], d[5], d[6]);
    return 1;
}

/* Root u′ of g(u′) = m (u′ − u) + k [L(δ₀) − L(δ₀ − dt u′)] = 0.
 *
 * Bracket.  g′ = m + k dt L′ ≥ m > 0, g(0) = −m u and g(u) has the sign of
 * u (L increases), so the root lies between 0 and u: the impulse never
 * reverses the approach (a finite bracket also with overlap = saturated,
 * whose L is unbounded below).  Newton starts from the linearly implicit step (the
 * damping −k L′(δ₀) u′ over dt), the root itself when the gap changes little
 * over the step, and is safeguarded by bisection; tolerance 1e-14 |u|. */
static double lub_solve(const lub_pair_t *p, double m, double k, double dt, double gap0, double u)
{
    if (u == 0) return 0.0;
    double x;
    lub_drift_t c;
    lub_drift_coef(p, m, k, dt, gap0, &c);
    if (lub_drift_change(&c, p, dt, gap0, u, &x)) {
        x += u;
        return u > 0 ? fmin(fmax(x, 0.0), u) : fmin(fmax(x, u), 0.0);
    }
    double L0 = NAN;
    double lo = fmin(u, 0.0), hi = fmax(u, 0.0);
    const double scale = fabs(u);
    x = u * m / (m + k * dt * lub_potential_slope(p, gap0));
    if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
    for (int it = 0; it < 200; it++) {
        const double g = m * (x - u) + k * lub_delta_potential(p, gap0, dt * x, &L0);
        if (g == 0) return x;
        if (g > 0)
            hi = x;
        else
            lo = x;
        const double dg = m + k * dt * lub_potential_slope(p, gap0 - dt * x);
        const double step = g / dg;
        /* converged: the Newton step is below 1e-14 |u| (it lands on the bracket's end when the
         * root is that close to it, and bisection would halve the last ulps for nothing) */
        if (fabs(step) <= 1e-14 * scale) return fmin(fmax(x - step, lo), hi);
        double xn = x - step;
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        if (hi - lo <= 1e-14 * scale) return xn;
        x = xn;
    }
    return x;
}

/* The resolved fluid's grid carries the film down to cutoff × h (model =
 * correction with a grid): the lubrication adds the rest, each term less its
 * value at the cut-off. */
static inline int lub_complements_grid(const dem_lub_t *L) { return L->model == LUB_CORRECTION && L->h > 0; }

/* Δ_lub of a particle of radius R (the smaller of a pair). */
static inline double lub_pair_range(const dem_lub_t *L, double R)
{
    return lub_complements_grid(L) ? L->cutoff * L->h : L->range * R;
}

static inline void lub_params(const dem_lub_t *L, double R, lub_pair_t *p)
{
    p->eta = L->roughness * R;
    p->range = lub_pair_range(L, R);
    p->sub = L->subtract || lub_complements_grid(L) ? 1.0 / (p->range + p->eta) : 0.0;
    p->overlap = L->overlap;
}

/* Cut-off of the tangential terms of a particle of radius R. */
static inline double lub_tangential_range(const dem_lub_t *L, double R)
{
    return lub_complements_grid(L) ? L->tcutoff * L->h : L->range * R;
}

double dem_lub_reach(const dem_lub_t *L, double rmax)
{
    if (!L->on) return 0.0;
    lub_pair_t p;
    lub_params(L, rmax, &p);
    return L->tangential ? fmax(p.range, lub_tangential_range(L, rmax)) : p.range;
}

/* Time for a lone pair to close its gap from gap0 to 0, at approach speed u0
 * and a constant approach acceleration a (gravity and the held external
 * forces), under the lubrication of the header: the motion keeps
 *     u − (k/m) L(δ) = u0 − (k/m) L(gap0) + a t
 * (the first integral of the header with a added), so t(δ) obeys
 *     dt/ds = (δ + η_e)/u,   s = ln(δ + η_e) decreasing,  u = w0 + a t + (k/m) L(δ),
 * integrated by RK4 in s, which resolves the logarithmic slow-down of the last
 * η_e's: 48 steps from gap0 down to Δ_lub (L constant there) and 48 from Δ_lub
 * (or gap0) down to 0.  INFINITY when the approach stops (u ≤ 0) before the
 * gap closes: the pair does not touch.  Used to align the fluid steps with
 * the contacts (dem_time_to_contact): the constant-velocity estimate gap0/u0
 * is early by the whole slow-down, up to several fluid steps at low St. */
static double lub_approach_time(const lub_pair_t *p, double m, double k, double gap0, double u0, double a)
{
    const double w0 = u0 - k / m * lub_potential(p, gap0), eta = p->eta;
    const double ends[3] = {gap0, gap0 > p->range ? p->range : gap0, 0.0};
    double t = 0.0;
    for (int seg = 0; seg < 2; seg++) {
        if (ends[seg] <= ends[seg + 1]) continue;
        const int N = 48;
        const double s0 = log(ends[seg] + eta), h = (s0 - log(ends[seg + 1] + eta)) / N;
        /* dt/dσ with σ = s0 − s increasing; u at the gap e^s − η_e */
        double s = s0;
        for (int q = 0; q < N; q++) {
            double kk[4], tt = t;
            for (int r = 0; r < 4; r++) {
                const double sr = s - (r == 0 ? 0.0 : r == 3 ? h : 0.5 * h);
                const double delta = fmax(exp(sr) - eta, 0.0);
                const double u = w0 + a * tt + k / m * lub_potential(p, delta);
                if (!(u > 0)) return INFINITY;
                kk[r] = (delta + eta) / u;
                tt = t + (r == 2 ? h : 0.5 * h) * kk[r];
            }
            t += h / 6.0 * (kk[0] + 2.0 * kk[1] + 2.0 * kk[2] + kk[3]);
            s -= h;
        }
    }
    return t;
}

double dem_lub_approach_time(const dem_t *d, double R, double reff, double m, double gap0, double u0, double a)
{
    lub_pair_t p;
    lub_params(&d->lub, R, &p);
    return lub_approach_time(&p, m, 6.0 * M_PI * d->lub.viscosity * reff * reff, gap0, u0, a);
}

static void lub_tangential_impulses(dem_t *d, double dt);

/* The entries of the lists that the sweep may lubricate, as arrays (one
 * block, d->lub_work): their indices, and at the start of the sweep their
 * geometry and the constants of their solves. */
enum { LW_NX, LW_NY, LW_NZ, LW_GAP, LW_M, LW_K, LW_ETA, LW_RANGE, LW_SUB, LW_IA, LW_ZMAX, LW_D0, LW_NA = LW_D0 + 7 };
typedef struct lub_work {
    int *i, *j;
    double *a[LW_NA];
} lub_work_t;

void dem_lubrication_free(dem_t *d)
{
    if (!d->lub_work) return;
    free(d->lub_work->i);
    free(d->lub_work->j);
    free(d->lub_work->a[0]);
    free(d->lub_work);
    d->lub_work = NULL;
    d->lub_work_cap = 0;
}

double dem_lubrication_work_bytes(void) { return 2 * sizeof(int) + LW_NA * sizeof(double); }

/* The work space with room for `need` entries, the first `keep` kept
 * (grown by doubling: it holds the selected entries, a few per particle). */
static lub_work_t *lub_work(dem_t *d, long need, long keep)
{
    if (d->lub_work && need <= d->lub_work_cap) return d->lub_work;
    long cap = d->lub_work_cap > 64 ? d->lub_work_cap : 64;
    while (cap < need) cap *= 2;
    lub_work_t *o = d->lub_work, *w = xcalloc(1, sizeof(lub_work_t));
    w->i = xcalloc((size_t)cap, sizeof(int));
    w->j = xcalloc((size_t)cap, sizeof(int));
    w->a[0] = xcalloc((size_t)cap * LW_NA, sizeof(double));
    for (int q = 1; q < LW_NA; q++) w->a[q] = w->a[0] + (size_t)q * cap;
    if (o) {
        memcpy(w->i, o->i, (size_t)keep * sizeof(int));
        memcpy(w->j, o->j, (size_t)keep * sizeof(int));
        for (int q = 0; q < LW_NA; q++) memcpy(w->a[q], o->a[q], (size_t)keep * sizeof(double));
        dem_lubrication_free(d);
    }
    d->lub_work = w;
    d->lub_work_cap = cap;
    return w;
}

/* The second pass of lub_gather_pairs: from the centre-to-centre vectors,
 * R_i, R_j and 1/m_i + 1/m_j (in nx.., eta, range, m) the normals, gaps and
 * constants (lub_params, lub_drift_coef with the d's times m*, the sweep's
 * impulse m* (u′ − u)) of np entries, without branches. */
static void lub_coef_pass(const dem_lub_t *L, double dt, long np, double *const *A)
{
    double *restrict nx = A[LW_NX], *restrict ny = A[LW_NY], *restrict nz = A[LW_NZ], *restrict gap = A[LW_GAP];
    double *restrict mm = A[LW_M], *restrict kk = A[LW_K], *restrict eta = A[LW_ETA], *restrict rng = A[LW_RANGE];
    double *restrict sub = A[LW_SUB], *restrict ia_ = A[LW_IA], *restrict zmax = A[LW_ZMAX];
    double *restrict D0 = A[LW_D0], *restrict D1 = A[LW_D0 + 1], *restrict D2 = A[LW_D0 + 2],
           *restrict D3 = A[LW_D0 + 3], *restrict D4 = A[LW_D0 + 4], *restrict D5 = A[LW_D0 + 5],
           *restrict D6 = A[LW_D0 + 6];
    const double k0 = 6.0 * M_PI * L->viscosity, rough = L->roughness;
    const int grid = lub_complements_grid(L), subtract = L->subtract || grid;
    const double lrange = L->range, grange = L->cutoff * L->h;
    /* the entries are independent (the arrays do not overlap) */
#pragma GCC ivdep
    for (long q = 0; q < np; q++) {
        const double ri = eta[q], rj = rng[q], R = ri < rj ? ri : rj;
        const double dist = sqrt(nx[q] * nx[q] + ny[q] * ny[q] + nz[q] * nz[q]), idist = 1.0 / dist;
        nx[q] *= idist;
        ny[q] *= idist;
        nz[q] *= idist;
        const double gap0 = dist - ri - rj, et = rough * R, ra = grid ? grange : lrange * R;
        const double sb = subtract ? 1.0 / (ra + et) : 0.0;
        const double m = 1.0 / mm[q], reff = ri * rj / (ri + rj), k = k0 * reff * reff;
        gap[q] = gap0;
        mm[q] = m;
        kk[q] = k;
        eta[q] = et;
        rng[q] = ra;
        sub[q] = sb;
        /* lub_drift_coef, the d's times m* (the sweep's impulse m* (u′ − u)) */
        const double ia = 1.0 / (gap0 + et);
        double dd[7];
        zmax[q] = lub_series(m, k * dt, ia, sb, dt, m, dd);
        ia_[q] = gap0 > 0 && gap0 < ra ? ia : 0.0;
        D0[q] = dd[0];
        D1[q] = dd[1];
        D2[q] = dd[2];
        D3[q] = dd[3];
        D4[q] = dd[4];
        D5[q] = dd[5];
        D6[q] = dd[6];
    }
}

/* The entries of the pair lists within reach of Δ_lub during a sweep of step
 * dt, in list order, into d->lub_work; returns their number.  A pair is
 * lubricated when one of its gaps δ₀, δ₀ − Δt u is below Δ_lub, and
 * |u| ≤ |v_i| + |v_j| at any moment of the sweep.  Each solve of the sweep
 * conserves the pair's momentum and does not reverse its approach: with the
 * fixed particles at rest it does not increase the kinetic energy E of the
 * mobile particles, so during the sweep |v_i| ≤ V = √(2E/m_min), E taken
 * before it, and a pair is out of reach when its centres are further apart
 * than R_i + R_j + Δ_lub + 2 Δt V (twice that, against round-off), or, with
 * overlap = off, closer than R_i + R_j − 2 Δt V (both gaps negative).  With a
 * moving fixed particle every entry is taken.  A first pass selects the
 * entries, a second one, without branches (vectorised), computes their
 * normals, gaps and the coefficients of lub_drift_coef. */
static long lub_gather_pairs(dem_t *d, double dt)
{
    const dem_lub_t *L = &d->lub;
    const double *restrict x = d->x, *restrict v = d->v, *restrict r = d->r, *restrict invm = d->invm;
    double e2 = 0.0, minv = 0.0, vfix2 = 0.0; /* 2E, largest 1/m, largest |v|^2 of the fixed particles */
    for (int i = 0; i < d->n; i++) {
        const double s2 = v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] + v[3 * i + 2] * v[3 * i + 2];
        if (invm[i] > 0) {
            e2 += s2 / invm[i];
            if (invm[i] > minv) minv = invm[i];
        } else if (s2 > vfix2)
            vfix2 = s2;
    }
    const double reach = vfix2 > 0 ? INFINITY : 4.0 * dt * sqrt(e2 * minv);
    lub_work_t *W = lub_work(d, 64, 0);
    long np = 0;
    for (int i = 0; i < d->nb_n_rows; i++)
        for (long e = d->nb_start[i]; e < d->nb_start[i + 1]; e++) {
            const int j = d->nb_j[e];
            if (invm[i] == 0 && invm[j] == 0) continue;
            const double ri = r[i], rj = r[j];
            const double A = ri + rj + lub_pair_range(L, ri < rj ? ri : rj) + reach;
            const double *sh = d->any_periodic ? d->shift[d->nb_img[e]] : d->shift[13];
            const double cx = x[3 * j] + sh[0] - x[3 * i], cy = x[3 * j + 1] + sh[1] - x[3 * i + 1],
                         cz = x[3 * j + 2] + sh[2] - x[3 * i + 2];
            const double c2 = cx * cx + cy * cy + cz * cz;
            if (c2 > A * A * (1.0 + 1e-9)) continue;
            /* overlapping during the whole sweep (the contacts of a bed): no lubrication with overlap = off */
            const double B = ri + rj - reach;
            if (!L->overlap && B > 0 && c2 < B * B * (1.0 - 1e-9)) continue;
            if (np == d->lub_work_cap) W = lub_work(d, np + 1, np);
            W->i[np] = i;
            W->j[np] = j;
            W->a[LW_NX][np] = cx;
            W->a[LW_NY][np] = cy;
            W->a[LW_NZ][np] = cz;
            W->a[LW_ETA][np] = ri; /* R_i, R_j and 1/m_i + 1/m_j, until the second pass */
            W->a[LW_RANGE][np] = rj;
            W->a[LW_M][np] = invm[i] + invm[j];
            np++;
        }
    lub_coef_pass(L, dt, np, W->a);
    return np;
}

void dem_lubrication_impulses(dem_t *d, double dt)
{
    const dem_lub_t *L = &d->lub;
    double *restrict v = d->v, *restrict fl = d->flub;
    const double *restrict r = d->r, *restrict invm = d->invm;
    memset(fl, 0, 3 * (size_t)d->n * sizeof(double));
    const double k0 = 6.0 * M_PI * L->viscosity;
    /* particle pairs, in list order: first the geometry of the entries that
     * can be lubricated during this sweep (it does not depend on the
     * velocities the sweep changes), then the sweep itself, a chain of
     * dependent solves that only reads the velocities */
    const long np = lub_gather_pairs(d, dt);
    const lub_work_t *W = d->lub_work;
    const int *restrict wi = W->i, *restrict wj = W->j;
    const double *const *a = (const double *const *)W->a;
    double jsum = 0.0;
    long nlub = 0;
    for (long q = 0; q < np; q++) {
        const int i = wi[q], j = wj[q];
        const double n[3] = {a[LW_NX][q], a[LW_NY][q], a[LW_NZ][q]};
        const double u = dem_pair_approach(d, i, j, n), gap0 = a[LW_GAP][q], range = a[LW_RANGE][q];
        const double gap1 = gap0 - dt * u, m = a[LW_M][q];
        if ((gap0 >= range && gap1 >= range) || (!L->overlap && gap0 <= 0 && gap1 <= 0)) continue;
        double J; /* impulse along n on i: m* times the change of the approach speed */
        const double ia = a[LW_IA][q];
        if (ia > 0 && gap1 > 0 && gap1 < range && fabs(dt * u * ia) < a[LW_ZMAX][q]) {
            const double *const *D = a + LW_D0;
            J = lub_series_eval(u, D[0][q], D[1][q], D[2][q], D[3][q], D[4][q], D[5][q], D[6][q]);
            J = u > 0 ? fmin(fmax(J, -m * u), 0.0) : fmax(fmin(J, -m * u), 0.0);
        } else {
            const lub_pair_t p = {a[LW_ETA][q], range, a[LW_SUB][q], L->overlap};
            J = m * (lub_solve(&p, m, a[LW_K][q], dt, gap0, u) - u);
        }
        jsum += fabs(J);
        nlub++;
        for (int c = 0; c < 3; c++) {
            v[3 * i + c] += J * invm[i] * n[c];
            v[3 * j + c] -= J * invm[j] * n[c];
            fl[3 * i + c] += J / dt * n[c];
            fl[3 * j + c] -= J / dt * n[c];
        }
    }
    if (d->fstat.on) {
        d->fstat.lub_norm += jsum / dt;
        d->fstat.lubricated += (double)nlub;
    }
    /* walls: R_eff → R_i, the wall moves with its velocity and has infinite mass */
    if (L->walls)
        for (int w = 0; w < d->nwall; w++) {
            const dem_wall_t *W = &d->wall[w];
            if (!W->active) continue;
            for (int q = 0; q < W->nlist; q++) {
                const int i = W->idx[q];
                if (invm[i] == 0) continue;
                double u;
                const double gap0 = dem_wall_gap(d, W, i, &u), gap1 = gap0 - dt * u;
                lub_pair_t p;
                lub_params(L, r[i], &p);
                if ((gap0 >= p.range && gap1 >= p.range) || (!p.overlap && gap0 <= 0 && gap1 <= 0)) continue;
                const double m = 1.0 / invm[i];
                const double du = lub_solve(&p, m, k0 * r[i] * r[i], dt, gap0, u) - u;
                if (d->fstat.on) {
                    d->fstat.lub_norm += m * fabs(du) / dt;
                    d->fstat.lubricated += 1.0;
                }
                /* the approach speed changes by du: v changes by −du n */
                for (int a = 0; a < 3; a++) {
                    v[3 * i + a] -= du * W->n[a];
                    fl[3 * i + a] -= m * du / dt * W->n[a];
                }
            }
        }
    if (L->tangential) lub_tangential_impulses(d, dt);
}

/* ---- tangential and rotational terms (model = correction) ----------------
 *
 * Goldman, Cox & Brenner (1967) for a sphere and a plane, and their
 * extension to two spheres of radii R_i and R_j = κR_i (Jeffrey & Onishi
 * 1984, in the form of Simeonov & Calantoni 2012), leading (logarithmic)
 * terms only, each less its value at the cut-off δ_t = tcutoff × h:
 * with ℓ = ln((δ_t + η_e)/(δ + η_e)) for 0 < δ < δ_t, n the unit normal
 * from i towards j (or the wall), u₁₂ = v_j − v_i, u_t its part normal to n,
 *
 *   F_i = 6πμR_i ℓ [a_tt u₁₂,t − R_i a_tr (ω_i + ω_j + 4ω_i/κ + 4κω_j) × n],
 *   T_i = 8πμR_i² ℓ [b_tt n × u₁₂ − R_i b_tr (ω_i + κω_j/4)_t],
 *   a_tt = 4κ(2 + κ + 2κ²)/(15(1 + κ)³),  a_tr = 2κ²/(15(1 + κ)²),
 *   b_tt = κ(4 + κ)/(10(1 + κ)²),         b_tr = 2κ/(5(1 + κ)),
 *
 * F_j = −F_i and T_j by exchanging i and j (κ → 1/κ, n → −n).  κ → ∞ is the
 * wall (at rest in rotation, moving with its velocity): a_tt = 8/15, a_tr =
 * 2/15, b_tt = 1/10, b_tr = 2/5 — GCB's coefficients.  The resistance is
 * symmetric and positive (tests/test_dem_lubrication.c checks that every
 * random motion dissipates), logarithmic only: not stiff, so these impulses
 * are explicit, applied with the normal ones before the drift, pair after
 * pair in list order; dem_lubrication_check_step bounds the step.  The
 * rotation about n is left out (Simeonov & Calantoni 2012: negligible). */

/* Impulses of the tangential terms of one sphere–sphere pair over dt. */
static void lub_tangential_pair(dem_t *d, int i, int j, const double n[3], double ell, double mu, double dt)
{
    const double ri = d->r[i], rj = d->r[j];
    double *v = d->v, *w = d->w, *fl = d->flub;
    double u12[3], un = 0;
    for (int a = 0; a < 3; a++) {
        u12[a] = v[3 * j + a] - v[3 * i + a];
        un += u12[a] * n[a];
    }
    double ut[3];
    for (int a = 0; a < 3; a++) ut[a] = u12[a] - un * n[a];
    /* force and torque on a particle p of radius rp against q of radius rq = κ rp, normal m from p to q */
    double F[3], Ti[3], Tj[3];
    for (int side = 0; side < 2; side++) {
        const int p = side ? j : i, q = side ? i : j;
        const double rp = side ? rj : ri, kap = (side ? ri : rj) / rp, s = side ? -1.0 : 1.0;
        const double att = 4 * kap * (2 + kap + 2 * kap * kap) / (15 * pow(1 + kap, 3));
        const double atr = 2 * kap * kap / (15 * (1 + kap) * (1 + kap));
        const double btt = kap * (4 + kap) / (10 * (1 + kap) * (1 + kap)), btr = 2 * kap / (5 * (1 + kap));
        const double *wp = w + 3 * p, *wq = w + 3 * q;
        double m[3], o[3], tw[3], uts[3];
        for (int a = 0; a < 3; a++) {
            m[a] = s * n[a];
            uts[a] = s * ut[a]; /* v_q − v_p, tangential */
            o[a] = wp[a] + wq[a] + 4 * wp[a] / kap + 4 * kap * wq[a];
            tw[a] = wp[a] + kap * wq[a] / 4;
        }
        const double twn = tw[0] * m[0] + tw[1] * m[1] + tw[2] * m[2];
        const double ox = o[1] * m[2] - o[2] * m[1], oy = o[2] * m[0] - o[0] * m[2], oz = o[0] * m[1] - o[1] * m[0];
        const double mux[3] = {m[1] * uts[2] - m[2] * uts[1], m[2] * uts[0] - m[0] * uts[2], m[0] * uts[1] - m[1] * uts[0]};
        const double cf = 6 * M_PI * mu * rp * ell, ct = 8 * M_PI * mu * rp * rp * ell;
        const double oxv[3] = {ox, oy, oz};
        double *T = side ? Tj : Ti;
        for (int a = 0; a < 3; a++) {
            if (!side) F[a] = cf * (att * uts[a] - rp * atr * oxv[a]);
            T[a] = ct * (btt * mux[a] - rp * btr * (tw[a] - twn * m[a]));
        }
    }
    const double imi = d->invm[i] * dt, imj = d->invm[j] * dt, iIi = d->invI[i] * dt, iIj = d->invI[j] * dt;
    for (int a = 0; a < 3; a++) {
        v[3 * i + a] += F[a] * imi;
        v[3 * j + a] -= F[a] * imj;
        w[3 * i + a] += Ti[a] * iIi;
        w[3 * j + a] += Tj[a] * iIj;
        fl[3 * i + a] += F[a];
        fl[3 * j + a] -= F[a];
    }
}

/* The same for particle i and a wall of unit normal nw (into the domain) moving with vel. */
static void lub_tangential_wall(dem_t *d, int i, const double nw[3], const double vel[3], double ell, double mu,
                                double dt)
{
    const double R = d->r[i];
    double *v = d->v + 3 * i, *w = d->w + 3 * i, *fl = d->flub + 3 * i;
    double n[3], u[3], un = 0, wn = 0;
    for (int a = 0; a < 3; a++) {
        n[a] = -nw[a]; /* towards the wall */
        u[a] = v[a] - vel[a];
        un += u[a] * n[a];
        wn += w[a] * n[a];
    }
    double ut[3], wt[3];
    for (int a = 0; a < 3; a++) {
        ut[a] = u[a] - un * n[a];
        wt[a] = w[a] - wn * n[a];
    }
    const double wxn[3] = {w[1] * n[2] - w[2] * n[1], w[2] * n[0] - w[0] * n[2], w[0] * n[1] - w[1] * n[0]};
    const double nxu[3] = {n[1] * ut[2] - n[2] * ut[1], n[2] * ut[0] - n[0] * ut[2], n[0] * ut[1] - n[1] * ut[0]};
    const double cf = 6 * M_PI * mu * R * ell, ct = 8 * M_PI * mu * R * R * ell;
    const double im = d->invm[i] * dt, iI = d->invI[i] * dt;
    for (int a = 0; a < 3; a++) {
        const double F = -cf * (8.0 / 15.0 * ut[a] + 2.0 / 15.0 * R * wxn[a]);
        const double T = -ct * (0.1 * nxu[a] + 0.4 * R * wt[a]);
        v[a] += F * im;
        w[a] += T * iI;
        fl[a] += F;
    }
}

/* ℓ of the tangential terms at gap δ (0 outside 0 < δ < δ_t). */
static inline double lub_tangential_log(double delta, double range, double eta)
{
    return delta > 0 && delta < range ? log((range + eta) / (delta + eta)) : 0.0;
}

static void lub_tangential_impulses(dem_t *d, double dt)
{
    const dem_lub_t *L = &d->lub;
    const double *invm = d->invm, *r = d->r;
    for (int i = 0; i < d->nb_n_rows; i++)
        for (long e = d->nb_start[i]; e < d->nb_start[i + 1]; e++) {
            const int j = d->nb_j[e];
            if (invm[i] == 0 && invm[j] == 0) continue;
            double n[3];
            const double R = r[i] < r[j] ? r[i] : r[j], gap = dem_pair_normal(d, i, e, n) - r[i] - r[j];
            const double ell = lub_tangential_log(gap, lub_tangential_range(L, R), L->roughness * R);
            if (ell > 0) lub_tangential_pair(d, i, j, n, ell, L->viscosity, dt);
        }
    if (L->walls)
        for (int k = 0; k < d->nwall; k++) {
            const dem_wall_t *W = &d->wall[k];
            if (!W->active) continue;
            for (int q = 0; q < W->nlist; q++) {
                const int i = W->idx[q];
                if (invm[i] == 0) continue;
                double u;
                const double gap = dem_wall_gap(d, W, i, &u);
                const double ell = lub_tangential_log(gap, lub_tangential_range(L, r[i]), L->roughness * r[i]);
                if (ell > 0) lub_tangential_wall(d, i, W->n, W->vel, ell, L->viscosity, dt);
            }
        }
}

double dem_lubrication_tangential_rate(const dem_t *d, double R, double m)
{
    const dem_lub_t *L = &d->lub;
    if (!L->on || !L->tangential) return 0.0;
    /* the largest damping rate of the explicit terms, at δ = 0: the rotation
     * of a sphere against a wall, (8πμR³ (2/5) ℓ)/(2/5 m R²) = 8πμR ℓ/m */
    const double ell = log((lub_tangential_range(L, R) + L->roughness * R) / (L->roughness * R));
    return 8 * M_PI * L->viscosity * R * ell / m;
}

static const cfg_key_t lub_keys[] = {
    {"lubrication", "model", CFG_ENUM, "none", 1, 0, "none|brenner|correction",
     "lubrication between particles and with walls: none; brenner (the seed's eq. 3.18: the whole normal force up to "
     "range x R); correction (only what the fluid model does not resolve: with the resolved fluid the normal and "
     "tangential terms below cutoff and tangential_cutoff grid cells, each less its value there; without it the whole "
     "force up to range x R)"},
    {"lubrication", "roughness", CFG_DOUBLE, "2e-4", 1e-12, 1, NULL, "effective roughness eta_e / R"},
    {"lubrication", "range", CFG_DOUBLE, "0.5", 1e-6, 10, NULL,
     "activation distance Delta_lub / R (gap 0 < delta <= Delta_lub) of brenner, and of correction without a resolved fluid"},
    {"lubrication", "cutoff", CFG_DOUBLE, "1.1", 0.01, 100, NULL,
     "correction with the resolved fluid: normal cut-off in grid cells (the gap below which the grid no longer carries "
     "the film force; 1.1 measured for the immersed boundary, docs/theory.md)"},
    {"lubrication", "tangential_cutoff", CFG_DOUBLE, "0.6", 0.01, 100, NULL,
     "correction with the resolved fluid: cut-off of the tangential and rotational terms in grid cells (0.6 "
     "measured, docs/theory.md)"},
    {"lubrication", "tangential", CFG_BOOL, "true", 1, 0, NULL,
     "correction: also the Goldman-Cox-Brenner tangential and rotational terms (logarithmic)"},
    {"lubrication", "subtract_resolved", CFG_BOOL, "false", 1, 0, NULL,
     "brenner: subtract the force at the activation distance (the part a resolved fluid already carries)"},
    {"lubrication", "overlap", CFG_ENUM, "off", 1, 0, "off|saturated",
     "lubrication while the particles overlap: off (decision 5), or saturated (the force keeps its delta = 0 value "
     "-6 pi eta_f R^2 u_n / eta_e: the contact damping of eq. 3.26)"},
    {"lubrication", "walls", CFG_BOOL, "true", 1, 0, NULL, "also between a particle and a wall"},
    {"lubrication", "viscosity", CFG_DOUBLE, "-1", -1, 1e12, NULL,
     "dynamic viscosity eta_f (Pa s); -1: that of the scene's fluid (rho nu of [fluid], or the viscosity of "
     "[drag] or [porenet])"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL},
};

void dem_lubrication_register_keys(void) { cfg_schema_add(lub_keys); }

void dem_lubrication_config(dem_t *d, cfg_t *cfg)
{
    dem_lub_t *L = &d->lub;
    memset(L, 0, sizeof *L);
    L->model = fluid_model_lubrication(cfg) ? cfg_enum(cfg, "lubrication", "model") : LUB_NONE;
    L->on = L->model != LUB_NONE;
    if (!L->on) return;
    L->roughness = cfg_double(cfg, "lubrication", "roughness");
    L->range = cfg_double(cfg, "lubrication", "range");
    L->subtract = cfg_bool(cfg, "lubrication", "subtract_resolved");
    L->walls = cfg_bool(cfg, "lubrication", "walls");
    L->overlap = cfg_enum(cfg, "lubrication", "overlap") == 1;
    if (L->model == LUB_CORRECTION) {
        L->cutoff = cfg_double(cfg, "lubrication", "cutoff");
        L->tcutoff = cfg_double(cfg, "lubrication", "tangential_cutoff");
        L->tangential = cfg_bool(cfg, "lubrication", "tangential");
        if (L->subtract)
            cfg_fail(cfg, "lubrication", "subtract_resolved",
                     "is for model = brenner: correction subtracts the value at its cut-off by itself");
    }
    L->viscosity = cfg_double(cfg, "lubrication", "viscosity");
    if (L->viscosity < 0) {
        L->viscosity = fluid_model_viscosity(cfg);
        if (L->viscosity < 0)
            cfg_fail(cfg, "lubrication", "viscosity",
                     "needed: the scene gives no fluid viscosity to take it from ([fluid] rho nu or mu, [drag] or "
                     "[porenet] viscosity)");
    }
    if (!(L->viscosity > 0)) cfg_fail(cfg, "lubrication", "viscosity", "must be positive with lubrication");
}

void dem_lubrication_set_grid(dem_t *d, double h)
{
    d->lub.h = h;
    if (d->lub.model == LUB_CORRECTION && h > 0)
        msg("lubrication: correction below %.3g (normal) and %.3g (tangential%s) grid cells of %.4g\n", d->lub.cutoff,
            d->lub.tcutoff, d->lub.tangential ? "" : ": off", h);
}

const double *dem_lubrication_forces(const dem_t *d) { return d->flub; }
