/* sim_oedometer.c — Terzaghi's consolidation in an oedometer as a part of a
 * run ([oedometer]; cases/consolidation/, docs/validation.md "Terzaghi
 * consolidation"; catalano_pfv.md §2.2 and §5.4).
 *
 * The scene is the DEM (a packing settled by [packing]) with the pore network
 * ([porenet], p = 0 on its top face) and a piston: a wall of [walls] that
 * becomes load-controlled.  Before the first step this part runs the dry
 * protocol on the DEM alone:
 *  1. the piston is brought onto the packing and loaded to σ₀ (a ramp), then
 *     to σ₀ + k Δσ and back to σ₀ (state S₀: the load step is a reloading,
 *     nearly elastic), each time to rest (the piston moves by less than
 *     rest_tolerance in 100 DEM steps; the local damping of [dem] vanishes
 *     there);
 *  2. dry: the step Δσ on S₀ gives the settlement ΔH and the oedometric
 *     modulus E_oed = Δσ H/ΔH (heights of the centres of the grains touching
 *     the piston in S₀: the piston's own contacts, at the drained face, would
 *     add a compliance that drains at once);
 *  3. a permeameter on S₀ (p = 1 at the base, 0 on the top face of the
 *     network, drained_layer mean radii above the piston): κ from the flux and
 *     the mean gradient of the central half of the column, and the drainage
 *     path L, where the central pressure line reaches the top pressure (the
 *     loose layer under the piston is about as open as the fluid above it);
 *     C_v = κ E_oed/μ;
 * then the run starts from S₀ with the load σ₀ + Δσ on the saturated sample:
 * the DEM and the pore network advance as in any coupled run, and this part
 * records, after every step, T_v = C_v t/L², the excess pore pressure at
 * mid-height and at the base (bands of 0.1 H), the degree of consolidation
 * U = settlement/ΔH and that of a marker layer (the grains marker_lo to
 * marker_hi mean diameters below the piston in S₀, tracked by identity, over
 * their dry settlement), against Terzaghi's series.  The run stops at
 * T_v = tv_end.  Outputs: series.csv columns, pressure_profile.csv (p/Δσ in
 * 20 bands of H at each T_v point), summary.json (E_oed, κ, κ/d², C_v, L, the
 * values at T_v = 0.1, 0.2, 0.5, 1 with Terzaghi's and the deviations, Taylor's
 * correction of the initial compression, the cost of a coupled step against a
 * dry one); postproc/plot_consolidation.py draws them.  A restart continues
 * exactly (the protocol's results, the sets of grains and the records are in
 * the checkpoint).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem.h"
#include "fluid_model.h"
#include "io.h"
#include "porenet.h"
#include "sim.h"
#include "util.h"

static const cfg_key_t oedo_keys[] = {
    {"oedometer", "piston", CFG_STRING, "wall1", 1, 0, NULL, "the wall of [walls] that becomes the load-controlled piston"},
    {"oedometer", "preload", CFG_DOUBLE, "2000", 0, 1e12, NULL, "sigma_0 (Pa): the load the sample is prepared under"},
    {"oedometer", "load_step", CFG_DOUBLE, "500", 1e-12, 1e12, NULL, "delta sigma (Pa): the step of the consolidation"},
    {"oedometer", "overconsolidation", CFG_DOUBLE, "2", 0, 1e6, NULL,
     "the sample is loaded to sigma_0 + this x delta sigma and unloaded to sigma_0 first (the step is a reloading)"},
    {"oedometer", "ramp", CFG_INT, "20", 1, 100000, NULL,
     "the first load sigma_0 is raised over this many x 100 DEM steps (at once the piston would overload the "
     "highest grains)"},
    {"oedometer", "dry_ramp", CFG_INT, "0", 0, 100000, NULL,
     "the dry load step raised over this many x 100 DEM steps (0: at once, as on the saturated sample)"},
    {"oedometer", "rest_tolerance", CFG_DOUBLE, "1e-9", 1e-300, 1e300, NULL,
     "at rest when the piston moves by less than this (m) in 100 DEM steps"},
    {"oedometer", "piston_mass", CFG_DOUBLE, "0.1", 1e-6, 1e6, NULL, "mass of the piston over that of the grains"},
    {"oedometer", "drained_layer", CFG_DOUBLE, "4", 0, 1e3, NULL,
     "top face of the network (p = 0) this many mean radii above the piston in S_0"},
    {"oedometer", "drainage_path", CFG_ENUM, "permeameter", 1, 0, "permeameter|height",
     "L of T_v = C_v t/L^2: where the permeameter's central pressure line reaches the top pressure, or the height H"},
    {"oedometer", "modulus", CFG_ENUM, "column", 1, 0, "column|below_marker",
     "E_oed of C_v: of the whole column (delta sigma H/delta H) or of the column below the marker layer"},
    {"oedometer", "marker_lo", CFG_DOUBLE, "1", 0, 1e3, NULL,
     "marker layer: the grains whose centres are marker_lo to marker_hi mean diameters below the piston in S_0"},
    {"oedometer", "marker_hi", CFG_DOUBLE, "2", 0, 1e3, NULL, "see marker_lo"},
    {"oedometer", "taylor_lo", CFG_DOUBLE, "0.02", 0, 10, NULL,
     "Taylor's sqrt(t) correction of the initial compression: U fitted against sqrt(T_v) on taylor_lo <= T_v <= taylor_hi"},
    {"oedometer", "taylor_hi", CFG_DOUBLE, "0.2", 0, 10, NULL, "see taylor_lo"},
    {"oedometer", "tv_end", CFG_DOUBLE, "1", 1e-6, 1e6, NULL, "the run stops at this T_v"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void sim_oedometer_register_keys(void) { cfg_schema_add(oedo_keys); }

#define NTV 4
#define NBAND 20
static const double TV[NTV] = {0.1, 0.2, 0.5, 1.0};

/* ---- Terzaghi's series (catalano_pfv.md §2.2): drained face at z = L, sealed base at z = 0,
 * M = (2m+1)π/2: p(z)/Δσ = Σ (2/M) sin(M (L − z)/L) e^{−M² T}, U = 1 − Σ (2/M²) e^{−M² T}.  The
 * sub-layer 0 ≤ z ≤ ζ_m L of the same layer (the marker's): U_m = 1 − Σ 2 cos(M (1 − ζ_m))/(M² ζ_m)
 * e^{−M² T}, its compression over its drained compression with the strain (Δσ − p)/E_oed. */
double terzaghi_p(double zeta, double T)
{
    double s = 0;
    for (int m = 0; m < 200; m++) {
        const double M = (2 * m + 1) * M_PI / 2;
        s += 2 / M * sin(M * (1 - zeta)) * exp(-M * M * T);
    }
    return s;
}

double terzaghi_U_sub(double zeta_m, double T)
{
    double s = 0;
    for (int m = 0; m < 200; m++) {
        const double M = (2 * m + 1) * M_PI / 2;
        s += 2 * cos(M * (1 - zeta_m)) / (M * M * zeta_m) * exp(-M * M * T);
    }
    return 1 - s;
}

double terzaghi_U(double T) { return terzaghi_U_sub(1.0, T); }

typedef struct {
    sim_t *sim;
    cfg_t *cfg;
    dem_t *d;
    int piston;
    double sigma0, dsig, ocr, rest_tol, piston_mass, layer, marker_lo, marker_hi, taylor_lo, taylor_hi, tv_end;
    int ramp, dry_ramp, path_is_h, cv_below_marker;
    int done_protocol;
    /* the protocol's results */
    double area, mass, rm, H, dH, Eoed, zpiston, hnet, kappa, mu, L, zdrain, cv, dH_piston, dH_marker;
    double z0, zm0;           /* heights of the surface and of the marker layer in S₀ */
    double t_dry;             /* CPU time per dry DEM step */
    long nid;                 /* ids covered by the sets */
    double *top, *marker;     /* by particle id: 1 in the set (doubles: checkpoint arrays) */
    double ntop, nmarker;
    /* the records */
    double T, pm, pb, U, Um, zmid, zbase, pmax;
    double tsum[5];           /* Σ x, Σ U, Σ x², Σ x U, n of Taylor's window (x = √T_v) */
    int next;                 /* T_v points reached */
    double rec[NTV][6];       /* at each T_v point: p_mid, p_base, U, U_marker, 1 − mean p below the marker, T_v */
    double prof[NTV][NBAND];  /* p/Δσ in bands of H/NBAND at each T_v point */
    double zprof[NBAND];      /* mean height of the pores of each band (last record) */
    long steps;
    double cpu0, cpu_run;     /* CPU time of the coupled steps (this run's part and the restored one) */
} oedo_t;

static const char *const oedo_cols[] = {"oedo_Tv", "oedo_p_mid", "oedo_p_base", "oedo_U", "oedo_U_marker", "oedo_piston_z"};

/* ---- the DEM side ---- */

static void set_load(oedo_t *o, double sigma) { dem_wall_set_load(o->d, o->piston, sigma * o->area, o->mass); }

static double piston_z(const oedo_t *o)
{
    double p[3];
    dem_wall_position(o->d, o->piston, p);
    return p[2];
}

/* Mean centre height of the grains of a set (by particle id). */
static double set_mean_z(const oedo_t *o, const double *set, double count)
{
    const int n = dem_count(o->d);
    const long *id = dem_ids(o->d);
    const double *x = dem_positions(o->d);
    double h = 0;
    for (int i = 0; i < n; i++)
        if (set[id[i]] != 0) h += x[3 * i + 2];
    return h / count;
}

static double surface_z(const oedo_t *o) { return set_mean_z(o, o->top, o->ntop); }
static double marker_z(const oedo_t *o) { return set_mean_z(o, o->marker, o->nmarker); }

static double dry_cpu;
static long dry_steps;

static void dry_run(oedo_t *o, long n)
{
    const double c = cputime();
    /* before the first step: parameters that cannot carry the load are bad input */
    if (dem_run_steps(o->d, n) != DEM_OK)
        cfg_fail(o->cfg, "oedometer", "preload", "the dry sample under the load: %s", dem_error(o->d));
    dry_cpu += cputime() - c;
    dry_steps += n;
}

/* To rest under the current load: the piston moves by less than the
 * tolerance in 100 steps.  Returns the height of the sample (the surface
 * grains' once they are known, the piston's before). */
static double relax(oedo_t *o)
{
    double h = piston_z(o);
    for (int k = 0; k < 5000; k++) {
        dry_run(o, 100);
        const double h1 = piston_z(o);
        if (k > 3 && fabs(h1 - h) < o->rest_tol) return o->ntop > 0 ? surface_z(o) : h1;
        h = h1;
    }
    cfg_fail(o->cfg, "oedometer", "rest_tolerance", "the dry sample did not come to rest (%g m per 100 steps)",
             o->rest_tol);
}

/* The load raised linearly to sigma over n × 100 steps (n = 0: at once), then to rest. */
static double load_to(oedo_t *o, double from, double sigma, int n)
{
    for (int k = 1; k < n; k++) {
        set_load(o, from + (sigma - from) * k / n);
        dry_run(o, 100);
    }
    set_load(o, sigma);
    return relax(o);
}

/* Mean pore pressure in the band zlo < z < zhi, and the mean height of its pores. */
static double band_pressure(const pn_model_t *m, double zlo, double zhi, double *zmean)
{
    double s = 0, c = 0, sz = 0;
    for (int i = 0; i < m->net.npore; i++) {
        const double z = m->net.P[3 * i + 2];
        if (z > zlo && z < zhi) s += m->p[i], sz += z, c++;
    }
    if (zmean) *zmean = c > 0 ? sz / c : 0.5 * (zlo + zhi);
    return c > 0 ? s / c : 0.0;
}

/* Permeameter on S₀ (the DEM holds S₀): κ and the drained face. */
static void permeameter(oedo_t *o)
{
    pn_model_t m;
    pn_model_from_config(o->cfg, &m);
    m.margin_warned = 3; /* the run's network warns */
    m.dom.hi[2] = o->hnet;
    m.dom.bc[4] = PN_BC_PRESSURE;
    m.dom.bc_value[4] = 1;
    m.dom.bc[5] = PN_BC_PRESSURE;
    m.dom.bc_value[5] = 0;
    const double g0[3] = {0, 0, 0};
    if (pn_model_couple_dem(&m, o->d, g0, 0.0)) die("oedometer: the permeameter: %s", m.err);
    double q[6];
    pn_face_fluxes(&m.dom, &m.net, m.p, q);
    /* mean gradient in the central half of the column */
    double sz = 0, sp = 0, szz = 0, szp = 0, c = 0;
    for (int i = 0; i < m.net.npore; i++) {
        const double z = m.net.P[3 * i + 2];
        if (z < 0.25 * o->H || z > 0.75 * o->H) continue;
        sz += z, sp += m.p[i], szz += z * z, szp += z * m.p[i], c++;
    }
    const double grad = (c * szp - sz * sp) / (c * szz - sz * sz);
    o->zdrain = -((sp - grad * sz) / c) / grad;
    o->mu = m.prm.mu;
    o->kappa = o->mu * (q[4] / o->area) / -grad;
    pn_model_free(&m);
}

static pn_model_t *network(oedo_t *o) { return sim_porenet_model(o->sim); }

/* The dry protocol (the header), then S₀ with the load step on, for the coupled run. */
static void protocol(void *ctx)
{
    oedo_t *o = ctx;
    if (o->done_protocol) return;
    o->done_protocol = 1;
    o->d = sim_dem_engine(o->sim);
    dem_t *d = o->d;
    o->piston = dem_wall_find(d, cfg_string(o->cfg, "oedometer", "piston"));
    if (o->piston < 0) cfg_fail(o->cfg, "oedometer", "piston", "no wall of that name in [walls]");
    const int n = dem_count(d);
    const double *x = dem_positions(d), *r = dem_radii(d);
    double ztop = -INFINITY, mtot = 0;
    o->rm = 0;
    for (int i = 0; i < n; i++) ztop = fmax(ztop, x[3 * i + 2] + r[i]), o->rm += r[i] / n, mtot += dem_mass(d, i);
    double L3[3];
    cfg_vec3(o->cfg, "domain", "length", L3);
    o->area = L3[0] * L3[1];
    o->mass = o->piston_mass * mtot;
    o->nid = 0;
    for (int i = 0; i < n; i++) o->nid = dem_ids(d)[i] + 1 > o->nid ? dem_ids(d)[i] + 1 : o->nid;
    o->top = xcalloc((size_t)o->nid, sizeof *o->top);
    o->marker = xcalloc((size_t)o->nid, sizeof *o->marker);
    const double c0 = wtime();
    {
        const double p[3] = {0, 0, ztop};
        dem_wall_set_point(d, o->piston, p); /* onto the settled packing */
    }
    msg("oedometer: loading the dry sample to sigma_0 = %g Pa, %g Pa, back to %g Pa\n", o->sigma0,
        o->sigma0 + o->ocr * o->dsig, o->sigma0);
    load_to(o, 0, o->sigma0, o->ramp);
    load_to(o, o->sigma0, o->sigma0 + o->ocr * o->dsig, 0);
    load_to(o, o->sigma0 + o->ocr * o->dsig, o->sigma0, 0);
    /* S₀: the grains touching the piston, the marker layer */
    o->zpiston = piston_z(o);
    x = dem_positions(d);
    r = dem_radii(d);
    const long *id = dem_ids(d);
    for (int i = 0; i < dem_count(d); i++) {
        if (x[3 * i + 2] + r[i] > o->zpiston) o->top[id[i]] = 1, o->ntop++;
        if (x[3 * i + 2] >= o->zpiston - 2 * o->rm * o->marker_hi && x[3 * i + 2] < o->zpiston - 2 * o->rm * o->marker_lo)
            o->marker[id[i]] = 1, o->nmarker++;
    }
    if (o->ntop == 0 || o->nmarker == 0)
        cfg_fail(o->cfg, "oedometer", "marker_lo", "no grain under the piston or in the marker layer");
    o->z0 = surface_z(o);
    o->zm0 = marker_z(o);
    o->H = o->z0;
    char s0[IO_PATH_MAX + 32];
    io_outdir_path(&o->sim->out, "oedometer_s0.h5", s0, sizeof s0);
    dem_write_checkpoint(d, s0);
    /* the dry load step */
    dry_cpu = 0;
    dry_steps = 0;
    const double h1 = load_to(o, o->sigma0, o->sigma0 + o->dsig, o->dry_ramp);
    o->t_dry = dry_cpu / dry_steps;
    o->dH = o->H - h1;
    o->dH_piston = o->zpiston - piston_z(o);
    o->dH_marker = o->zm0 - marker_z(o);
    o->Eoed = o->dsig * o->H / o->dH;
    /* the permeameter on S₀ */
    dem_read_checkpoint(d, s0);
    o->hnet = o->zpiston + o->layer * o->rm;
    permeameter(o);
    o->L = o->path_is_h ? o->H : o->zdrain;
    const double E = o->cv_below_marker ? o->dsig * o->zm0 / o->dH_marker : o->Eoed;
    o->cv = o->kappa * E / o->mu;
    /* the saturated sample: S₀ again, the load step on, time from 0 */
    dem_read_checkpoint(d, s0);
    dem_set_time(d, 0.0);
    if (dem_advance(d, 0.0) != DEM_OK) die("oedometer: %s", dem_error(d));
    set_load(o, o->sigma0 + o->dsig);
    network(o)->dom.hi[2] = o->hnet;
    msg("oedometer: S_0 (%.1f s): H = %.5g m (%g grains under the piston), dry step dH = %.4g m, E_oed = %.5g Pa; "
        "permeameter: kappa = %.5g m^2 (kappa/d^2 = %.4g), drainage path L = %.5g m (L/H = %.4f), C_v = %.5g m^2/s\n",
        wtime() - c0, o->H, o->ntop, o->dH, o->Eoed, o->kappa, o->kappa / (4 * o->rm * o->rm), o->L, o->zdrain / o->H,
        o->cv);
    o->cpu0 = cputime();
}

/* ---- the records of the coupled run ---- */

static void write_profiles(const oedo_t *o)
{
    if (mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 32];
    io_outdir_path(&o->sim->out, "pressure_profile.csv", path, sizeof path);
    FILE *f = fopen(path, "w");
    if (!f) die_local("cannot write %s", path);
    fprintf(f, "Tv_target,Tv,z_over_L,p_over_dsigma,terzaghi\n");
    for (int k = 0; k < o->next; k++)
        for (int b = 0; b < NBAND; b++) {
            const double z = (b + 0.5) * o->H / NBAND / o->L;
            fprintf(f, "%g,%.6g,%.6g,%.6g,%.6g\n", TV[k], o->rec[k][5], z, o->prof[k][b], z <= 1 ? terzaghi_p(z, o->rec[k][5]) : 0.0);
        }
    if (fclose(f) != 0) die_local("cannot write %s", path);
}

static void record(oedo_t *o)
{
    const long step = o->sim->step + 1; /* called from the advance, before the driver counts the step */
    const pn_model_t *m = network(o);
    o->T = o->cv * dem_time(o->d) / (o->L * o->L);
    o->pm = band_pressure(m, 0.45 * o->H, 0.55 * o->H, &o->zmid) / o->dsig;
    o->pb = band_pressure(m, -1, 0.1 * o->H, &o->zbase) / o->dsig;
    o->U = (o->z0 - surface_z(o)) / o->dH;
    o->Um = (o->zm0 - marker_z(o)) / o->dH_marker;
    o->pmax = fmax(o->pmax, o->pb);
    o->steps++;
    if (o->T >= o->taylor_lo && o->T <= o->taylor_hi) {
        const double x = sqrt(o->T);
        o->tsum[0] += x, o->tsum[1] += o->U, o->tsum[2] += x * x, o->tsum[3] += x * o->U, o->tsum[4]++;
    }
    if (o->next < NTV && o->T >= TV[o->next]) {
        double *r = o->rec[o->next];
        r[0] = o->pm, r[1] = o->pb, r[2] = o->U, r[3] = o->Um;
        r[4] = 1 - band_pressure(m, -1, o->zm0, NULL) / o->dsig;
        r[5] = o->T;
        for (int b = 0; b < NBAND; b++)
            o->prof[o->next][b] = band_pressure(m, b * o->H / NBAND, (b + 1) * o->H / NBAND, &o->zprof[b]) / o->dsig;
        o->next++;
        write_profiles(o);
        msg("oedometer: T_v = %.3g at step %ld: p_mid/dsigma %.4f (Terzaghi %.4f), p_base/dsigma %.4f (%.4f), "
            "U %.4f (%.4f), U_marker %.4f (%.4f)\n",
            o->T, step, o->pm, terzaghi_p(o->zmid / o->L, o->T), o->pb, terzaghi_p(o->zbase / o->L, o->T), o->U,
            terzaghi_U(o->T), o->Um, terzaghi_U_sub(o->zm0 / o->L, o->T));
    }
}

/* ---- the part ---- */

/* After the DEM and the network advanced (this part comes after them). */
static void part_advance(void *ctx, double dt)
{
    (void)dt;
    oedo_t *o = ctx;
    protocol(o);
    record(o);
}

static void part_diagnostics(void *ctx, double *c)
{
    oedo_t *o = ctx;
    protocol(o);
    c[0] = o->T;
    c[1] = o->pm;
    c[2] = o->pb;
    c[3] = o->U;
    c[4] = o->Um;
    c[5] = piston_z(o);
}

static int part_done(void *ctx)
{
    const oedo_t *o = ctx;
    return o->done_protocol && o->T >= o->tv_end;
}

/* Taylor's √t construction: the straight part of U against √T_v extrapolated to t = 0 gives the
 * corrected zero d_s/ΔH (0 if the window was not reached); its slope in *slope. */
static double taylor(const oedo_t *o, double *slope)
{
    const double *s = o->tsum;
    *slope = NAN;
    if (s[4] < 2) return 0;
    *slope = (s[4] * s[3] - s[0] * s[1]) / (s[4] * s[2] - s[0] * s[0]);
    return (s[1] - *slope * s[0]) / s[4];
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    oedo_t *o = ctx;
    if (!o->done_protocol) return;
    char key[160];
#define KEY(...) (snprintf(key, sizeof key, __VA_ARGS__), key)
    io_summary_double(y, KEY("%s.spheres_under_piston", prefix), o->ntop);
    io_summary_double(y, KEY("%s.height", prefix), o->H);
    io_summary_double(y, KEY("%s.dry_settlement", prefix), o->dH);
    io_summary_double(y, KEY("%s.E_oed", prefix), o->Eoed);
    io_summary_double(y, KEY("%s.E_oed_piston", prefix), o->dsig * o->zpiston / o->dH_piston);
    io_summary_double(y, KEY("%s.strain", prefix), o->dH / o->H);
    io_summary_double(y, KEY("%s.kappa", prefix), o->kappa);
    io_summary_double(y, KEY("%s.kappa_over_d2", prefix), o->kappa / (4 * o->rm * o->rm));
    io_summary_double(y, KEY("%s.viscosity", prefix), o->mu);
    io_summary_double(y, KEY("%s.C_v", prefix), o->cv);
    io_summary_double(y, KEY("%s.drainage_path", prefix), o->L);
    io_summary_double(y, KEY("%s.drained_face_over_H", prefix), o->zdrain / o->H);
    io_summary_double(y, KEY("%s.zeta_mid", prefix), o->zmid / o->L);
    io_summary_double(y, KEY("%s.zeta_base", prefix), o->zbase / o->L);
    io_summary_double(y, KEY("%s.zeta_marker", prefix), o->zm0 / o->L);
    io_summary_double(y, KEY("%s.marker_grains", prefix), o->nmarker);
    io_summary_double(y, KEY("%s.marker_dry_settlement_over_dH", prefix), o->dH_marker / o->dH);
    io_summary_double(y, KEY("%s.p_base_max", prefix), o->pmax);
    io_summary_double(y, KEY("%s.Tv", prefix), o->T);
    io_summary_long(y, KEY("%s.coupled_steps", prefix), o->steps);
    double slope;
    const double ds = taylor(o, &slope);
    io_summary_double(y, KEY("%s.taylor_zero", prefix), ds);
    io_summary_double(y, KEY("%s.taylor_slope", prefix), slope);
    double dev = 0, dev_raw = 0, dev_marker = 0;
    for (int k = 0; k < o->next; k++) {
        const double *r = o->rec[k], T = r[5];
        const double tp = terzaghi_p(o->zmid / o->L, T), tb = terzaghi_p(o->zbase / o->L, T), tu = terzaghi_U(T);
        const double tm = terzaghi_U_sub(o->zm0 / o->L, T), uc = (r[2] - ds) / (1 - ds);
        const char *tv = k == 0 ? "0_1" : k == 1 ? "0_2" : k == 2 ? "0_5" : "1"; /* (a dot nests the key) */
        io_summary_double(y, KEY("%s.Tv_%s.p_mid", prefix, tv), r[0]);
        io_summary_double(y, KEY("%s.Tv_%s.p_mid_terzaghi", prefix, tv), tp);
        io_summary_double(y, KEY("%s.Tv_%s.p_base", prefix, tv), r[1]);
        io_summary_double(y, KEY("%s.Tv_%s.p_base_terzaghi", prefix, tv), tb);
        io_summary_double(y, KEY("%s.Tv_%s.U", prefix, tv), r[2]);
        io_summary_double(y, KEY("%s.Tv_%s.U_corrected", prefix, tv), uc);
        io_summary_double(y, KEY("%s.Tv_%s.U_terzaghi", prefix, tv), tu);
        io_summary_double(y, KEY("%s.Tv_%s.U_marker", prefix, tv), r[3]);
        io_summary_double(y, KEY("%s.Tv_%s.U_marker_terzaghi", prefix, tv), tm);
        io_summary_double(y, KEY("%s.Tv_%s.U_marker_effective_stress", prefix, tv), r[4]);
        dev = fmax(dev, fmax(fabs(r[0] - tp), fmax(fabs(r[1] - tb), fabs(uc - tu))));
        dev_raw = fmax(dev_raw, fabs(r[2] - tu));
        dev_marker = fmax(dev_marker, fabs(r[3] - tm));
    }
    io_summary_long(y, KEY("%s.Tv_points", prefix), o->next);
    io_summary_double(y, KEY("%s.deviation", prefix), dev);
    io_summary_double(y, KEY("%s.deviation_marker", prefix), dev_marker);
    io_summary_double(y, KEY("%s.deviation_raw_U", prefix), dev_raw);
    const double cpu = o->cpu_run + (cputime() - o->cpu0);
    io_summary_double(y, KEY("%s.dry_step_cpu", prefix), o->t_dry);
    if (o->steps > 0) {
        /* per DEM step: a coupled step is porenet.dem_steps of them */
        const double per_dem = cpu / o->steps / cfg_int(o->cfg, "porenet", "dem_steps");
        io_summary_double(y, KEY("%s.coupled_step_cpu", prefix), cpu / o->steps);
        io_summary_double(y, KEY("%s.coupled_over_dry", prefix), per_dem / o->t_dry);
    }
#undef KEY
}

/* ---- checkpoint ---- */

#define SCALARS(X)                                                                                                     \
    X(area) X(mass) X(rm) X(H) X(dH) X(Eoed) X(zpiston) X(hnet) X(kappa) X(mu) X(L) X(zdrain) X(cv) X(dH_piston)      \
        X(dH_marker) X(z0) X(zm0) X(t_dry) X(ntop) X(nmarker) X(T) X(pm) X(pb) X(U) X(Um) X(zmid) X(zbase) X(pmax)

static void part_checkpoint_write(void *ctx, hid_t g)
{
    oedo_t *o = ctx;
    protocol(o);
#define W(v) io_h5_attr_double(g, #v, o->v);
    SCALARS(W)
#undef W
    io_h5_attr_long(g, "piston", o->piston);
    io_h5_attr_long(g, "next", o->next);
    io_h5_attr_long(g, "steps", o->steps);
    io_h5_attr_long(g, "ids", o->nid);
    io_h5_attr_double(g, "cpu", o->cpu_run + (cputime() - o->cpu0));
    io_h5_write_array(g, "taylor_sums", 5, o->tsum);
    io_h5_write_array(g, "records", NTV * 6, &o->rec[0][0]);
    io_h5_write_array(g, "profiles", NTV * NBAND, &o->prof[0][0]);
    io_h5_write_array(g, "top", o->nid, o->top);
    io_h5_write_array(g, "marker", o->nid, o->marker);
}

static void part_checkpoint_read(void *ctx, hid_t g, const char *path)
{
    oedo_t *o = ctx;
    long piston = 0, next = 0, nid = 0;
    int bad = 0;
#define R(v) bad |= io_h5_get_attr_double(g, #v, &o->v);
    SCALARS(R)
#undef R
    bad |= io_h5_get_attr_long(g, "piston", &piston) | io_h5_get_attr_long(g, "next", &next) |
           io_h5_get_attr_long(g, "steps", &o->steps) | io_h5_get_attr_long(g, "ids", &nid) |
           io_h5_get_attr_double(g, "cpu", &o->cpu_run);
    if (bad) die("%s: /oedometer lacks an attribute of the state", path);
    o->piston = (int)piston;
    o->next = (int)next;
    o->nid = nid;
    o->top = xcalloc((size_t)nid + 1, sizeof *o->top);
    o->marker = xcalloc((size_t)nid + 1, sizeof *o->marker);
    if (io_h5_read_array(g, "taylor_sums", 5, o->tsum) != 5 || io_h5_read_array(g, "records", NTV * 6, &o->rec[0][0]) != NTV * 6 ||
        io_h5_read_array(g, "profiles", NTV * NBAND, &o->prof[0][0]) != NTV * NBAND ||
        io_h5_read_array(g, "top", nid, o->top) != nid || io_h5_read_array(g, "marker", nid, o->marker) != nid)
        die("%s: /oedometer lacks an array of the state", path);
    o->d = sim_dem_engine(o->sim);
    o->done_protocol = 1;
    o->cpu0 = cputime();
    /* the piston is the checkpoint's wall: its load and mass */
    set_load(o, o->sigma0 + o->dsig);
    network(o)->dom.hi[2] = o->hnet;
}

static void part_destroy(void *ctx)
{
    oedo_t *o = ctx;
    free(o->top);
    free(o->marker);
    free(o);
}

void sim_add_oedometer(sim_t *s, cfg_t *cfg)
{
    oedo_t *o = xcalloc(1, sizeof *o);
    o->sim = s;
    o->cfg = cfg;
    o->sigma0 = cfg_double(cfg, "oedometer", "preload");
    o->dsig = cfg_double(cfg, "oedometer", "load_step");
    o->ocr = cfg_double(cfg, "oedometer", "overconsolidation");
    o->ramp = cfg_int(cfg, "oedometer", "ramp");
    o->dry_ramp = cfg_int(cfg, "oedometer", "dry_ramp");
    o->rest_tol = cfg_double(cfg, "oedometer", "rest_tolerance");
    o->piston_mass = cfg_double(cfg, "oedometer", "piston_mass");
    o->layer = cfg_double(cfg, "oedometer", "drained_layer");
    o->path_is_h = cfg_enum(cfg, "oedometer", "drainage_path") == 1;
    o->cv_below_marker = cfg_enum(cfg, "oedometer", "modulus") == 1;
    o->marker_lo = cfg_double(cfg, "oedometer", "marker_lo");
    o->marker_hi = cfg_double(cfg, "oedometer", "marker_hi");
    o->taylor_lo = cfg_double(cfg, "oedometer", "taylor_lo");
    o->taylor_hi = cfg_double(cfg, "oedometer", "taylor_hi");
    o->tv_end = cfg_double(cfg, "oedometer", "tv_end");
    cfg_string(cfg, "oedometer", "piston");
    if (o->marker_hi <= o->marker_lo) cfg_fail(cfg, "oedometer", "marker_hi", "must exceed marker_lo");
    if (!cfg_has_section(cfg, "particles") || s->fluid_model != FLUID_MODEL_PORENET)
        cfg_fail(cfg, "oedometer", "piston", "the oedometer needs DEM particles and the pore network (coupling.fluid = porenet)");
    /* the protocol runs before the network's first solve (on S₀, with its top face) */
    sim_porenet_before_start(s, protocol, o);
    sim_part_t part = {
        .name = "oedometer",
        .ctx = o,
        .advance = part_advance,
        .ncol = 6,
        .col_names = oedo_cols,
        .diagnostics = part_diagnostics,
        .checkpoint_write = part_checkpoint_write,
        .checkpoint_read = part_checkpoint_read,
        .summary = part_summary,
        .done = part_done,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}
