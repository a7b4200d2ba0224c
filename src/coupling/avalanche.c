/* avalanche.c — the measurements of a flow down a rough inclined plane
 * (avalanche.h; definitions in docs/theory.md §10). */
#include "avalanche.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "io.h"
#include "util.h"

/* Volume of a sphere of radius R centred at 0 below the height s. */
static double cap_below(double R, double s)
{
    if (s <= -R) return 0.0;
    if (s >= R) return 4.0 / 3.0 * M_PI * R * R * R;
    return M_PI * (R * R * s - s * s * s / 3.0 + 2.0 / 3.0 * R * R * R);
}

/* Volume of the sphere (centre c, radius R) between the heights a < b. */
static double slab_volume(double c, double R, double a, double b) { return cap_below(R, b - c) - cap_below(R, a - c); }

void avalanche_init(avalanche_t *a, const dem_t *d, int normal_axis, double bed_plane, double zmax,
                    const double L[3], const double g[3], double rho, double eta, double bin, double t1, double t2)
{
    memset(a, 0, sizeof *a);
    a->an = normal_axis;
    a->z0 = bed_plane;
    a->zmax = zmax;
    /* downslope: the in-plane axis along which gravity pulls most */
    int as = -1;
    for (int c = 0; c < 3; c++)
        if (c != normal_axis && (as < 0 || fabs(g[c]) > fabs(g[as]))) as = c;
    a->as = as;
    const int at = 3 - normal_axis - as;
    a->Ls = L[as];
    a->area = L[as] * L[at];
    a->g = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    a->sin_theta = a->g > 0 ? fabs(g[as]) / a->g : 0.0;
    /* the mean mobile grain, summed in the order of the ids: the DEM reorders its
     * particles, and a restart must find the same D to the last bit */
    const unsigned char *fx = dem_fixed(d);
    const double *r = dem_radii(d);
    const int n = dem_count(d);
    int *o = dem_id_order(d);
    int nm = 0;
    for (int k = 0; k < n; k++) {
        const int i = o[k];
        if (fx[i]) continue;
        a->D += 2 * r[i];
        a->rho_p += dem_density(d, i);
        nm++;
    }
    free(o);
    if (nm) {
        a->D /= nm;
        a->rho_p /= nm;
    }
    a->rho = rho;
    a->eta = eta;
    const double dr = a->rho_p - rho, gs = a->g * a->sin_theta, D = a->D;
    a->St = sqrt(a->rho_p * dr * gs * D * D * D) / (18.0 * M_SQRT2 * eta);
    a->r = sqrt(5.0 * a->rho_p / (3.0 * rho));
    a->Ar = rho * dr * a->g * D * D * D / (eta * eta);
    a->Tv = 18.0 * eta / (dr * gs * D);
    a->Ti = sqrt(rho * D / (2.0 * dr * gs));
    a->Tff = sqrt(2.0 * a->rho_p * D / (dr * gs));
    a->bin = bin > 0 ? bin : D / 5.0;
    a->nbin = (int)ceil((zmax - bed_plane) / a->bin - 1e-9);
    if (a->nbin < 1) a->nbin = 1;
    a->grain = xcalloc(4 * (size_t)a->nbin, sizeof(double));
    a->fluid = xcalloc(10 * (size_t)a->nbin, sizeof(double));
    a->scratch = xcalloc(12 * (size_t)a->nbin, sizeof(double));
    a->t1 = t1;
    a->t2 = t2;
}

void avalanche_free(avalanche_t *a)
{
    free(a->grain);
    free(a->fluid);
    free(a->work);
    free(a->scratch);
    a->grain = a->fluid = a->work = a->scratch = NULL;
}

/* The step [t − dt, t] counts in the window when its middle does. */
static int in_window(const avalanche_t *a, double t, double dt)
{
    const double m = t - 0.5 * dt;
    return dt > 0 && m >= a->t1 && m <= a->t2;
}

static double norm3(const double *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* The solid fraction of every grain averaged over the slab [z − D/2, z + D/2]
 * above the bed plane, from the particles (exact). */
typedef struct {
    const avalanche_t *a;
    const dem_t *d;
    double half; /* subtracted: the root is where the average is half its plateau */
} slab_avg_t;

static double slab_average(double z, void *ctx)
{
    const slab_avg_t *q = ctx;
    const avalanche_t *a = q->a;
    const double *x = dem_positions(q->d), *r = dem_radii(q->d);
    double v = 0.0;
    for (int i = 0; i < dem_count(q->d); i++)
        v += slab_volume(x[3 * i + a->an] - a->z0, r[i], z - 0.5 * a->D, z + 0.5 * a->D);
    return v / (a->area * a->D) - q->half;
}

/* Height of the bed above the bed plane: the highest point where the solid
 * fraction of every grain, averaged over a slab of one diameter, is half its
 * largest value.  The slab average at the bin centres (from the binned
 * profile) brackets the crossing; Brent's method (GSL) finds it on the exact
 * average. */
static double bed_height(avalanche_t *a, const dem_t *d, const double *phi)
{
    const int n = a->nbin, w = (int)fmax(1.0, floor(a->D / a->bin + 0.5));
    double *s = a->scratch + 11 * (size_t)n, smax = 0.0;
    for (int k = 0; k < n; k++) {
        s[k] = 0.0;
        int c = 0;
        for (int q = k - w / 2; q <= k + (w - 1) / 2; q++)
            if (q >= 0 && q < n) {
                s[k] += phi[q];
                c++;
            }
        s[k] /= c;
        if (c == w) smax = fmax(smax, s[k]); /* the plateau from whole slabs only */
    }
    int top = -1;
    for (int k = n - 1; k >= 0 && smax > 0; k--)
        if (s[k] >= 0.5 * smax) {
            top = k;
            break;
        }
    if (top < 0) return 0.0;
    slab_avg_t q = {a, d, 0.5 * smax};
    double lo = (top + 0.5) * a->bin, hi = fmin(lo + a->bin, a->zmax - a->z0);
    if (!(slab_average(lo, &q) >= 0 && slab_average(hi, &q) < 0)) return lo;
    gsl_function F = {slab_average, &q};
    gsl_root_fsolver *sv = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    gsl_root_fsolver_set(sv, &F, lo, hi);
    double h = 0.5 * (lo + hi);
    for (int it = 0; it < 100; it++) {
        if (gsl_root_fsolver_iterate(sv)) break;
        h = gsl_root_fsolver_root(sv);
        lo = gsl_root_fsolver_x_lower(sv);
        hi = gsl_root_fsolver_x_upper(sv);
        if (gsl_root_test_interval(lo, hi, 1e-13 * a->D, 0) == GSL_SUCCESS) break;
    }
    gsl_root_fsolver_free(sv);
    return h;
}

void avalanche_sample_grains(avalanche_t *a, dem_t *d, const dem_force_stats_t *fs, const double *Fh, double t,
                             double dt)
{
    const int n = dem_count(d), nb = a->nbin, an = a->an, as = a->as;
    const double *x = dem_positions(d), *r = dem_radii(d), *fc = dem_contact_forces(d);
    const double *fl = dem_lubrication_forces(d);
    const unsigned char *fx = dem_fixed(d);
    const long *id = dem_ids(d);
    double *prof = a->scratch; /* V, V u per slab of this step */
    memset(prof, 0, 4 * (size_t)nb * sizeof(double));
    double vm = 0, vu = 0, st = 0, Fc = 0, Fl = 0, Fhs = 0;
    int nm = 0;
    for (int i = 0; i < n; i++) {
        double u[3] = {0, 0, 0};
        if (!fx[i]) dem_full_velocity(d, i, u);
        const double R = r[i], c = x[3 * i + an] - a->z0;
        int k0 = (int)floor((c - R) / a->bin), k1 = (int)floor((c + R) / a->bin);
        if (k0 < 0) k0 = 0;
        if (k1 > nb - 1) k1 = nb - 1;
        for (int k = k0; k <= k1; k++) {
            const double v = slab_volume(c, R, k * a->bin, (k + 1) * a->bin);
            prof[4 * k] += v;
            for (int q = 0; q < 3; q++) prof[4 * k + 1 + q] += v * u[q];
        }
        if (fx[i]) continue;
        const double V = 4.0 / 3.0 * M_PI * R * R * R;
        vm += V;
        vu += V * u[as];
        st += dem_density(d, i) * norm3(u) * 2 * R;
        Fc += norm3(fc + 3 * i);
        if (fl) Fl += norm3(fl + 3 * i);
        if (Fh) Fhs += norm3(Fh + 3 * id[i]);
        nm++;
    }
    double *phi = a->scratch + 10 * (size_t)nb;
    for (int k = 0; k < nb; k++) phi[k] = prof[4 * k] / (a->area * a->bin);
    const double h = bed_height(a, d, phi);
    /* global compacity between D/2 and h − D/2 (the fixed grains and the free surface left out) */
    double vin = 0.0;
    const double lo = 0.5 * a->D, hi = h - 0.5 * a->D;
    if (hi > lo)
        for (int i = 0; i < n; i++)
            if (!fx[i]) vin += slab_volume(x[3 * i + an] - a->z0, r[i], lo, hi);
    double *now = a->now;
    now[AV_Q] = vu / a->Ls;
    now[AV_H] = h;
    now[AV_PHI] = hi > lo ? vin / (a->area * (hi - lo)) : 0.0;
    now[AV_U] = vm > 0 ? vu / vm : 0.0;
    now[AV_ST_MEAN] = nm ? st / (9.0 * a->eta * nm) : 0.0;
    now[AV_FC_PAIR] = fs && fs->contacts > 0 ? fs->contact_norm / fs->contacts : 0.0;
    now[AV_FLUB_PAIR] = fs && fs->lubricated > 0 ? fs->lub_norm / fs->lubricated : 0.0;
    now[AV_FC_GRAIN] = nm ? Fc / nm : 0.0;
    now[AV_FLUB_GRAIN] = nm ? Fl / nm : 0.0;
    now[AV_FH_GRAIN] = nm ? Fhs / nm : 0.0;
    if (in_window(a, t, dt)) {
        a->tw += dt;
        for (int c = 0; c < AV_NCOL; c++) a->scal[c] += dt * now[c];
        for (long q = 0; q < 4L * nb; q++) a->grain[q] += dt * prof[q];
    }
}

void avalanche_sample_fluid(avalanche_t *a, const fluid_t *f, const ibm_t *ibm, double t, double dt)
{
    if (!in_window(a, t, dt)) return;
    const grid_t *g = f->g;
    const int nb = a->nbin, an = a->an;
    if (!a->work) a->work = xcalloc((size_t)g->nalloc, sizeof(double));
    if (ibm)
        ibm_solid_fraction_cell(ibm, a->work);
    else
        memset(a->work, 0, (size_t)g->nalloc * sizeof(double));
    double *acc = a->scratch; /* the slab sums of this step */
    memset(acc, 0, 10 * (size_t)nb * sizeof(double));
    const long off[3] = {g->sx, g->sy, 1};
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                const double zc[3] = {g->xc[i], grid_yc(g, j), grid_zc(g, k)};
                const int b = (int)floor((zc[an] - a->z0) / a->bin);
                if (b < 0 || b >= nb) continue;
                const long c = G_IDX(g, i, j, k);
                double u[3];
                for (int q = 0; q < 3; q++) u[q] = f->u[q] ? 0.5 * (f->u[q][c] + f->u[q][c - off[q]]) : 0.0;
                const double W = (1.0 - a->work[c]) * g->dxf[i] * g->dy * g->dz;
                double *s = acc + 10 * b;
                s[0] += W;
                s[1] += W * u[0];
                s[2] += W * u[1];
                s[3] += W * u[2];
                s[4] += W * u[0] * u[0];
                s[5] += W * u[1] * u[1];
                s[6] += W * u[2] * u[2];
                s[7] += W * u[0] * u[1];
                s[8] += W * u[0] * u[2];
                s[9] += W * u[1] * u[2];
            }
    MPI_Allreduce(MPI_IN_PLACE, acc, 10 * nb, MPI_DOUBLE, MPI_SUM, g->comm);
    a->tw_fluid += dt;
    for (long q = 0; q < 10L * nb; q++) a->fluid[q] += dt * acc[q];
}

double avalanche_mean(const avalanche_t *a, int col) { return a->tw > 0 ? a->scal[col] / a->tw : 0.0; }

double avalanche_flow_time(const avalanche_t *a)
{
    const double Q = avalanche_mean(a, AV_Q), h = avalanche_mean(a, AV_H);
    return Q > 0 ? a->area * h / Q : INFINITY;
}

int avalanche_write_profiles(const avalanche_t *a, const char *path)
{
    char tmp[IO_PATH_MAX + 16];
    FILE *f = atomic_open(path, tmp, sizeof tmp);
    if (!f) return -1;
    static const char ax[] = "xyz";
    fprintf(f, "# profiles across the bed over t = [%.9g, %.9g] s (%.9g s sampled; fluid %.9g s), bins of %.9g m "
               "along %c from the bed plane %c = %.9g m, downslope %c; D = %.9g m\n",
            a->t1, a->t2, a->tw, a->tw_fluid, a->bin, ax[a->an], ax[a->an], a->z0, ax[a->as], a->D);
    fprintf(f, "z,z_over_D,phi,Ug_x,Ug_y,Ug_z,phi_fluid,Uf_x,Uf_y,Uf_z,uu,vv,ww,uv,uw,vw,tau_f\n");
    const double nu = a->eta / a->rho;
    for (int k = 0; k < a->nbin; k++) {
        const double *g = a->grain + 4 * k, *s = a->fluid + 10 * k;
        const double z = (k + 0.5) * a->bin;
        const double phi = a->tw > 0 ? g[0] / (a->tw * a->area * a->bin) : 0.0;
        double Ug[3], Uf[3] = {0, 0, 0}, R[6] = {0, 0, 0, 0, 0, 0};
        for (int q = 0; q < 3; q++) Ug[q] = g[0] > 0 ? g[1 + q] / g[0] : 0.0;
        const double pf = a->tw_fluid > 0 ? s[0] / (a->tw_fluid * a->area * a->bin) : 0.0;
        if (s[0] > 0) {
            for (int q = 0; q < 3; q++) Uf[q] = s[1 + q] / s[0];
            static const int p[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
            for (int q = 0; q < 6; q++) R[q] = s[4 + q] / s[0] - Uf[p[q][0]] * Uf[p[q][1]];
        }
        /* viscous stress ν d⟨U_s⟩_f/dz (centred, one-sided at the ends) */
        double tau = 0.0;
        const int km = k > 0 ? k - 1 : k, kp = k + 1 < a->nbin ? k + 1 : k;
        const double *sm = a->fluid + 10 * km, *sp = a->fluid + 10 * kp;
        if (kp > km && sm[0] > 0 && sp[0] > 0)
            tau = nu * (sp[1 + a->as] / sp[0] - sm[1 + a->as] / sm[0]) / ((kp - km) * a->bin);
        fprintf(f, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", z, z / a->D, phi,
                Ug[0], Ug[1], Ug[2], pf, Uf[0], Uf[1], Uf[2], R[0], R[1], R[2], R[3], R[4], R[5], tau);
    }
    return atomic_commit(f, tmp, path);
}

void avalanche_state_write(const avalanche_t *a, hid_t g)
{
    double s[2 + AV_NCOL];
    s[0] = a->tw;
    s[1] = a->tw_fluid;
    memcpy(s + 2, a->scal, sizeof a->scal);
    io_h5_write_array(g, "sums", 2 + AV_NCOL, s);
    io_h5_write_array(g, "grain", 4L * a->nbin, a->grain);
    io_h5_write_array(g, "fluid", 10L * a->nbin, a->fluid);
}

int avalanche_state_read(avalanche_t *a, hid_t g)
{
    double s[2 + AV_NCOL];
    if (io_h5_read_array(g, "sums", 2 + AV_NCOL, s) != 2 + AV_NCOL) return -1;
    if (io_h5_read_array(g, "grain", 4L * a->nbin, a->grain) != 4L * a->nbin) return -1;
    if (io_h5_read_array(g, "fluid", 10L * a->nbin, a->fluid) != 10L * a->nbin) return -1;
    a->tw = s[0];
    a->tw_fluid = s[1];
    memcpy(a->scal, s + 2, sizeof a->scal);
    return 0;
}

void avalanche_copy_sums(avalanche_t *dst, const avalanche_t *src)
{
    dst->tw = src->tw;
    dst->tw_fluid = src->tw_fluid;
    memcpy(dst->scal, src->scal, sizeof src->scal);
    memcpy(dst->now, src->now, sizeof src->now);
    memcpy(dst->grain, src->grain, 4 * (size_t)src->nbin * sizeof(double));
    memcpy(dst->fluid, src->fluid, 10 * (size_t)src->nbin * sizeof(double));
}
