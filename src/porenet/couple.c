/* couple.c — the pore network coupled with the DEM engine (DEM–PFV, thesis
 * §4.2, fig. 4.3): the fluid forces of the pore pressures are the external
 * forces of the particles, and the pore volume rates come from their motion. */
#include <math.h>
#include <stdlib.h>

#include "dem.h"
#include "porenet.h"

void pn_model_gather(pn_model_t *m, const dem_t *d)
{
    const int n = dem_count(d);
    const double *x = dem_positions(d), *r = dem_radii(d);
    const long *id = dem_ids(d);
    if (n != m->n || !m->xid) {
        m->xid = realloc(m->xid, 3 * (size_t)n * sizeof *m->xid);
        m->rid = realloc(m->rid, (size_t)n * sizeof *m->rid);
    }
    for (int i = 0; i < n; i++) {
        const long k = id[i];
        for (int a = 0; a < 3; a++) {
            double v = x[3 * i + a];
            /* the DEM brings a centre back across a periodic face at its own pace (list updates) */
            if (m->dom.periodic[a]) {
                const double L = m->dom.hi[a] - m->dom.lo[a];
                if (v < m->dom.lo[a]) v += L;
                else if (v > m->dom.hi[a]) v -= L;
            }
            m->xid[3 * k + a] = v;
        }
        m->rid[k] = r[i];
    }
}

int pn_model_couple_dem(pn_model_t *m, dem_t *d, const double g[3], double dt)
{
    pn_model_gather(m, d);
    if (pn_model_step(m, dem_count(d), m->xid, m->rid, dt)) return -1;
    pn_model_apply_forces(m, d, g);
    return 0;
}

void pn_model_apply_forces(const pn_model_t *m, dem_t *d, const double g[3])
{
    const int n = dem_count(d);
    const double *r = dem_radii(d);
    const long *id = dem_ids(d);
    double *fe = dem_ext_force(d), *te = dem_ext_torque(d);
    for (int i = 0; i < n; i++) {
        const long k = id[i];
        /* buoyancy of the hydrostatic pressure (the model solves the excess one) */
        const double vs = 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];
        for (int a = 0; a < 3; a++) {
            fe[3 * i + a] = m->f[3 * k + a] - m->rho_f * vs * g[a];
            te[3 * i + a] = 0;
        }
    }
}

double pn_coupled_dt(const pn_model_t *m, const dem_t *d)
{
    const int n = dem_count(d);
    const double *r = dem_radii(d);
    const unsigned char *fixed = dem_fixed(d);
    double lim = INFINITY;
    for (int i = 0; i < n; i++)
        if (!fixed[i]) lim = fmin(lim, dem_mass(d, i) / (200.0 * m->prm.mu * 2.0 * r[i])); /* (4.20) */
    return m->dt_factor * lim;
}

double pn_coupled_step(const pn_model_t *m, const dem_t *d)
{
    return fmin(pn_coupled_dt(m, d), (m->dem_steps > 1 ? m->dem_steps : 1) * dem_dt(d));
}
