/* contact_linear.c — linear spring–dashpot contact of the seed (Izard 2014,
 * eq. 3.13–3.17), with a linear tangential spring and a Coulomb limit.
 *
 * Normal force (positive = repulsive), overlap δ > 0, δ̇ = −v_n:
 *     F_n = k_n δ + γ_n δ̇,   clipped at zero when [contact] normal_clip (decision 3).
 * The constants scale with the pair's effective mass m* = m_i m_j/(m_i + m_j)
 * (m* = m_i against a wall or a fixed particle):
 *     k_n = m* K,  γ_n = m* G,
 * so that every pair has the same restitution e and contact duration t_c.
 *
 * K and G from e and t_c ([contact] calibration):
 *  - seed:    G = −2 ln e / t_c, K = π²/t_c² + G²/4 (eq. 3.16–3.17).  The
 *             UNCLIPPED oscillator then has restitution e and half period t_c.
 *             With the clip the force vanishes before the overlap does: the
 *             effective restitution is e_eff = exp(−q(π − 2 atan q)),
 *             q = −ln e/π, (e = 0.1 → 0.2527, 0.5 → 0.5503, 0.87 → 0.8734) and the force lasts t_c (1 − 2 atan(q)/π).
 *  - clipped (default): K and G chosen so that the CLIPPED law gives exactly
 *             e and a force duration t_c.  With β = G/2, ω_d² = K − β²,
 *             q = β/ω_d, the force vanishes when the acceleration does, at
 *             ω_d t* = π − 2 atan q, where the velocity ratio is
 *             e = exp(−q(π − 2 atan q)).  This covers e > e^{−2} ≈ 0.135
 *             (underdamped); below, the overdamped solution (s² = β² − K,
 *             p = β/s > 1) gives s t* = 2 atanh(1/p), e = exp(−2p atanh(1/p)).
 *             We solve for q (or p) by bisection, then ω_d = (π − 2 atan q)/t_c.
 *  - [contact] parameters = stiffness: k_n (N/m) and γ_n/m* (1/s) given
 *             directly (the LIGGGHTS hooke/stiffness convention of the
 *             benchmark: the same k_n for walls, damping ∝ m*).
 * Tangential: k_t = kt_ratio k_n (seed: 0.2), no tangential damping.
 */
#include <math.h>
#include <stdio.h>

#include "dem_private.h"
#include "util.h"

static inline double linear_normal(const dem_contact_prm_t *cp, double delta, double meff, double reff,
                                   double vn_damp, double *kt, double *gt)
{
    (void)reff;
    const double kn = cp->kn_abs + meff * cp->kn_rel;
    *kt = cp->kt_ratio * kn;
    *gt = 0.0;
    return kn * delta - meff * cp->gn_rel * vn_damp;
}

/* K = k_n/m*: the force k_n max(δ, 0) has a kink of this stiffness (per
 * unit effective mass) at δ = 0, which the kernel treats at the first and the
 * last step of a contact ([contact] spring_kink, docs/theory.md §7.7). */
static inline double linear_kink(const dem_contact_prm_t *cp, double meff, double imeff)
{
    (void)meff;
    return cp->kn_abs * imeff + cp->kn_rel;
}

#define LAW_NORMAL linear_normal
#define LAW_KINK linear_kink
#define LAW_PAIRS linear_pairs
#define LAW_WALL linear_wall
#include "dem_kernel.inc"

/* Duration of the non-zero normal force of the oscillator δ'' + G δ' + K δ = 0
 * started at δ = 0 (clipped: until F = 0; unclipped: until δ = 0), and its
 * restitution. */
static void linear_oscillator(double K, double G, int clip, double *duration, double *restitution)
{
    const double beta = 0.5 * G;
    if (K > beta * beta) {
        const double wd = sqrt(K - beta * beta), q = beta / wd;
        if (clip) {
            *duration = (M_PI - 2.0 * atan(q)) / wd;
            *restitution = exp(-q * (M_PI - 2.0 * atan(q)));
        } else {
            *duration = M_PI / wd;
            *restitution = exp(-q * M_PI);
        }
    } else {
        /* overdamped: only the clipped law separates (F = 0 while δ > 0) */
        const double s = sqrt(beta * beta - K), p = beta / s;
        *duration = p > 1.0 ? 2.0 * atanh(1.0 / p) / s : INFINITY;
        *restitution = p > 1.0 ? exp(-2.0 * p * atanh(1.0 / p)) : 0.0;
    }
}

/* K, G (per unit effective mass) of the clipped law with restitution e and
 * force duration tc. */
static void calibrate_clipped(double e, double tc, double *K, double *G)
{
    const double L = -log(e);
    if (L == 0.0) {
        *K = M_PI * M_PI / (tc * tc);
        *G = 0.0;
        return;
    }
    if (L < 2.0) {
        /* underdamped: L = q (π − 2 atan q), increasing in q from 0 to 2 */
        double lo = 0.0, hi = 1.0;
        while (hi * (M_PI - 2.0 * atan(hi)) < L) hi *= 2.0;
        for (int it = 0; it < 200; it++) {
            const double q = 0.5 * (lo + hi);
            if (q * (M_PI - 2.0 * atan(q)) < L)
                lo = q;
            else
                hi = q;
        }
        const double q = 0.5 * (lo + hi), wd = (M_PI - 2.0 * atan(q)) / tc, beta = q * wd;
        *K = wd * wd + beta * beta;
        *G = 2.0 * beta;
    } else {
        /* overdamped: L = 2 p atanh(1/p), decreasing in p > 1 from ∞ to 2 */
        double lo = 1.0, hi = 2.0;
        while (2.0 * hi * atanh(1.0 / hi) > L) hi *= 2.0;
        for (int it = 0; it < 200; it++) {
            const double p = 0.5 * (lo + hi);
            if (2.0 * p * atanh(1.0 / p) > L)
                lo = p;
            else
                hi = p;
        }
        const double p = 0.5 * (lo + hi), s = 2.0 * atanh(1.0 / p) / tc, beta = p * s;
        *K = beta * beta - s * s;
        *G = 2.0 * beta;
    }
}

/* The onset/separation weights of the spring (dem_kernel.inc) where the
 * force keeps its kink at δ = 0 at both ends: unclipped, or without damping
 * (a clipped law with damping lets go before δ = 0, at the clip). */
static void linear_kink_setup(dem_contact_prm_t *cp, cfg_t *cfg)
{
    cp->kink_energy = cfg_enum(cfg, "contact", "spring_kink") == 0 && (!cp->clip || cp->gn_rel == 0.0);
}

static void linear_setup(dem_t *d, cfg_t *cfg)
{
    dem_contact_prm_t *cp = &d->cp;
    cp->kt_ratio = cfg_double(cfg, "contact", "kt_ratio");
    const int stiffness = cfg_enum(cfg, "contact", "parameters") == 1;
    cp->kn_abs = cp->kn_rel = cp->gn_rel = 0.0;
    if (stiffness) {
        cp->kn_abs = cfg_double(cfg, "contact", "kn");
        cp->gn_rel = cfg_double(cfg, "contact", "gamma_n");
        cp->restitution = cp->tc_given = 0.0;
        snprintf(cp->summary, sizeof cp->summary, "linear contact, k_n = %.6g N/m, gamma_n/m* = %.6g s^-1, k_t/k_n = %g%s",
                 cp->kn_abs, cp->gn_rel, cp->kt_ratio, cp->clip ? " (normal force clipped)" : "");
        linear_kink_setup(cp, cfg);
        return;
    }
    const double e = cfg_double(cfg, "contact", "restitution");
    const double tc = cfg_double(cfg, "contact", "contact_time");
    cp->restitution = e;
    cp->tc_given = tc;
    const int seed = cfg_enum(cfg, "contact", "calibration") == 1;
    if (seed) {
        /* eq. 3.16–3.17 per unit effective mass */
        cp->gn_rel = -2.0 * log(e) / tc;
        cp->kn_rel = M_PI * M_PI / (tc * tc) + 0.25 * cp->gn_rel * cp->gn_rel;
    } else {
        if (!cp->clip)
            cfg_fail(cfg, "contact", "calibration",
                     "'clipped' calibrates the clipped law; with normal_clip = false use calibration = seed");
        calibrate_clipped(e, tc, &cp->kn_rel, &cp->gn_rel);
    }
    linear_kink_setup(cp, cfg);
    double dur, eeff;
    linear_oscillator(cp->kn_rel, cp->gn_rel, cp->clip, &dur, &eeff);
    snprintf(cp->summary, sizeof cp->summary,
             "linear contact, k_n/m* = %.6g s^-2, gamma_n/m* = %.6g s^-1, k_t/k_n = %g: restitution %.5f, "
             "force duration %.6g s%s",
             cp->kn_rel, cp->gn_rel, cp->kt_ratio, eeff, dur, cp->clip ? " (normal force clipped)" : "");
}

static double linear_contact_time(const dem_t *d)
{
    const dem_contact_prm_t *cp = &d->cp;
    double mmin = dem_lightest_mass(d, NULL);
    if (!isfinite(mmin)) mmin = 1.0; /* no particle yet: restitution parameters do not depend on it */
    /* the shortest contact: the lightest pair (m* = m_min/2) */
    const double meff = 0.5 * mmin;
    const double K = cp->kn_abs / meff + cp->kn_rel, G = cp->gn_rel;
    double dur, e;
    linear_oscillator(K, G, cp->clip, &dur, &e);
    return dur;
}

static double linear_energy(const dem_contact_prm_t *cp, double delta, double meff, double reff, double xi2)
{
    (void)reff;
    const double kn = cp->kn_abs + meff * cp->kn_rel;
    return 0.5 * kn * delta * delta + 0.5 * cp->kt_ratio * kn * xi2;
}

const dem_contact_law_t dem_contact_linear = {
    .name = "linear",
    .setup = linear_setup,
    .contact_time = linear_contact_time,
    .pair_forces = linear_pairs,
    .wall_forces = linear_wall,
    .energy = linear_energy,
};
