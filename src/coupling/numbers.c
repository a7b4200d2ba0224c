/* numbers.c — the dimensionless numbers of a resolved particle in its fluid,
 * from the case's physical inputs (printed at the start of a coupled run and
 * written to summary.json, so that a case written in SI units states the
 * regime it is in):
 *
 *   density ratio r = ρ_p/ρ, Galileo number Ga = √((r − 1) g D³)/ν,
 *   Archimedes number Ar = Ga², the terminal velocity V_T of the
 *   Schiller–Naumann drag, C_D = 24/Re (1 + 0.15 Re^0.687) with
 *   C_D Re² = (4/3) Ar (Brent's method, gsl_root), Re_T = V_T D/ν, the
 *   Stokes number of the bounce St_T = (ρ_p + ρ/2) V_T D/(9μ) (Izard eq. 3.19),
 *   the resolution D/h and the contact time t_c √(g/D) and t_c V_T/D.
 */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>

#include "coupling.h"
#include "util.h"

static double sn_residual(double re, void *p)
{
    const double ar = *(const double *)p;
    return 24.0 * re * (1.0 + 0.15 * pow(re, 0.687)) - 4.0 / 3.0 * ar;
}

/* Re of the Schiller–Naumann terminal velocity for an Archimedes number ar (> 0). */
static double sn_reynolds(double ar)
{
    double p = ar, lo = 0.0, hi = ar / 18.0 + 1.0; /* Stokes: Re = Ar/18 bounds it from above */
    gsl_function F = {sn_residual, &p};
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    gsl_root_fsolver_set(s, &F, lo, hi);
    double re = hi;
    for (int it = 0; it < 200; it++) {
        gsl_root_fsolver_iterate(s);
        re = gsl_root_fsolver_root(s);
        lo = gsl_root_fsolver_x_lower(s);
        hi = gsl_root_fsolver_x_upper(s);
        if (gsl_root_test_interval(lo, hi, 0.0, 1e-12) == GSL_SUCCESS) break;
    }
    gsl_root_fsolver_free(s);
    return re;
}

void coupling_numbers(double D, double rho_p, double rho_f, double mu, double g, double h, double tc,
                      coupling_numbers_t *n)
{
    n->D = D;
    n->ratio = rho_p / rho_f;
    const double nu = mu / rho_f;
    n->Ga = n->ratio > 1 && g > 0 ? sqrt((n->ratio - 1.0) * g * D * D * D) / nu : 0.0;
    n->Re_T = n->Ga > 0 ? sn_reynolds(n->Ga * n->Ga) : 0.0;
    n->V_T = n->Re_T * nu / D;
    n->St_T = (rho_p + 0.5 * rho_f) * n->V_T * D / (9.0 * mu);
    n->D_over_h = h > 0 ? D / h : 0.0;
    n->tc_g = g > 0 ? tc * sqrt(g / D) : 0.0;
    n->tc_VT = tc * n->V_T / D;
}
