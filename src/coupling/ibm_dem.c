/* ibm_dem.c — the exchanges of the resolved coupling (coupling.h): DEM
 * particles as immersed spheres, hydrodynamic forces to the DEM, motion
 * back to the immersed boundary.  Sphere p is the particle of id p. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "coupling.h"
#include "util.h"

ibm_sphere_t *coupling_spheres_of_particles(const dem_t *d, int *n)
{
    const int np = dem_count(d);
    ibm_sphere_t *s = xcalloc((size_t)(np > 0 ? np : 1), sizeof *s);
    const double *x = dem_positions(d), *v = dem_velocities(d), *w = dem_omegas(d), *r = dem_radii(d);
    const long *id = dem_ids(d);
    for (int i = 0; i < np; i++) {
        if (id[i] < 0 || id[i] >= np) die("coupling: particle ids must be 0..N-1 (got %ld)", id[i]);
        ibm_sphere_t *t = &s[id[i]];
        t->kind = IBM_EXTERNAL;
        t->radius = r[i];
        t->density = dem_density(d, i);
        t->history = -1;
        for (int a = 0; a < 3; a++) {
            t->x[a] = t->xa[a] = x[3 * i + a];
            t->u[a] = v[3 * i + a];
            t->omega[a] = w[3 * i + a];
        }
    }
    *n = np;
    return s;
}

void coupling_freeze_init(coupling_freeze_t *fz, int n, double hold_time)
{
    fz->n = n;
    fz->hold_time = hold_time;
    fz->F0 = xcalloc(6 * (size_t)(n > 0 ? n : 1), sizeof(double));
    fz->J = xcalloc(6 * (size_t)(n > 0 ? n : 1), sizeof(double));
    fz->held = xcalloc((size_t)(n > 0 ? n : 1), sizeof(double));
}

void coupling_freeze_free(coupling_freeze_t *fz)
{
    free(fz->F0);
    free(fz->J);
    free(fz->held);
    memset(fz, 0, sizeof *fz);
}

void coupling_added_mass_init(coupling_added_mass_t *am, int n, double cm)
{
    am->n = n;
    am->cm = cm;
    am->dU = xcalloc(3 * (size_t)(n > 0 ? n : 1), sizeof(double));
    am->U0 = xcalloc(3 * (size_t)(n > 0 ? n : 1), sizeof(double));
    am->slow = xcalloc(3 * (size_t)(n > 0 ? n : 1), sizeof(double));
}

void coupling_added_mass_free(coupling_added_mass_t *am)
{
    free(am->dU);
    free(am->U0);
    free(am->slow);
    memset(am, 0, sizeof *am);
}

void coupling_added_mass_apply(const coupling_added_mass_t *am, dem_t *d, double rho_fluid)
{
    const double *r = dem_radii(d);
    for (int i = 0; i < dem_count(d); i++)
        dem_set_added_mass(d, i, am->cm * rho_fluid * 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i]);
}

void coupling_added_mass_after_step(coupling_added_mass_t *am, const dem_t *d)
{
    const long *id = dem_ids(d);
    const unsigned char *fx = dem_fixed(d);
    for (int i = 0; i < dem_count(d); i++) {
        const long p = id[i];
        double U[3];
        dem_full_velocity(d, i, U);
        /* a fixed particle (infinite mass) takes no collision velocity change */
        for (int a = 0; a < 3; a++) am->dU[3 * p + a] = fx[i] ? 0.0 : U[a] - am->U0[3 * p + a] - am->slow[3 * p + a];
    }
}

void coupling_forces_to_dem(const ibm_t *ibm, dem_t *d, double rho_fluid, const double gravity[3],
                            coupling_freeze_t *fz, coupling_added_mass_t *am, double dt)
{
    double *fe = dem_ext_force(d), *te = dem_ext_torque(d);
    const double *r = dem_radii(d);
    const long *id = dem_ids(d);
    for (int i = 0; i < dem_count(d); i++) {
        const long p = id[i];
        const ibm_sphere_t *s = &ibm->s[p];
        const double V = 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];
        double F[6] = {s->force[0], s->force[1], s->force[2], s->torque[0], s->torque[1], s->torque[2]};
        /* the fluid's reaction to the collision velocity change of the last step, ≈ −C_M ρ V ΔU_c/Δt,
         * was already taken by the DEM (contacts and lubrication on m*): added back */
        if (am)
            for (int a = 0; a < 3; a++) F[a] += am->cm * rho_fluid * V * am->dU[3 * p + a] / dt;
        if (fz) {
            const int contact = dem_in_contact(d, i);
            double *F0 = fz->F0 + 6 * p, *J = fz->J + 6 * p;
            if (contact && fz->held[p] < fz->hold_time) {
                /* frozen: the force before the contact; what the fluid did meanwhile is deferred */
                for (int a = 0; a < 6; a++) {
                    J[a] += (F[a] - F0[a]) * dt;
                    F[a] = F0[a];
                }
                fz->held[p] += dt;
            } else {
                for (int a = 0; a < 6; a++) {
                    if (!contact) F0[a] = F[a];
                    F[a] += J[a] / dt;
                    J[a] = 0.0;
                }
                if (!contact) fz->held[p] = 0.0;
            }
        }
        for (int a = 0; a < 3; a++) {
            /* decision 7: the fluid pressure is relative to hydrostatic, so the DEM's weight m_p g
             * needs the buoyancy −ρ V_p g besides the hydrodynamic force of the immersed boundary */
            fe[3 * i + a] = F[a] - rho_fluid * V * gravity[a];
            te[3 * i + a] = F[3 + a];
        }
        if (am && !dem_fixed(d)[i]) {
            /* the DEM's inertia is m* = m_p + C_M ρ V: the held force scaled by m* over m_p keeps the acceleration
             * (F_h − ρ V g)/m_p + g of the forces that are not the collision's */
            const double mstar = dem_mass(d, i), mp = dem_density(d, i) * V;
            double U[3];
            dem_full_velocity(d, i, U);
            for (int a = 0; a < 3; a++) {
                fe[3 * i + a] *= mstar / mp;
                am->U0[3 * p + a] = U[a];
                am->slow[3 * p + a] = dt * (fe[3 * i + a] / mstar + gravity[a]);
            }
        }
    }
}

void coupling_motion_to_ibm(const dem_t *d, ibm_t *ibm)
{
    const double *x = dem_positions(d), *v = dem_velocities(d), *w = dem_omegas(d);
    const long *id = dem_ids(d);
    for (int i = 0; i < dem_count(d); i++) {
        ibm_sphere_t *s = &ibm->s[id[i]];
        for (int a = 0; a < 3; a++) {
            s->x[a] = x[3 * i + a];
            s->u[a] = v[3 * i + a];
            s->omega[a] = w[3 * i + a];
        }
    }
    ibm_update_geometry(ibm);
}

void coupling_drag_init(coupling_drag_t *dr, int n, double k, double mu, int hindered)
{
    memset(dr, 0, sizeof *dr);
    dr->n = n;
    dr->k = k;
    dr->mu = mu;
    dr->held = xcalloc(6 * (size_t)(n > 0 ? n : 1), sizeof(double));
    dr->hindered = hindered;
    dr->bounded[0] = dr->bounded[1] = dr->bounded[2] = 1;
}

void coupling_drag_set_bounded(coupling_drag_t *dr, const int periodic[3])
{
    for (int a = 0; a < 3; a++) dr->bounded[a] = !periodic[a];
}

void coupling_drag_free(coupling_drag_t *dr)
{
    free(dr->held);
    free(dr->factor);
    free(dr->phi);
    free(dr->du);
    dem_nbhood_free(&dr->nbh);
    memset(dr, 0, sizeof *dr);
}

/* Richardson & Zaki's exponent in the viscous limit (Re_t < 0.2), as [drag] exponent's default. */
#define DRAG_RZ_EXPONENT 4.65
/* Radius of the sampling ball of the local solid fraction, in mean diameters: the first shell of
 * neighbours of a dense packing (centres at ~1 D) whole, and within the 3 D periods of the quick
 * avalanche box once clipped (dem_fraction_radius). */
#define DRAG_FRACTION_RADIUS 1.5

/* The local fraction read by the hindrance at most: random close packing.  A denser reading is
 * the estimator's scatter (a ball of 1.5 D holds a few grains); the cap also bounds the
 * coefficient (116 times Stokes's), so the chunks of coupling_drag_advance stay several DEM
 * steps long and the explicit update of the term within a chunk stable. */
#define DRAG_PHI_MAX 0.64

double coupling_drag_hindrance(double k, double phi)
{
    const double h = pow(1.0 - (phi < DRAG_PHI_MAX ? phi : DRAG_PHI_MAX), -DRAG_RZ_EXPONENT);
    return h > k ? h : k;
}

/* The force coefficient over 3πηD of every particle (by id) for this step. */
static void drag_factors(coupling_drag_t *dr, const dem_t *d)
{
    const long nid = dem_id_bound(d);
    if (dr->nid < nid) {
        free(dr->factor);
        free(dr->phi);
        free(dr->du);
        dr->factor = xcalloc((size_t)nid, sizeof *dr->factor);
        dr->phi = xcalloc((size_t)nid, sizeof *dr->phi);
        dr->du = xcalloc(3 * (size_t)nid, sizeof *dr->du);
        dr->nid = nid;
    }
    const long *id = dem_ids(d);
    const unsigned char *fixed = dem_fixed(d);
    const int np = dem_count(d);
    if (dr->hindered) {
        int clipped;
        dem_local_fraction(d, dem_fraction_radius(d, DRAG_FRACTION_RADIUS, &clipped), dr->phi, NULL, NULL,
                           dr->hindered == DRAG_HINDRANCE_RELATIVE ? &dr->nbh : NULL);
    }
    double ps = 0, fm = 0;
    int nm = 0;
    for (int i = 0; i < np; i++) {
        const long p = id[i];
        dr->factor[p] = dr->hindered ? coupling_drag_hindrance(dr->k, dr->phi[p]) : dr->k;
        if (fixed[i]) continue;
        nm++;
        ps += dr->hindered ? dr->phi[p] : 0.0;
        fm = fmax(fm, dr->factor[p]);
    }
    dr->phi_mean = nm ? ps / nm : 0.0;
    dr->factor_max = fm;
}

/* c = f 3πηD and c_r = K πηD³ of a particle of radius r, f its force coefficient over 3πηD
 * (the torque's is K: the rotation of a grain in its cage is resisted by the lubrication's
 * tangential terms where they are modelled, not by a hindered drag) */
static void drag_coefficients(const coupling_drag_t *dr, double f, double r, double *c, double *cr)
{
    *c = f * 6.0 * M_PI * dr->mu * r;
    *cr = dr->k * 8.0 * M_PI * dr->mu * r * r * r;
}

dem_status_t coupling_drag_advance(coupling_drag_t *dr, const ibm_t *ibm, dem_t *d, coupling_added_mass_t *am,
                                   double dt)
{
    const int np = dem_count(d);
    const long *id = dem_ids(d);
    const double *r = dem_radii(d);
    const unsigned char *fixed = dem_fixed(d);
    double *fe = dem_ext_force(d), *te = dem_ext_torque(d);
    /* the held force and torque, by sphere (the DEM may reorder its particles between chunks),
     * and the shortest relaxation time */
    double tau = INFINITY;
    drag_factors(dr, d);
    for (int i = 0; i < np; i++) {
        const long p = id[i];
        for (int a = 0; a < 3; a++) {
            dr->held[6 * p + a] = fe[3 * i + a];
            dr->held[6 * p + 3 + a] = te[3 * i + a];
        }
        if (fixed[i]) continue;
        double c, cr;
        /* (relative: the part (c_h − c_K)(ΔU − ΔŪ) has rates up to 2 (c_h − c_K)/m, ΔŪ being a weighted
         * mean; a chunk of 5 % of m/c_h keeps that mode's update at most 0.1 per chunk: stable, and
         * within 0.5 % of its exponential per chunk) */
        drag_coefficients(dr, dr->factor[p], r[i], &c, &cr);
        const double mp = dem_density(d, i) * 4.0 / 3.0 * M_PI * r[i] * r[i] * r[i];
        tau = fmin(tau, fmin(dem_mass(d, i) / c, 0.4 * mp * r[i] * r[i] / cr));
    }
    /* the steps dem_advance would take over dt, in chunks of at most 5 % of the relaxation time */
    const double t0 = dem_time(d), ratio = dt / dem_dt(d);
    long nsteps = lround(ratio);
    if (nsteps < 1 || fabs(ratio - (double)nsteps) > 1e-6) nsteps = (long)ceil(ratio * (1 - 1e-12));
    if (nsteps < 1) nsteps = 1;
    const double per = 0.05 * tau / (dt / (double)nsteps); /* steps per chunk (inf: no mobile particle) */
    long chunk = per < (double)nsteps ? (long)per : nsteps;
    if (chunk < 1) chunk = 1;
    dem_status_t st = DEM_OK;
    for (long done = 0; done < nsteps && st == DEM_OK; done += chunk) {
        const long next = done + chunk < nsteps ? done + chunk : nsteps;
        const double span = (double)(next - done) * dt / (double)nsteps;
        const int n = dem_count(d);
        const long *idn = dem_ids(d);
        const double *rn = dem_radii(d), *w = dem_omegas(d);
        const unsigned char *fx = dem_fixed(d);
        fe = dem_ext_force(d);
        te = dem_ext_torque(d);
        /* every particle's change ΔU = U − U_n first (the neighbourhood means read them) */
        for (int i = 0; i < n; i++) {
            const long p = idn[i];
            double U[3];
            dem_full_velocity(d, i, U);
            for (int a = 0; a < 3; a++) dr->du[3 * p + a] = fx[i] ? 0.0 : U[a] - ibm->s[p].u[a];
        }
        for (int i = 0; i < n; i++) {
            const long p = idn[i];
            const ibm_sphere_t *s = &ibm->s[p];
            const double *dU = dr->du + 3 * p;
            double c, ck, cr, dum[3];
            drag_coefficients(dr, dr->factor[p], rn[i], &c, &cr);
            drag_coefficients(dr, dr->k, rn[i], &ck, &cr);
            /* relative: ΔŪ, the neighbourhood's mean change (none in the ball: the particle's own, K alone) */
            double ws = 0;
            for (int a = 0; a < 3; a++) dum[a] = 0.0;
            if (dr->hindered == DRAG_HINDRANCE_RELATIVE && !fx[i])
                for (long k = dr->nbh.beg[p]; k < dr->nbh.end[p]; k++) {
                    ws += dr->nbh.w[k];
                    for (int a = 0; a < 3; a++) dum[a] += dr->nbh.w[k] * dr->du[3 * dr->nbh.id[k] + a];
                }
            for (int a = 0; a < 3; a++) dum[a] = ws > 0 ? dum[a] / ws : dU[a];
            for (int a = 0; a < 3; a++) {
                const double F = fx[i] ? 0.0
                                 : dr->hindered == DRAG_HINDRANCE_RELATIVE && !dr->bounded[a]
                                     ? -ck * dU[a] - (c - ck) * (dU[a] - dum[a])
                                     : -c * dU[a];
                fe[3 * i + a] = dr->held[6 * p + a] + F;
                te[3 * i + a] = dr->held[6 * p + 3 + a] - (fx[i] ? 0.0 : cr * (w[3 * i + a] - s->omega[a]));
                if (am && !fx[i]) am->slow[3 * p + a] += span * F / dem_mass(d, i);
            }
        }
        st = dem_advance(d, next == nsteps ? t0 + dt : t0 + (double)next * dt / (double)nsteps);
        dr->chunks++;
    }
    return st;
}
