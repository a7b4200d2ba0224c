/* contact_hertz.c — Hertz–Mindlin contact (no-slip Mindlin tangential
 * stiffness), the common alternative to the linear law (Di Renzo & Di Maio
 * 2004; Tsuji et al. 1992 damping; as in LIGGGHTS "hertz").
 *
 * One material: Young's modulus E, Poisson ratio ν, restitution e.
 *     E* = E / (2(1 − ν²)),  G* = E / (4 (2 − ν)(1 + ν)),  R* = R_i R_j/(R_i + R_j)
 *     S_n = 2 E* √(R* δ),  S_t = 8 G* √(R* δ)
 *     F_n = (4/3) E* √R* δ^{3/2} + γ_n δ̇,   γ_n = 2 √(5/6) |β| √(S_n m*)
 *     F_t = −S_t ξ − γ_t v_t (Coulomb-capped),   γ_t = 2 √(5/6) |β| √(S_t m*)
 *     β = ln e / √(ln² e + π²)
 * Walls: the same material, R* = R_i, m* = m_i.  The contact time depends
 * on the impact velocity; the time step uses the elastic Hertz time
 *     t_c = 2.868 (m*² / (R* E*² v))^{1/5}
 * of the lightest pair at [contact] reference_velocity.
 */
#include <math.h>

#include "dem_private.h"
#include <stdio.h>

static inline double hertz_normal(const dem_contact_prm_t *cp, double delta, double meff, double reff,
                                  double vn_damp, double *kt, double *gt)
{
    const double a = sqrt(reff * delta); /* contact radius */
    const double sn = 2.0 * cp->E_star * a, st = 8.0 * cp->G_star * a;
    const double c = 2.0 * sqrt(5.0 / 6.0) * cp->beta_damp;
    *kt = st;
    *gt = c * sqrt(st * meff);
    return (2.0 / 3.0) * sn * delta - c * sqrt(sn * meff) * vn_damp;
}

#define LAW_NORMAL hertz_normal
#define LAW_PAIRS hertz_pairs
#define LAW_WALL hertz_wall
#include "dem_kernel.inc"

static void hertz_setup(dem_t *d, cfg_t *cfg)
{
    dem_contact_prm_t *cp = &d->cp;
    const double E = cfg_double(cfg, "contact", "youngs_modulus");
    const double nu = cfg_double(cfg, "contact", "poisson_ratio");
    const double e = cfg_double(cfg, "contact", "restitution");
    cp->E_star = E / (2.0 * (1.0 - nu * nu));
    cp->G_star = E / (4.0 * (2.0 - nu) * (1.0 + nu));
    const double le = log(e);
    cp->beta_damp = -le / sqrt(le * le + M_PI * M_PI); /* |β| */
    cp->v_ref = cfg_double(cfg, "contact", "reference_velocity");
    cp->restitution = e;
    snprintf(cp->summary, sizeof cp->summary, "Hertz-Mindlin contact, E* = %.6g Pa, G* = %.6g Pa, |beta| = %.5f",
             cp->E_star, cp->G_star, cp->beta_damp);
}

static double hertz_contact_time(const dem_t *d)
{
    const dem_contact_prm_t *cp = &d->cp;
    double rmin;
    const double mmin = dem_lightest_mass(d, &rmin);
    if (!isfinite(mmin)) return INFINITY;
    const double meff = 0.5 * mmin, reff = 0.5 * rmin;
    return 2.868 * pow(meff * meff / (reff * cp->E_star * cp->E_star * cp->v_ref), 0.2);
}

static double hertz_energy(const dem_contact_prm_t *cp, double delta, double meff, double reff, double xi2)
{
    (void)meff;
    /* ∫ (4/3) E* √R* δ^{3/2} dδ = (8/15) E* √R* δ^{5/2}; Mindlin spring ½ S_t ξ² */
    const double a = sqrt(reff * delta);
    return (8.0 / 15.0) * cp->E_star * a * delta * delta + 0.5 * 8.0 * cp->G_star * a * xi2;
}

const dem_contact_law_t dem_contact_hertz_mindlin = {
    .name = "hertz_mindlin",
    .setup = hertz_setup,
    .contact_time = hertz_contact_time,
    .pair_forces = hertz_pairs,
    .wall_forces = hertz_wall,
    .energy = hertz_energy,
};
