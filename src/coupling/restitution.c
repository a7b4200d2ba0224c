/* restitution.c — restitution of a bounce measured during the run
 * (decision 8; Izard 2014 §3.1.3.1 and §3.2 of the reference notes).
 *
 * Wall: the particle of id 0 moves along `axis` (towards the wall).  Its
 * approach speed u = v·axis is sampled at the end of every fluid step and
 * at every DEM sub-step:
 *   V_T  the largest approach speed before the first contact, over the fluid
 *        steps ("the terminal velocity before any wall influence");
 *   V_C  the approach speed at the last fluid step before the contact (the
 *        seed's velocity histories are sampled at the fluid steps; with
 *        aligned contacts that step ends t_c/8 before the contact, see
 *        docs/theory.md §9.1); the speed at the last sub-step before the
 *        contact, V_C_onset, is lower by the lubrication of the last
 *        fraction of the gap, ∝ ln of that gap over η_e;
 *   V_R  the largest rebound speed −u after the contact, over the fluid
 *        steps until the next contact ("the maximum value of the velocity of
 *        opposite sign just after detachment": the seed's velocity history
 *        is the particle's at the fluid steps, after the lubrication of the
 *        detachment has acted — see docs/theory.md §9);
 *   ε = V_R/V_T, St = (ρ_p + ρ/2) V_T D/(9μ), Re_p = ρ V_T D/μ  (eq. 3.19).
 * Pair: the relative approach speed (v₀ − v₁)·n₀₁ of the particles of ids 0
 * and 1 (n₀₁ from 0 to 1), ε_B = −(U_r1 − U_r2)/(U_i1 − U_i2), St_B = ρ_p U D/(9μ),
 * Re = ρ U D/μ  (eq. 3.34–3.35).
 * A contact is on while the tracked particle carries a contact force (the
 * normal force is clipped at zero: the contact ends when it vanishes).
 *
 * The rebound as an experiment records it (Gondret et al. 2002, Joseph et
 * al. 2001 fit the trajectory of the sphere): the gap δ(t) (to the nearest
 * wall, or between the surfaces of the pair) at every sub-step; V_in is the
 * slope of the least-squares line through the gaps of the window W before
 * the contact, V_out the slope through those of the window W after the
 * release (gsl_fit_linear), ε_fit = V_out/V_in, with W = [coupling]
 * fit_window or 0.2 D/V_T; and, against a wall, the apex: the largest gap
 * after the release, and its time.
 */
#include <gsl/gsl_fit.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "coupling.h"
#include "util.h"

void restitution_init(restitution_t *r, restitution_mode_t mode, const double axis[3], double rho_f, double mu,
                      double rho_p, double D, double e_dry)
{
    memset(r, 0, sizeof *r);
    r->mode = mode;
    const double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (int a = 0; a < 3; a++) r->axis[a] = n > 0 ? axis[a] / n : 0.0;
    r->rho_f = rho_f;
    r->mu = mu;
    r->rho_p = rho_p;
    r->D = D;
    r->e_dry = e_dry;
    r->t_contact = r->t_release = -1;
}

void restitution_free(restitution_t *r)
{
    free(r->traj);
    r->traj = NULL;
    r->ntraj = r->captraj = 0;
}

static void traj_add(restitution_t *r, double t, double gap)
{
    if (r->ntraj == r->captraj) {
        r->captraj = r->captraj ? 2 * r->captraj : 1024;
        double *grown = realloc(r->traj, 2 * (size_t)r->captraj * sizeof(double));
        if (!grown) die_local("restitution: out of memory for the trajectory (%ld samples)", r->captraj);
        r->traj = grown;
    }
    r->traj[2 * r->ntraj] = t;
    r->traj[2 * r->ntraj + 1] = gap;
    r->ntraj++;
}

/* Slope of the least-squares line through the samples with t in [t0, t1] (0 with fewer than 3). */
static double traj_slope(const restitution_t *r, double t0, double t1)
{
    long k0 = 0, k1 = r->ntraj;
    while (k0 < r->ntraj && r->traj[2 * k0] < t0) k0++;
    while (k1 > k0 && r->traj[2 * (k1 - 1)] > t1) k1--;
    if (k1 - k0 < 3) return 0.0;
    double c0, c1, cov00, cov01, cov11, sumsq;
    gsl_fit_linear(r->traj + 2 * k0, 2, r->traj + 2 * k0 + 1, 2, (size_t)(k1 - k0), &c0, &c1, &cov00, &cov01, &cov11,
                   &sumsq);
    return c1;
}

/* Gap of the tracked motion: to the nearest wall, or between the surfaces of the pair. */
static double tracked_gap(const restitution_t *r, dem_t *d, int i, int j)
{
    if (r->mode == RESTITUTION_WALL) return dem_wall_gap_min(d, i);
    const double *x = dem_positions(d), *rad = dem_radii(d);
    double l2 = 0;
    for (int a = 0; a < 3; a++) l2 += (x[3 * j + a] - x[3 * i + a]) * (x[3 * j + a] - x[3 * i + a]);
    return sqrt(l2) - rad[i] - rad[j];
}

double restitution_epsilon_fit(const restitution_t *r) { return r->V_in > 0 ? r->V_out / r->V_in : 0.0; }

/* Velocity of the contact point of particle i with the wall, in the wall's plane (axis: towards the wall),
 * and the centre's velocity there. */
static void contact_point_velocity(const restitution_t *r, dem_t *d, int i, double cp[3], double vt[3])
{
    double v[3];
    dem_full_velocity(d, i, v);
    const double *w = dem_omegas(d) + 3 * i, R = dem_radii(d)[i], *n = r->axis;
    const double wxn[3] = {w[1] * n[2] - w[2] * n[1], w[2] * n[0] - w[0] * n[2], w[0] * n[1] - w[1] * n[0]};
    const double vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    for (int a = 0; a < 3; a++) {
        vt[a] = v[a] - vn * n[a];
        cp[a] = vt[a] + R * wxn[a];
    }
}

void restitution_oblique(const restitution_t *r, double *psi_in, double *psi_out, double *beta, double *mu_f,
                         double *angle_out)
{
    *psi_in = *psi_out = *beta = *mu_f = *angle_out = 0.0;
    if (r->mode != RESTITUTION_WALL || r->phase < 2 || !(r->VC_onset > 0)) return;
    /* the normal speeds as an experiment measures them (the trajectory fits), when they are made */
    const int fits = r->V_in > 0 && r->V_out > 0;
    const double un = fits ? r->V_in : r->VC_onset, e = fits ? r->V_out / r->V_in : r->VR_release / r->VC_onset;
    const double ut = sqrt(r->cp_in[0] * r->cp_in[0] + r->cp_in[1] * r->cp_in[1] + r->cp_in[2] * r->cp_in[2]);
    const double vt = sqrt(r->vt_out[0] * r->vt_out[0] + r->vt_out[1] * r->vt_out[1] + r->vt_out[2] * r->vt_out[2]);
    *angle_out = 180.0 / M_PI * atan2(vt, fits ? r->V_out : r->vn_out);
    if (!(ut > 1e-9 * un)) return;
    *psi_in = ut / un;
    *psi_out = (r->cp_out[0] * r->cp_in[0] + r->cp_out[1] * r->cp_in[1] + r->cp_out[2] * r->cp_in[2]) / ut / un;
    *beta = -*psi_out / *psi_in;
    *mu_f = 2.0 * (1.0 + *beta) * *psi_in / (7.0 * (1.0 + e));
}

/* index of the particle with this id (−1 if absent) */
static int index_of(const dem_t *d, long id)
{
    const long *ids = dem_ids(d);
    for (int i = 0; i < dem_count(d); i++)
        if (ids[i] == id) return i;
    return -1;
}

/* Velocity of particle i, full-step or as stored. */
static void velocity_of(dem_t *d, int i, int full_step, double v[3])
{
    if (full_step)
        dem_full_velocity(d, i, v);
    else
        memcpy(v, dem_velocities(d) + 3 * i, 3 * sizeof(double));
}

/* Direction of the approach: the wall axis, or the unit vector from particle i to j. */
static void approach_direction(const restitution_t *r, dem_t *d, int i, int j, double dir[3])
{
    memcpy(dir, r->axis, 3 * sizeof(double));
    if (r->mode != RESTITUTION_PAIR || j < 0) return;
    const double *x = dem_positions(d);
    double len = 0;
    for (int a = 0; a < 3; a++) {
        dir[a] = x[3 * j + a] - x[3 * i + a];
        len += dir[a] * dir[a];
    }
    len = sqrt(len);
    for (int a = 0; a < 3; a++) dir[a] /= len;
}

/* Approach speed of particle i (wall), or of i towards j (pair), along dir. */
static double approach_speed(const restitution_t *r, dem_t *d, int i, int j, const double dir[3], int full_step)
{
    double vi[3], vj[3] = {0, 0, 0};
    velocity_of(d, i, full_step, vi);
    if (r->mode == RESTITUTION_PAIR) velocity_of(d, j, full_step, vj);
    return (vi[0] - vj[0]) * dir[0] + (vi[1] - vj[1]) * dir[1] + (vi[2] - vj[2]) * dir[2];
}

/* The tracked particles: i = id 0, j = id 1 (pair); 0 if they are not there. */
static int tracked(const restitution_t *r, dem_t *d, int *i, int *j)
{
    *i = index_of(d, 0);
    *j = r->mode == RESTITUTION_PAIR ? index_of(d, 1) : -1;
    return *i >= 0 && (r->mode != RESTITUTION_PAIR || *j >= 0);
}

double restitution_approach_speed(const restitution_t *r, dem_t *d, int full_step)
{
    int i, j;
    if (!tracked(r, d, &i, &j)) return 0.0;
    double dir[3];
    approach_direction(r, d, i, j, dir);
    return approach_speed(r, d, i, j, dir, full_step);
}

void restitution_substep(restitution_t *r, dem_t *d)
{
    int i, j;
    if (r->mode == RESTITUTION_OFF || !tracked(r, d, &i, &j)) return;
    double dir[3];
    approach_direction(r, d, i, j, dir);
    const double u = approach_speed(r, d, i, j, dir, 1);
    const double *fl = dem_lubrication_forces(d) + 3 * i;
    const int c = dem_in_contact(d, i);
    /* lubrication impulse on particle 0 against its approach direction: positive when it
     * pushes the particle back */
    r->lub_impulse -= dem_dt(d) * (fl[0] * dir[0] + fl[1] * dir[1] + fl[2] * dir[2]);
    const double t = dem_time(d), gap = tracked_gap(r, d, i, j);
    switch (r->phase) {
    case 0:
        if (c) {
            r->phase = 1;
            r->VC_onset = r->u_last;
            r->t_contact = t;
            if (r->mode == RESTITUTION_WALL) memcpy(r->cp_in, r->cp_last, sizeof r->cp_in);
            const double V = r->VT > 0 ? r->VT : r->u_last;
            r->window = r->fit_window > 0 ? r->fit_window : V > 0 ? 0.2 * r->D / V : 0.0;
            r->V_in = -traj_slope(r, t - r->window, t);
            r->ntraj = 0;
        } else if (gap < 0.3 * r->D) {
            traj_add(r, t, gap); /* the approach, kept from 0.3 D (more than the window's travel) */
        } else {
            r->ntraj = 0;
        }
        break;
    case 1:
        if (!c) {
            r->phase = 2;
            r->VR_release = -u;
            r->t_release = t;
            if (r->mode == RESTITUTION_WALL) {
                contact_point_velocity(r, d, i, r->cp_out, r->vt_out);
                r->vn_out = -u;
            }
            r->ntraj = 0;
            traj_add(r, t, gap);
            r->apex = gap;
            r->t_apex = t;
        }
        break;
    case 2:
        if (c) {
            r->phase = 3;
            break;
        }
        if (t <= r->t_release + r->window)
            traj_add(r, t, gap);
        else if (r->V_out == 0 && r->ntraj > 0) {
            r->V_out = traj_slope(r, r->t_release, r->t_release + r->window);
            r->ntraj = 0;
        }
        /* the apex: until the particle turns back towards the wall */
        if (r->mode == RESTITUTION_WALL && gap > r->apex && u < 0) {
            r->apex = gap;
            r->t_apex = t;
        }
        break;
    default: break;
    }
    r->u_last = u;
    if (r->mode == RESTITUTION_WALL && r->phase == 0) {
        double vt[3];
        contact_point_velocity(r, d, i, r->cp_last, vt);
    }
}

int restitution_measured(const restitution_t *r)
{
    return r->phase == 3 || (r->phase == 2 && r->V_out != 0);
}

void restitution_sample(restitution_t *r, dem_t *d)
{
    if (r->mode == RESTITUTION_OFF) return;
    const double u = restitution_approach_speed(r, d, 0);
    if (r->phase == 0 && u > r->VT) r->VT = u;
    if (r->phase == 0) r->VC = u;
    if (r->phase == 2 && -u > r->VR) r->VR = -u;
}

double restitution_epsilon(const restitution_t *r) { return r->VT > 0 ? r->VR / r->VT : 0.0; }

double restitution_stokes(const restitution_t *r)
{
    if (!(r->mu > 0)) return INFINITY;
    const double rho_eff = r->rho_p + (r->mode == RESTITUTION_WALL ? 0.5 * r->rho_f : 0.0);
    return rho_eff * r->VT * r->D / (9 * r->mu);
}

double restitution_reynolds(const restitution_t *r) { return r->mu > 0 ? r->rho_f * r->VT * r->D / r->mu : INFINITY; }
