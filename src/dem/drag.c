/* drag.c — the drag closure of the reduced fluid model `drag` ([coupling]
 * fluid = drag, [drag]; docs/theory.md "Drag closure"): every grain feels
 *
 *     F = 3π μ d K(φ_i) (U_f − v) − ρ_f V g,        T = −π μ d³ ω,
 *
 * the Stokes drag relative to a fluid at rest (or moving with the prescribed
 * mean velocity U_f = [drag] fluid_velocity) times a hindrance function of
 * the local solid fraction φ_i, the buoyancy of the hydrostatic pressure (the
 * immersed weight), and the Stokes torque of a rotating sphere (no hindrance).
 * The hindrance K = 1 (closure stokes: an isolated sphere) or K = (1 − φ)^−n
 * (closure richardson_zaki, n = [drag] exponent, 4.65 in the viscous limit):
 * a homogeneous suspension then settles at v_t (1 − φ)^n, Richardson & Zaki's
 * law (1954), relative to the zero-volume-flux frame in which the fluid's
 * mean velocity is prescribed.  [lubrication] acts as set, on top.
 *
 * Local solid fraction.  φ_i = Σ_{j≠i} V(B_i ∩ S_j) / (|B_i| − V_i): the
 * volume of the other spheres inside the sampling ball B_i of radius
 * R = fraction_radius × the mean diameter around the centre of i (exact
 * sphere–sphere lens volumes), over the ball's volume inside the box without
 * i's own volume.  The particle itself is left out of both, so an isolated
 * sphere has φ = 0 (Stokes's drag) and in a homogeneous suspension the
 * expectation is the suspension's fraction.  The ball is clipped by the
 * non-periodic faces of the domain (spherical caps, an edge's overlap of two
 * caps neglected).  φ_i is recomputed every fraction_every DEM steps (at the
 * steps whose number is a multiple of it) and held in between; the held
 * values are part of the DEM checkpoint (a restart continues exactly).
 *
 * Integration.  The drag is linear in v: over the drift of a step it is
 * applied to the half-step velocity implicitly (backward Euler),
 *     v′ = (v + Δt F_b/m + (Δt/τ) U_f) / (1 + Δt/τ),   τ = m / (3π μ d K),
 * just before the drift (as the lubrication impulses).  Unconditionally
 * stable for any Δt/τ, and a sphere falling under gravity reaches exactly
 * v = U_f + τ (g + F_b/m), the closure's terminal velocity (the kicks add
 * Δt g per step, the relaxation removes Δt/τ of the excess). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "fluid.h"
#include "fluid_model.h"
#include "util.h"

static const cfg_key_t drag_keys[] = {
    {"drag", "closure", CFG_ENUM, "richardson_zaki", 1, 0, "stokes|richardson_zaki",
     "coupling.fluid = drag: drag of each grain, 3 pi mu d K(phi) (U_f - v): stokes (K = 1, an isolated sphere) or "
     "richardson_zaki (K = (1 - phi)^-n, phi the local solid fraction: hindered settling of a suspension)"},
    {"drag", "exponent", CFG_DOUBLE, "4.65", 0, 20, NULL,
     "Richardson-Zaki exponent n (4.65: the viscous limit Re_t < 0.2 of Richardson & Zaki 1954)"},
    {"drag", "viscosity", CFG_DOUBLE, "-1", -1, 1e12, NULL, "dynamic viscosity mu (Pa s); -1: rho nu of [fluid]"},
    {"drag", "fluid_density", CFG_DOUBLE, "-1", -1, 1e12, NULL,
     "fluid density (kg/m^3) of the buoyancy -rho_f V g; -1: rho of [fluid]"},
    {"drag", "fluid_velocity", CFG_VEC3, "0 0 0", -1e300, 1e300, NULL,
     "mean velocity U_f of the fluid (m/s), prescribed; the drag acts on the velocity relative to it"},
    {"drag", "fluid_velocity_from", CFG_ENUM, "prescribed", 1, 0, "prescribed|grains",
     "the fluid velocity U_f of each grain: prescribed (fluid_velocity) or grains (the mean velocity of the other "
     "grains in its sampling ball, volume-weighted, fixed grains at rest: the interstitial fluid of a dense bed "
     "moves with the grains around it; fluid_velocity where the ball holds none)"},
    {"drag", "fraction_radius", CFG_DOUBLE, "3", 0.5, 100, NULL,
     "radius of the sampling ball of the local solid fraction, in mean diameters"},
    {"drag", "fraction_every", CFG_INT, "20", 1, 1000000, NULL,
     "DEM steps between updates of the local solid fraction (held in between)"},
    {"drag", "rotation", CFG_BOOL, "true", 1, 0, NULL, "also the Stokes torque -pi mu d^3 omega of a rotating sphere"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL},
};

void dem_drag_register_keys(void) { cfg_schema_add(drag_keys); }

void dem_drag_config(dem_t *d, cfg_t *cfg)
{
    dem_drag_t *D = &d->drag;
    free(D->phi);
    free(D->fd);
    free(D->ug);
    memset(D, 0, sizeof *D);
    if (fluid_model_of(cfg) != FLUID_MODEL_DRAG) return;
    D->on = 1;
    D->closure = cfg_enum(cfg, "drag", "closure");
    D->n_rz = cfg_double(cfg, "drag", "exponent");
    D->mu = cfg_double(cfg, "drag", "viscosity");
    D->rho_f = cfg_double(cfg, "drag", "fluid_density");
    const int fluid = cfg_has_section(cfg, "fluid");
    if (D->mu < 0) {
        if (!fluid) cfg_fail(cfg, "drag", "viscosity", "needed: the case has no [fluid] section to take rho nu from");
        D->mu = cfg_double(cfg, "fluid", "rho") * fluid_nu_from_config(cfg);
    }
    if (!(D->mu > 0)) cfg_fail(cfg, "drag", "viscosity", "must be positive");
    if (D->rho_f < 0) {
        if (!fluid) cfg_fail(cfg, "drag", "fluid_density", "needed: the case has no [fluid] section to take rho from");
        D->rho_f = cfg_double(cfg, "fluid", "rho");
    }
    cfg_vec3(cfg, "drag", "fluid_velocity", D->uf);
    D->uf_grains = cfg_enum(cfg, "drag", "fluid_velocity_from") == 1;
    D->radius_rel = cfg_double(cfg, "drag", "fraction_radius");
    D->every = cfg_int(cfg, "drag", "fraction_every");
    D->rotation = cfg_bool(cfg, "drag", "rotation");
    D->phi_step = -1;
}

void dem_drag_free(dem_t *d)
{
    free(d->drag.phi);
    free(d->drag.fd);
    free(d->drag.ug);
    d->drag.phi = d->drag.fd = d->drag.ug = NULL;
}

/* Volume of the intersection of balls of radii R and r whose centres are s apart. */
static double lens_volume(double R, double r, double s)
{
    if (s >= R + r) return 0.0;
    if (s <= fabs(R - r)) {
        const double m = R < r ? R : r;
        return 4.0 / 3.0 * M_PI * m * m * m;
    }
    const double t = R + r - s;
    return M_PI * t * t * (s * s + 2 * s * r - 3 * r * r + 2 * s * R + 6 * r * R - 3 * R * R) / (12 * s);
}

/* Volume of the ball (centre c, radius R) inside the box: the caps beyond the
 * non-periodic faces removed. */
static double ball_in_box(const dem_t *d, const double c[3], double R)
{
    double v = 4.0 / 3.0 * M_PI * R * R * R;
    for (int a = 0; a < 3; a++) {
        if (d->periodic[a]) continue;
        const double dist[2] = {c[a] - d->lo[a], d->hi[a] - c[a]};
        for (int s = 0; s < 2; s++) {
            const double h = R - (dist[s] > 0 ? dist[s] : 0);
            if (h > 0) v -= M_PI * h * h * (3 * R - h) / 3;
        }
    }
    return v;
}

void dem_nbhood_free(dem_nbhood_t *h)
{
    free(h->beg);
    free(h->end);
    free(h->id);
    free(h->w);
    memset(h, 0, sizeof *h);
}

/* one more neighbour j (weight lv) of the particle whose list is being written */
static void nbhood_add(dem_nbhood_t *h, long k, long j, double lv)
{
    if (k >= h->cap) {
        long c = h->cap > 0 ? 2 * h->cap : 256;
        h->id = realloc(h->id, (size_t)c * sizeof *h->id);
        h->w = realloc(h->w, (size_t)c * sizeof *h->w);
        if (!h->id || !h->w) die_local("dem: out of memory for %ld neighbourhood entries", c);
        h->cap = c;
    }
    h->id[k] = j;
    h->w[k] = lv;
}

void dem_local_fraction(const dem_t *d, double R, double *phi_by_id, double *ug_by_id, const double fallback[3],
                        dem_nbhood_t *nbh)
{
    const int n = d->n;
    long nk = 0; /* entries of nbh written */
    if (nbh) {
        const long nid = dem_id_bound(d);
        if (nbh->nid < nid) {
            free(nbh->beg);
            free(nbh->end);
            nbh->beg = xcalloc((size_t)nid, sizeof *nbh->beg);
            nbh->end = xcalloc((size_t)nid, sizeof *nbh->end);
            nbh->nid = nid;
        }
    }
    double rmax = 0; /* of the particles now (d->rmax is set by the first neighbour-list build) */
    for (int i = 0; i < n; i++) rmax = fmax(rmax, d->r[i]);
    const double reach = R + rmax;
    int nc[3];
    double cs[3];
    for (int a = 0; a < 3; a++) {
        nc[a] = (int)floor(d->L[a] / reach);
        if (nc[a] < 1) nc[a] = 1;
        if (nc[a] > 256) nc[a] = 256;
        cs[a] = d->L[a] / nc[a];
    }
    const long ncell = (long)nc[0] * nc[1] * nc[2];
    int *head = malloc((size_t)ncell * sizeof *head), *next = malloc((size_t)(n ? n : 1) * sizeof *next);
    int *cell = malloc(3 * (size_t)(n ? n : 1) * sizeof *cell);
    for (long c = 0; c < ncell; c++) head[c] = -1;
    for (int i = n - 1; i >= 0; i--) {
        long c = 0;
        for (int a = 2; a >= 0; a--) {
            int k = (int)floor((d->x[3 * i + a] - d->lo[a]) / cs[a]);
            k = k < 0 ? 0 : k >= nc[a] ? nc[a] - 1 : k;
            cell[3 * i + a] = k;
            c = c * nc[a] + k;
        }
        /* c was built z-major: index (kz * ny + ky) * nx + kx */
        next[i] = head[c];
        head[c] = i;
    }
    for (int i = 0; i < n; i++) {
        const double *xi = d->x + 3 * i;
        /* neighbour cells, each once (fewer than 3 cells along an axis: fewer offsets) */
        int off[3][3] = {{0}}, noff[3];
        for (int a = 0; a < 3; a++) {
            noff[a] = 0;
            for (int o = -1; o <= 1; o++) {
                int k = cell[3 * i + a] + o;
                if (d->periodic[a])
                    k = (k + nc[a]) % nc[a];
                else if (k < 0 || k >= nc[a])
                    continue;
                int dup = 0;
                for (int q = 0; q < noff[a]; q++) dup |= off[a][q] == k;
                if (!dup) off[a][noff[a]++] = k;
            }
        }
        double vs = 0, vu[3] = {0, 0, 0};
        if (nbh) nbh->beg[d->id[i]] = nk;
        for (int qz = 0; qz < noff[2]; qz++)
            for (int qy = 0; qy < noff[1]; qy++)
                for (int qx = 0; qx < noff[0]; qx++)
                    for (int j = head[((long)off[2][qz] * nc[1] + off[1][qy]) * nc[0] + off[0][qx]]; j >= 0; j = next[j]) {
                        if (j == i) continue;
                        double s2 = 0;
                        for (int a = 0; a < 3; a++) {
                            double dx = d->x[3 * j + a] - xi[a];
                            if (d->periodic[a]) dx -= d->L[a] * nearbyint(dx / d->L[a]);
                            s2 += dx * dx;
                        }
                        if (s2 < reach * reach) {
                            const double lv = lens_volume(R, d->r[j], sqrt(s2));
                            vs += lv;
                            if (nbh) nbhood_add(nbh, nk++, d->id[j], lv);
                            if (!d->fixed[j])
                                for (int a = 0; a < 3; a++) vu[a] += lv * d->v[3 * j + a];
                        }
                    }
        if (nbh) nbh->end[d->id[i]] = nk;
        const double vol = ball_in_box(d, xi, R) - 4.0 / 3.0 * M_PI * d->r[i] * d->r[i] * d->r[i];
        double phi = vol > 0 ? vs / vol : 0.0;
        phi_by_id[d->id[i]] = phi < 0.95 ? phi : 0.95;
        if (ug_by_id)
            for (int a = 0; a < 3; a++) ug_by_id[3 * d->id[i] + a] = vs > 0 ? vu[a] / vs : fallback[a];
    }
    free(head);
    free(next);
    free(cell);
}

double dem_fraction_radius(const dem_t *d, double rel, int *clipped)
{
    double dsum = 0;
    int nm = 0;
    for (int i = 0; i < d->n; i++)
        if (!d->fixed[i]) dsum += 2 * d->r[i], nm++;
    double rmax = 0;
    for (int i = 0; i < d->n; i++) rmax = fmax(rmax, d->r[i]);
    double R = rel * (nm ? dsum / nm : 2 * rmax);
    *clipped = 0;
    for (int a = 0; a < 3; a++)
        if (d->periodic[a] && R + rmax > 0.5 * d->L[a]) {
            R = 0.5 * d->L[a] - rmax;
            *clipped |= 1 << a;
        }
    return R;
}

/* φ of every particle (by id), in the drag's sampling ball. */
static void update_fraction(dem_t *d)
{
    dem_drag_t *D = &d->drag;
    if (!D->R) {
        int clipped;
        D->R = dem_fraction_radius(d, D->radius_rel, &clipped);
        for (int a = 0; a < 3; a++)
            if (clipped & (1 << a))
                warn("dem: the drag's sampling ball (%g mean diameters) does not fit in half the periodic length "
                     "along %c: radius %g m\n",
                     D->radius_rel, 'x' + a, D->R);
    }
    if (D->nphi < d->next_id) {
        D->phi = realloc(D->phi, (size_t)d->next_id * sizeof *D->phi);
        D->fd = realloc(D->fd, 3 * (size_t)d->next_id * sizeof *D->fd);
        memset(D->fd, 0, 3 * (size_t)d->next_id * sizeof *D->fd);
        D->ug = realloc(D->ug, 3 * (size_t)d->next_id * sizeof *D->ug);
        memset(D->ug, 0, 3 * (size_t)d->next_id * sizeof *D->ug);
        D->nphi = d->next_id;
    }
    dem_local_fraction(d, D->R, D->phi, D->ug, D->uf, NULL);
    D->phi_step = d->step;
}

/* The hindrance K(φ). */
static double hindrance(const dem_drag_t *D, double phi) { return D->closure == 0 ? 1.0 : pow(1.0 - phi, -D->n_rz); }

void dem_drag_impulses(dem_t *d, double dt)
{
    dem_drag_t *D = &d->drag;
    if (D->phi_step < 0 || D->nphi < d->next_id || (d->step % D->every == 0 && D->phi_step != d->step))
        update_fraction(d);
    double *restrict v = d->v, *restrict w = d->w;
    for (int i = 0; i < d->n; i++) {
        if (d->fixed[i]) continue;
        const double m = 1.0 / d->invm[i], r = d->r[i], vol = 4.0 / 3.0 * M_PI * r * r * r;
        const long k = d->id[i];
        const double beta = 6 * M_PI * D->mu * r * hindrance(D, D->phi[k]); /* 3π μ d K */
        const double a = dt * beta / m;                                     /* Δt/τ */
        const double *uf = D->uf_grains ? D->ug + 3 * k : D->uf;
        for (int c = 0; c < 3; c++) {
            const double fb = -D->rho_f * vol * d->gravity[c];
            const double vn = (v[3 * i + c] + dt * fb / m + a * uf[c]) / (1 + a);
            D->fd[3 * k + c] = m * (vn - v[3 * i + c]) / dt - fb; /* the drag of this step */
            v[3 * i + c] = vn;
        }
        if (D->rotation) {
            const double ar = dt * M_PI * D->mu * 8 * r * r * r * d->invI[i]; /* Δt/τ_r, 8π μ r³ = π μ d³ */
            for (int c = 0; c < 3; c++) w[3 * i + c] /= 1 + ar;
        }
    }
}

const double *dem_drag_fraction(const dem_t *d) { return d->drag.on ? d->drag.phi : NULL; }
const double *dem_drag_forces(const dem_t *d) { return d->drag.on ? d->drag.fd : NULL; }
