/* test_porenet_consolidation.c — Terzaghi consolidation in an oedometer with
 * the pore network coupled to the DEM (cases/consolidation/coarse.ini;
 * catalano_pfv.md §2.2 and §5.4, thesis §4.4; docs/validation.md):
 *  1. a dense packing is settled under gravity, then held without gravity by
 *     a piston (a load-controlled DEM wall the fluid does not see) under the
 *     preload σ₀, σ₀ + 2Δσ and σ₀ again (state S₀; damped skeleton);
 *  2. dry: the load step Δσ on the piston gives the settlement ΔH and the
 *     oedometric modulus E_oed = Δσ H/ΔH (same packing, same load path);
 *  3. permeameter on S₀: κ from the flux and the mean pressure gradient, and
 *     the drainage path L (where the central pressure line reaches the top
 *     pressure);
 *  4. saturated: the same load step on S₀, sealed at the bottom and drained
 *     at the top; the excess pore pressure at mid-height and at the base and
 *     the degree of consolidation U = settlement/ΔH against the series
 *     solution at T_v = C_v t/L² = 0.1, 0.2, 0.5, 1 with C_v = κ E_oed/μ.
 *     §5.4 asks ±0.05 (PN_TOL=0.05 in scripts/validate.sh, full column);
 *     make test bounds the coarse column by its measured deviation.
 *  5. the settlement corrected for the initial compression (Taylor's √t
 *     method, ASTM D2435): the straight part of U against √T_v, fitted on
 *     TAYLOR_LO ≤ T_v ≤ TAYLOR_HI and extrapolated to t = 0, gives the
 *     corrected zero d_s/ΔH; U_corr = (U − d_s/ΔH)/(1 − d_s/ΔH).
 *  6. without a correction: the marker layer (the grains 1–2 d below the
 *     piston in S₀, tracked by identity), its settlement over its dry
 *     settlement U_m against the degree of consolidation of the sub-layer
 *     below it in the same layer (terzaghi_U_sub, same T_v).  The ±0.05
 *     bound applies to p_mid, p_base, U_corr and U_m; the raw U is printed
 *     and bounded separately (docs/validation.md).
 *  7. multi-rate: the saturated run again with twice porenet.dem_steps DEM
 *     steps per coupled step; p_mid, p_base and U at the T_v points within
 *     1e-3 of the first run (docs/theory.md §8).
 * Heights and settlements are those of the centres of the grains touching
 * the piston: the piston's own contacts, at the drained face, would add a
 * compliance that drains at once (not Terzaghi's).
 * Environment: cases/consolidation/README.md (PN_REFERENCE=1: also the run
 * re-triangulating at every step, within 0.02 of the default one).
 * RANKS: 1 (2 ranks: checked by hand, the DEM and the network are replicated)
 */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "config.h"
#include "dem.h"
#include "modules.h"
#include "porenet.h"
#include "testutil.h"
#include "util.h"

static const double TV[4] = {0.1, 0.2, 0.5, 1.0};
/* bound on the deviation from the series of the coarse case (p_mid, p_base, U_corr; see the end
 * of test_consolidation): measured 0.066 (p_base at T_v = 0.5) + 0.02 */
#define COARSE_TOL 0.09
/* bound on the deviation of the raw (uncorrected) U of the coarse case: measured 0.083 (T_v = 0.1) + 0.02 */
#define COARSE_RAW_TOL 0.10
/* bound on the deviation of the marker layer's U of the coarse case: measured 0.034 (T_v = 0.2) + 0.02 */
#define COARSE_MARKER_TOL 0.055
/* Taylor's √t construction: the window of the straight line.  Terzaghi's U is
 * 2 √(T_v/π) to 2·10⁻⁴ up to T_v = 0.2 (U ≈ 0.5); from T_v = 0.02 on the
 * immediate compression of the layer under the piston is over (600 spheres:
 * U/√T_v peaks at T_v ≈ 0.002 and the line fits U on [0.02, 0.2] within 0.003).
 * The window ends at 0.2 so that the reference runs (PN_TV_MAX=0.2) have it. */
#define TAYLOR_LO 0.02
#define TAYLOR_HI 0.2
/* The marker layer: the grains whose centres lie MARKER_LO to MARKER_HI mean
 * diameters below the piston in S₀, i.e. the layer under the grains touching
 * the piston (centres ≈ ½ d below it), so that its settlement, the compression
 * of the sample below it, leaves out the soft first layer.  One diameter
 * thick (≈ 26 grains in the 5 × 5 cm box): the half-diameter bands 1–1.5 d and
 * 1.5–2 d differ by 0.025 of their dry settlement at T_v = 0.5
 * (docs/validation.md).  PN_MARKER="lo hi" overrides, in diameters. */
#define MARKER_LO 1.0
#define MARKER_HI 2.0

/* Terzaghi's series (catalano_pfv.md §2.2), drained face at z = L, sealed
 * base at z = 0 (the drainage path L = H), M = (2m+1)π/2:
 * p(z)/Δσ = Σ (2/M) sin(M (L − z)/L) e^{−M² T}, U = 1 − Σ (2/M²) e^{−M² T}.
 * The pressure at the base is that at mid-height of a layer drained on both
 * faces (the table of §2.2). */
static double terzaghi_p(double zeta, double T)
{
    double s = 0;
    for (int m = 0; m < 200; m++) {
        const double M = (2 * m + 1) * M_PI / 2;
        s += 2 / M * sin(M * (1 - zeta)) * exp(-M * M * T);
    }
    return s;
}

static double terzaghi_U(double T)
{
    double s = 0;
    for (int m = 0; m < 200; m++) {
        const double M = (2 * m + 1) * M_PI / 2;
        s += 2 / (M * M) * exp(-M * M * T);
    }
    return 1 - s;
}

/* Degree of consolidation of the sub-layer 0 ≤ z ≤ ζ_m L of the same layer
 * (docs/validation.md, "marker layer"): its compression over its drained
 * compression, with the strain (Δσ − p)/E_oed,
 * U_m = 1 − (1/ζ_m) ∫₀^ζ_m p/Δσ dζ = 1 − Σ 2 cos(M (1 − ζ_m))/(M² ζ_m) e^{−M² T}
 * (∫₀^ζ_m sin(M(1 − ζ)) dζ = [cos(M(1 − ζ)) − cos M]/M and cos M = 0).
 * ζ_m = 1 gives U.  T is the T_v of the whole layer: the pressure field is the
 * layer's, the sub-layer's top is not a drained face. */
static double terzaghi_U_sub(double zeta_m, double T)
{
    double s = 0;
    for (int m = 0; m < 200; m++) {
        const double M = (2 * m + 1) * M_PI / 2;
        s += 2 * cos(M * (1 - zeta_m)) / (M * M * zeta_m) * exp(-M * M * T);
    }
    return 1 - s;
}

typedef struct {
    int piston;            /* the load-controlled wall */
    double area;           /* cross-section of the oedometer */
    double mass;           /* of the piston */
    unsigned char *top;    /* by particle id: grain touching the piston in S₀ */
    int ntop;
    unsigned char *marker; /* by particle id: the marker layer (centres MARKER_LO–MARKER_HI d below the piston in S₀) */
    int nmarker;
    double dH_marker;      /* drained (dry) settlement of the marker layer under the load step */
} oedo_t;

static void set_load(dem_t *d, const oedo_t *o, double sigma) { dem_wall_set_load(d, o->piston, sigma * o->area, o->mass); }

static double piston_z(const dem_t *d, const oedo_t *o)
{
    double p[3];
    dem_wall_position(d, o->piston, p);
    return p[2];
}

/* Mean centre height of the grains of a set (by particle id). */
static double set_mean_z(const dem_t *d, const unsigned char *set, int count)
{
    const int n = dem_count(d);
    const long *id = dem_ids(d);
    const double *x = dem_positions(d);
    double h = 0;
    for (int i = 0; i < n; i++)
        if (set[id[i]]) h += x[3 * i + 2];
    return h / count;
}

/* Height of the sample: mean centre height of the grains under the piston. */
static double surface_z(const dem_t *d, const oedo_t *o) { return set_mean_z(d, o->top, o->ntop); }

/* Height of the marker layer above the (fixed) base. */
static double marker_z(const dem_t *d, const oedo_t *o) { return set_mean_z(d, o->marker, o->nmarker); }

/* CPU time (cputime(): the machine is shared, the wall time of a step
 * depends on the other jobs, the CPU time much less) and count of the dry DEM
 * steps (the cost of a coupled step is reported relative to a dry one of the
 * same packing) */
static double dry_time;
static long dry_steps;

static void dry_steps_run(dem_t *d, long n)
{
    const double t0 = cputime();
    assert_int_equal(dem_run_steps(d, n), DEM_OK);
    dry_time += cputime() - t0;
    dry_steps += n;
}

/* Dry, under the current load, to the static equilibrium (the local damping
 * of the case takes the kinetic energy away and does not change the
 * equilibrium): at rest when the piston moved by less than tol in 100
 * steps.  Returns the height of the sample (the piston's before the grains
 * under it are known). */
static double relax_loaded(dem_t *d, const oedo_t *o, double tol)
{
    double h = piston_z(d, o);
    for (int k = 0; k < 2000; k++) {
        dry_steps_run(d, 100);
        const double h1 = piston_z(d, o);
        if (getenv("PN_TRACE") && mpi_rank() == 0) printf("# dry %d: piston %.9g\n", k, h1);
        if (k > 3 && fabs(h1 - h) < tol) return o->ntop ? surface_z(d, o) : h1;
        h = h1;
    }
    fail_msg("the dry oedometer did not come to rest");
    return h;
}

/* Dry: the load σ at once, then to rest. */
static double relax_dry(dem_t *d, const oedo_t *o, double sigma, double tol)
{
    set_load(d, o, sigma);
    return relax_loaded(d, o, tol);
}

/* Dry: the load raised linearly from 0 to σ over n × 100 steps, then to rest
 * (the first loading: at once, the piston would push the few highest grains
 * alone into overlaps above dem.max_overlap). */
static double ramp_dry(dem_t *d, const oedo_t *o, double sigma, int n, double tol)
{
    for (int k = 1; k <= n; k++) {
        set_load(d, o, sigma * k / n);
        dry_steps_run(d, 100);
    }
    return relax_loaded(d, o, tol);
}

/* Mean pore pressure in the band zlo < z < zhi, and the mean height of its
 * pores (where the series is evaluated). */
static double band_pressure(const pn_model_t *m, double zlo, double zhi, double *zmean)
{
    double s = 0, c = 0, sz = 0;
    for (int i = 0; i < m->net.npore; i++) {
        const double z = m->net.P[3 * i + 2];
        if (z > zlo && z < zhi) s += m->p[i], sz += z, c++;
    }
    if (zmean) *zmean = sz / c;
    return s / c;
}

typedef struct {
    double pmid[4], pbase[4], U[4];
    double Um[4];       /* degree of consolidation of the marker layer (its settlement / its dry settlement) */
    double Um_eff[4];   /* 1 − mean p/Δσ of the pores below the marker: U_m from the effective stress of a linear skeleton */
    double T_end, U_end, Um_end, pbase_end; /* at the end of the run (PN_TV_MAX > 1: the final settlement) */
    double ds;          /* Taylor's corrected zero d_s/ΔH (0 if the window was not reached) */
    double taylor_slope; /* dU/d√T_v of the straight part (Terzaghi: 2/√π ≈ 1.128) */
    double zmid, zbase; /* mean heights of the pores of the two bands */
    double pmax;        /* largest p_base/Δσ seen (the undrained jump) */
    long steps, retri;
    double t_step;      /* CPU time per coupled step (DEM + network) */
    double dt;
    int ntv;            /* T_v values reached */
} wet_t;

static wet_t run_wet(cfg_t *cfg, const char *s0, const oedo_t *o, double hnet, double sigma, double dsig, double H,
                     double L, double dH, double cv, double eps_retri, int dem_steps, FILE *series, const char *label)
{
    wet_t w = {0};
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    dem_read_checkpoint(d, s0);
    assert_int_equal(dem_advance(d, dem_time(d)), DEM_OK);
    const double z0 = surface_z(d, o), zm0 = marker_z(d, o);
    double *zinit = calloc((size_t)dem_count(d), sizeof *zinit);
    for (int i = 0; i < dem_count(d); i++) zinit[dem_ids(d)[i]] = dem_positions(d)[3 * i + 2];
    pn_model_t m;
    pn_model_from_config(cfg, &m);
    m.dom.hi[2] = hnet;
    m.eps_retri = eps_retri;
    if (dem_steps > 0) m.dem_steps = dem_steps;
    /* PN_DT_FACTOR: ζ beyond the case file's range (stability measurements of the multi-rate step) */
    if (getenv("PN_DT_FACTOR")) m.dt_factor = atof(getenv("PN_DT_FACTOR"));
    const double g0[3] = {0, 0, 0};
    assert_int_equal(pn_model_couple_dem(&m, d, g0, 0.0), 0);
    set_load(d, o, sigma + dsig);
    if (getenv("PN_WET_DAMPING")) dem_set_damping(d, atof(getenv("PN_WET_DAMPING")));
    /* porenet.dem_steps DEM steps per coupled step, within the viscous limit (thesis 4.21) */
    const double dt = pn_coupled_step(&m, d);
    w.dt = dt;
    if (getenv("PN_TRACE") && mpi_rank() == 0)
        printf("# wet: dt %.3g s (viscous limit x dt_factor %.3g, DEM %.3g)\n", dt, pn_coupled_dt(&m, d), dem_dt(d));
    const double t0 = dem_time(d);
    int next = 0;
    double sx = 0, sy = 0, sxx = 0, sxy = 0, sn = 0; /* least squares of U on √T_v, Taylor's window */
    /* PN_STEPS: stop after this many steps (timing runs) */
    const long max_steps = getenv("PN_STEPS") ? atol(getenv("PN_STEPS")) : -1;
    /* PN_TV_MAX: stop after the last T_v of the list not above it (reference runs);
     * above 1, run on to that T_v (the final settlement against the dry one) */
    int ntv = 4;
    const double tv_max = getenv("PN_TV_MAX") ? atof(getenv("PN_TV_MAX")) : 1;
    while (ntv > 1 && TV[ntv - 1] > tv_max + 1e-12) ntv--;
    double T = 0;
    double t_dem = 0, t_couple = 0; /* CPU time of the DEM steps and of the network's part of the coupled steps */
    while ((next < ntv || T < tv_max) && w.steps != max_steps) {
        const double c0 = cputime();
        const dem_status_t st = dem_advance(d, dem_time(d) + dt);
        const double c1 = cputime();
        if (st != DEM_OK) fprintf(stderr, "wet step %ld: %s\n", w.steps, dem_error(d));
        assert_int_equal(st, DEM_OK);
        assert_int_equal(pn_model_couple_dem(&m, d, g0, dt), 0);
        t_dem += c1 - c0;
        t_couple += cputime() - c1;
        w.steps++;
        T = cv * (dem_time(d) - t0) / (L * L);
        /* bands of 0.1 H: around mid-height, and on the base */
        const double pm = band_pressure(&m, 0.45 * H, 0.55 * H, &w.zmid) / dsig;
        const double pb = band_pressure(&m, -1, 0.1 * H, &w.zbase) / dsig, U = (z0 - surface_z(d, o)) / dH;
        const double Um = (zm0 - marker_z(d, o)) / o->dH_marker;
        w.pmax = fmax(w.pmax, pb);
        if (T >= TAYLOR_LO && T <= TAYLOR_HI) {
            const double x = sqrt(T);
            sx += x, sy += U, sxx += x * x, sxy += x * U, sn++;
        }
        if (series && w.steps % 20 == 0)
            fprintf(series, "%s,%.6g,%.6g,%.6g,%.6g,%.4f,%.4f,%.6g,%.5f\n", label, T, pm, pb, U, w.zmid / L, w.zbase / L, Um,
                    zm0 / L);
        if (getenv("PN_TRACE") && w.steps % 100 == 0 && mpi_rank() == 0)
            printf("# wet %ld: T %.4g pmid %.4f pbase %.4f U %.4f U_marker %.4f\n", w.steps, T, pm, pb, U, Um);
        if (getenv("PN_PROFILE") && mpi_rank() == 0 && w.steps % 500 == 0) {
            /* p(z)/Δσ in 10 bands of H, and the grains' mean z displacement per band */
            printf("# profile T %.4g:", T);
            for (int b = 0; b < 12; b++) printf(" %.3f", band_pressure(&m, b * 0.1 * H, (b + 1) * 0.1 * H, NULL) / dsig);
            printf("\n# disp  T %.4g:", T);
            {
                /* mean settlement of the grains in 12 bands of their initial height, in units of ΔH */
                const int nn = dem_count(d);
                const long *id = dem_ids(d);
                const double *xx = dem_positions(d);
                double sd[12] = {0}, cd[12] = {0};
                for (int i = 0; i < nn; i++) {
                    const int b = (int)(zinit[id[i]] / (0.1 * H));
                    if (b >= 0 && b < 12) sd[b] += zinit[id[i]] - xx[3 * i + 2], cd[b]++;
                }
                for (int b = 0; b < 12; b++) printf(" %.3f", cd[b] ? sd[b] / cd[b] / dH : 0);
            }
            printf("\n");
        }
        w.T_end = T, w.U_end = U, w.Um_end = Um, w.pbase_end = pb;
        if (next < ntv && T >= TV[next]) {
            w.Um_eff[next] = 1 - band_pressure(&m, -1, zm0, NULL) / dsig;
            w.pmid[next] = pm;
            w.pbase[next] = pb;
            w.U[next] = U;
            w.Um[next] = Um;
            next++;
        }
    }
    if (sn >= 2) {
        w.taylor_slope = (sn * sxy - sx * sy) / (sn * sxx - sx * sx);
        w.ds = (sy - w.taylor_slope * sx) / sn;
    }
    w.t_step = (t_dem + t_couple) / w.steps;
    w.ntv = next;
    free(zinit);
    w.retri = m.n_retri;
    if (mpi_rank() == 0) {
        const double us = 1e6 / w.steps;
        printf("# %s: %ld steps of %.3g s, %d pores, %ld triangulations (last: triangulation %.3g ms, network %.3g ms, factorisation "
               "%.3g ms); per coupled step (CPU, us): DEM %.1f, volume rates %.1f, solve %.1f, forces %.1f, "
               "rebuilds amortised %.1f, gather/scatter %.1f; total %.1f\n",
               label, w.steps, dt, m.net.npore, m.n_retri, 1e3 * m.t_tri, 1e3 * m.t_net, 1e3 * m.t_factor, t_dem * us, m.t_vol * us,
               m.t_solve * us, m.t_force * us, m.t_rebuild * us,
               (t_couple - m.t_vol - m.t_solve - m.t_force - m.t_rebuild) * us, (t_dem + t_couple) * us);
    }
    pn_model_free(&m);
    dem_free(d);
    return w;
}

static void test_consolidation(void **state)
{
    (void)state;
    /* PN_SET: overrides "section.key=value ..." (scripts/validate.sh) */
    char setbuf[1024] = "", *sets[16];
    int nset = 0;
    if (getenv("PN_SET")) snprintf(setbuf, sizeof setbuf, "%s", getenv("PN_SET"));
    for (char *tok = strtok(setbuf, " "); tok && nset < 16; tok = strtok(NULL, " ")) sets[nset++] = tok;
    cfg_t *cfg = cfg_load(getenv("PN_CASE") ? getenv("PN_CASE") : "cases/consolidation/coarse.ini", nset, sets);
    assert_non_null(cfg);
    char dir[] = "/tmp/pn_consolidation_XXXXXX";
    if (mpi_rank() == 0) assert_non_null(mkdtemp(dir));
    MPI_Bcast(dir, sizeof dir, MPI_CHAR, 0, MPI_COMM_WORLD);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    const int prc = dem_prepare_packing(d, cfg, dir);
    if (prc >= 10) fprintf(stderr, "prepare: %s\n", dem_error(d));
    assert_true(prc < 10);
    assert_int_equal(dem_advance(d, dem_time(d)), DEM_OK);

    const int n = dem_count(d);
    const double *x = dem_positions(d), *r = dem_radii(d);
    double ztop = -INFINITY, rm = 0, mtot = 0;
    for (int i = 0; i < n; i++) ztop = fmax(ztop, x[3 * i + 2] + r[i]), rm += r[i] / n, mtot += dem_mass(d, i);
    double L3[3];
    cfg_vec3(cfg, "domain", "length", L3);
    /* the piston: the mass of a tenth of the grains (≥ those it touches, ~25:
     * its contact period is no shorter than a grain's) */
    oedo_t o = {dem_wall_find(d, "wall1"), L3[0] * L3[1], 0.1 * mtot, calloc((size_t)n + 1, 1), 0, calloc((size_t)n + 1, 1), 0, 0};
    assert_true(o.piston >= 0);
    {
        /* the piston brought down onto the top of the settled packing */
        const double p[3] = {0, 0, ztop};
        dem_wall_set_point(d, o.piston, p);
    }

    /* preload and load step: σ₀ holds the packing together without gravity;
     * Δσ/E_oed ~ 1e-3 keeps the response linear (thesis c1) */
    const double sigma0 = 2000, dsig = getenv("PN_DSIG") ? atof(getenv("PN_DSIG")) : 500;
    /* at rest: the piston moves by less than 1e-9 m per 100 steps (the
     * settlement of the load step is ~5e-5 m) */
    const double rest_tol = 1e-9;
    /* overconsolidated: loaded to σ₀ + 2Δσ first and unloaded to σ₀, so that
     * the load step is a reloading, nearly elastic like the thesis' (its dry
     * strain was recovered on unloading); a virgin loading would be mostly
     * rearrangement, rate-dependent under the fluid */
    ramp_dry(d, &o, sigma0, 20, rest_tol);
    relax_dry(d, &o, sigma0 + (getenv("PN_OCR") ? atof(getenv("PN_OCR")) : 2) * dsig, rest_tol);
    relax_dry(d, &o, sigma0, rest_tol);
    {
        /* the grains touching the piston */
        const double zp = piston_z(d, &o);
        const long *id = dem_ids(d);
        x = dem_positions(d);
        r = dem_radii(d);
        for (int i = 0; i < dem_count(d); i++)
            if (x[3 * i + 2] + r[i] > zp) o.top[id[i]] = 1, o.ntop++;
        /* the marker layer, tracked by identity from S₀ on */
        double mlo = MARKER_LO, mhi = MARKER_HI;
        if (getenv("PN_MARKER")) assert_int_equal(sscanf(getenv("PN_MARKER"), "%lf %lf", &mlo, &mhi), 2);
        for (int i = 0; i < dem_count(d); i++)
            if (x[3 * i + 2] >= zp - 2 * rm * mhi && x[3 * i + 2] < zp - 2 * rm * mlo) o.marker[id[i]] = 1, o.nmarker++;
        assert_true(o.nmarker > 0);
    }
    const double h0 = surface_z(d, &o), zpiston = piston_z(d, &o), zm0 = marker_z(d, &o);
    double *zs0 = calloc((size_t)n, sizeof *zs0);
    for (int i = 0; i < n; i++) zs0[dem_ids(d)[i]] = dem_positions(d)[3 * i + 2];
    char s0[512];
    snprintf(s0, sizeof s0, "%s/s0.h5", dir);
    dem_write_checkpoint(d, s0);
    dry_time = 0;
    dry_steps = 0;
    /* the load step at once, as on the saturated sample (a ramp over 10⁴
     * steps gave a 4 % stiffer E_oed and no closer agreement).  PN_DRY_RAMP=n:
     * raised linearly over n × 100 steps instead (the quasi-static path; with
     * PN_PROFILE and PN_DRY_ONLY, a measurement of the dry step alone) */
    const int dry_ramp = getenv("PN_DRY_RAMP") ? atoi(getenv("PN_DRY_RAMP")) : 0;
    for (int k = 1; k < dry_ramp; k++) {
        set_load(d, &o, sigma0 + dsig * k / dry_ramp);
        dry_steps_run(d, 100);
    }
    const double h1 = relax_dry(d, &o, sigma0 + dsig, rest_tol);
    const double t_dry = dry_time / dry_steps;
    const double dH_piston = zpiston - piston_z(d, &o);
    o.dH_marker = zm0 - marker_z(d, &o);
    if (getenv("PN_PROFILE") && mpi_rank() == 0) {
        double sd[12] = {0}, cd[12] = {0};
        for (int i = 0; i < n; i++) {
            const int b = (int)(zs0[dem_ids(d)[i]] / (0.1 * h0));
            if (b >= 0 && b < 12) sd[b] += zs0[dem_ids(d)[i]] - dem_positions(d)[3 * i + 2], cd[b]++;
        }
        printf("# dry disp:");
        for (int b = 0; b < 12; b++) printf(" %.3f", cd[b] ? sd[b] / cd[b] / (h0 - h1) : 0);
        printf("\n# dry step: dH = %.6g m, E_oed = %.6g Pa; marker layer: dH_m = %.6g m, E_oed below it %.6g Pa\n", h0 - h1,
               dsig * h0 / (h0 - h1), o.dH_marker, dsig * zm0 / o.dH_marker);
        fflush(stdout);
        if (getenv("PN_DRY_ONLY")) exit(0);
    }
    free(zs0);
    const double H = h0, dH = h0 - h1, Eoed = dsig * H / dH;

    /* permeameter on S₀: p = 1 at the base, 0 at the top of the network, two
     * mean diameters above the piston (the drained fluid layer) */
    const double hnet = zpiston + 4 * rm;
    pn_model_t m;
    pn_model_from_config(cfg, &m);
    m.dom.hi[2] = hnet;
    m.dom.bc[4] = PN_BC_PRESSURE;
    m.dom.bc_value[4] = 1;
    {
        dem_t *d0 = dem_create_from_config(cfg, MPI_COMM_WORLD);
        dem_read_checkpoint(d0, s0);
        const double g0[3] = {0, 0, 0};
        assert_int_equal(pn_model_couple_dem(&m, d0, g0, 0.0), 0);
        dem_free(d0);
    }
    double q[6];
    pn_face_fluxes(&m.dom, &m.net, m.p, q);
    /* mean gradient in the central half of the column (away from the base
     * and the fluid layer above the grains) */
    double sz = 0, sp = 0, szz = 0, szp = 0, c = 0;
    for (int i = 0; i < m.net.npore; i++) {
        const double z = m.net.P[3 * i + 2];
        if (z < 0.25 * H || z > 0.75 * H) continue;
        sz += z, sp += m.p[i], szz += z * z, szp += z * m.p[i], c++;
    }
    const double grad = (c * szp - sz * sp) / (c * szz - sz * sz);
    /* the drained face as the flow sees it: where the central pressure line
     * reaches the top pressure (0); the loose layer of grains under the
     * piston, about one diameter, is nearly as open as the fluid above it */
    const double zdrain = -((sp - grad * sz) / c) / grad;
    const double L = getenv("PN_L_IS_H") ? H : zdrain;
    const double mu = m.prm.mu, kappa = mu * (q[4] / o.area) / -grad;
    /* PN_CV_MARKER=1: C_v from the modulus of the column below the marker layer
     * (the part where the pressure diffuses; the soft first layer, at the drained
     * face, is left out) instead of the whole column's (docs/validation.md) */
    const double E_cv = getenv("PN_CV_MARKER") ? dsig * zm0 / o.dH_marker : Eoed;
    const double cv = kappa * E_cv / mu;
    pn_model_free(&m);

    FILE *series = NULL;
    if (getenv("PN_SERIES") && mpi_rank() == 0) {
        series = fopen(getenv("PN_SERIES"), "w");
        assert_non_null(series);
        fprintf(series, "run,Tv,pmid,pbase,U,zmid_over_H,zbase_over_H,U_marker,zeta_marker\n");
    }
    const double eps_default = cfg_double(cfg, "porenet", "retriangulate");
    const wet_t w = run_wet(cfg, s0, &o, hnet, sigma0, dsig, H, L, dH, cv, eps_default, 0, series, "default");
    if (mpi_rank() == 0) {
        printf("# consolidation: %d spheres (%d under the piston), H = %.4g m, E_oed = %.4g Pa (strain %.2e; from "
               "the piston %.4g Pa), kappa = %.4g m^2 (kappa/d^2 = %.3g), mu = %g Pa s, C_v = %.4g m^2/s, dt = %.3g s; "
               "%ld coupled steps to T_v = 1, %ld triangulations (retriangulate = %g), %.3g ms CPU per step; largest "
               "p_base/dsigma %.3f; dry DEM step %.3g ms CPU (coupled/dry %.2f)\n",
               n, o.ntop, H, Eoed, dH / H, dsig * zpiston / dH_piston, kappa, kappa / (4 * rm * rm), mu, cv, w.dt,
               w.steps, w.retri, eps_default, 1e3 * w.t_step, w.pmax, 1e3 * t_dry, w.t_step / t_dry);
        if (getenv("PN_CV_MARKER") || getenv("PN_DRY_RAMP"))
            printf("#   variant: dry step %s; C_v from %s, E = %.4g Pa\n",
                   getenv("PN_DRY_RAMP") ? "ramped over PN_DRY_RAMP x 100 steps" : "at once",
                   getenv("PN_CV_MARKER") ? "the column below the marker layer" : "the whole column", E_cv);
        printf("#   drainage path L = %.4g m (drained face from the permeameter; L/H = %.4f), T_v = C_v t/L^2; bands: "
               "mid-height z/L = %.3f, base z/L = %.3f\n",
               L, zdrain / H, w.zmid / L, w.zbase / L);
        printf("#   Taylor (U against sqrt(T_v) on %.2g <= T_v <= %.2g): corrected zero d_s = %.4f dH, slope %.4f "
               "(Terzaghi 2/sqrt(pi) = %.4f; x (1 - d_s) = %.4f)\n",
               TAYLOR_LO, TAYLOR_HI, w.ds, w.taylor_slope, 2 / sqrt(M_PI), 2 / sqrt(M_PI) * (1 - w.ds));
        printf("#   marker layer: %d grains, centres at z_m = %.4g m (z_m/L = %.4f, (H - z_m)/d = %.2f), dry settlement "
               "%.4g m = %.4f dH (z_m/H = %.4f; E_oed below it %.4g Pa, of the layer above it %.4g Pa)\n",
               o.nmarker, zm0, zm0 / L, (H - zm0) / (2 * rm), o.dH_marker, o.dH_marker / dH, zm0 / H,
               dsig * zm0 / o.dH_marker, dsig * (H - zm0) / (dH - o.dH_marker));
        for (int k = 0; k < w.ntv; k++)
            printf("#   T_v = %.1f: p_mid/dsigma = %.4f (Terzaghi %.4f), p_base/dsigma = %.4f (Terzaghi %.4f), U = %.4f, "
                   "U_corr = %.4f (Terzaghi %.4f), U_marker = %.4f (Terzaghi, sub-layer z < z_m: %.4f; 1 - mean p/dsigma "
                   "of the pores below z_m: %.4f)\n",
                   TV[k], w.pmid[k], terzaghi_p(w.zmid / L, TV[k]), w.pbase[k], terzaghi_p(w.zbase / L, TV[k]), w.U[k],
                   (w.U[k] - w.ds) / (1 - w.ds), terzaghi_U(TV[k]), w.Um[k], terzaghi_U_sub(zm0 / L, TV[k]), w.Um_eff[k]);
    }
    if (mpi_rank() == 0 && w.T_end > 1.01)
        printf("#   end of the run, T_v = %.3g: U = %.4f (Terzaghi %.4f), U_marker = %.4f (Terzaghi %.4f), p_base/dsigma = %.4f "
               "(Terzaghi %.4f)\n",
               w.T_end, w.U_end, terzaghi_U(w.T_end), w.Um_end, terzaghi_U_sub(zm0 / L, w.T_end), w.pbase_end,
               terzaghi_p(w.zbase / L, w.T_end));
    double dev = 0;     /* largest deviation from the series: p_mid, p_base, U_corr */
    double dev_raw = 0; /* that of the raw U (settlement from the instant of loading) */
    double dev_marker = 0; /* that of the marker layer's U against the sub-layer's series */
    const int ntv = w.ntv;
    for (int k = 0; k < ntv; k++) {
        dev = fmax(dev, fabs(w.pmid[k] - terzaghi_p(w.zmid / L, TV[k])));
        dev = fmax(dev, fabs(w.pbase[k] - terzaghi_p(w.zbase / L, TV[k])));
        dev = fmax(dev, fabs((w.U[k] - w.ds) / (1 - w.ds) - terzaghi_U(TV[k])));
        dev_marker = fmax(dev_marker, fabs(w.Um[k] - terzaghi_U_sub(zm0 / L, TV[k])));
        dev_raw = fmax(dev_raw, fabs(w.U[k] - terzaghi_U(TV[k])));
    }
    if (mpi_rank() == 0)
        printf("# largest deviation from Terzaghi: %.4f (p_mid, p_base, U_corr); marker layer U: %.4f; raw U: %.4f\n", dev,
               dev_marker, dev_raw);
    if (getenv("PN_REFERENCE")) {
        double worst = 0;
        const wet_t e = run_wet(cfg, s0, &o, hnet, sigma0, dsig, H, L, dH, cv, 0.0, 0, series, "every_step");
        if (mpi_rank() == 0)
            printf("# re-triangulating every step: %ld triangulations, %.3g ms CPU per step\n", e.retri, 1e3 * e.t_step);
        for (int k = 0; k < ntv && k < e.ntv; k++) {
            if (mpi_rank() == 0)
                printf("#   T_v = %.1f: p_mid/dsigma = %.4f (default %.4f), p_base/dsigma = %.4f (default %.4f), U = %.4f "
                       "(default %.4f), U_marker = %.4f (default %.4f)\n",
                       TV[k], e.pmid[k], w.pmid[k], e.pbase[k], w.pbase[k], e.U[k], w.U[k], e.Um[k], w.Um[k]);
            worst = fmax(worst, fmax(fabs(e.pmid[k] - w.pmid[k]), fabs(e.U[k] - w.U[k])));
            worst = fmax(worst, fmax(fabs(e.pbase[k] - w.pbase[k]), fabs(e.Um[k] - w.Um[k])));
        }
        if (mpi_rank() == 0) printf("# largest difference (of Δσ, of ΔH): %.4f\n", worst);
        /* §5.4: the default criterion agrees with every-step re-triangulation within 2 %
         * (measured only in the reference run: PN_REFERENCE=1, scripts/validate.sh) */
        assert_true(worst < 0.02);
    }
    {
        /* multi-rate (docs/theory.md §8): twice the DEM steps per coupled step,
         * the pressures solved every other DEM step.  The lag of the fluid force
         * is O(Δt) against the consolidation time (≈ 7000 DEM steps): measured
         * ≤ 6e-4 of Δσ (p) and 1.5e-4 of ΔH (U) at the T_v points with
         * dem_steps = 2, 1.5e-3 with 4; the issue asks 1e-3 */
        const int ms = 2 * cfg_int(cfg, "porenet", "dem_steps");
        const wet_t e = run_wet(cfg, s0, &o, hnet, sigma0, dsig, H, L, dH, cv, eps_default, ms, series, "multirate");
        double worst = 0;
        for (int k = 0; k < ntv && k < e.ntv; k++) {
            if (mpi_rank() == 0)
                printf("#   dem_steps %d, T_v = %.1f: p_mid/dsigma = %.4f (default %.4f), p_base/dsigma = %.4f (default "
                       "%.4f), U = %.4f (default %.4f)\n",
                       ms, TV[k], e.pmid[k], w.pmid[k], e.pbase[k], w.pbase[k], e.U[k], w.U[k]);
            worst = fmax(worst, fmax(fabs(e.pmid[k] - w.pmid[k]), fabs(e.U[k] - w.U[k])));
            worst = fmax(worst, fabs(e.pbase[k] - w.pbase[k]));
        }
        if (mpi_rank() == 0)
            printf("# multi-rate: %ld coupled steps, %.3g ms CPU per step (%.3g per DEM step); largest difference from "
                   "the default (of Δσ, of ΔH) %.2e\n",
                   e.steps, 1e3 * e.t_step, 1e3 * e.t_step / ms, worst);
        assert_int_equal(e.ntv, ntv);
        assert_true(worst < 1e-3);
    }
    if (series) fclose(series);
    /* the incompressible fluid takes the load step at once (undrained
     * response, thesis §4.4.1: "the excess pore pressure jumps to Δσ"); the
     * peak is above 1 by the impact of the piston (measured 1.13 on coarse.ini,
     * 1.17 on oedometer.ini) */
    assert_true(w.pmax > 0.95);
    /* deviation from the series: §5.4 asks ±0.05 (PN_TOL=0.05, scripts/validate.sh on
     * oedometer.ini).  The coarse column of make test (11 grains high) is
     * bounded by COARSE_TOL, its measured deviation plus 0.02: it guards the
     * set-up against regressions, not Terzaghi's accuracy */
    const double tol = getenv("PN_TOL") ? atof(getenv("PN_TOL")) : COARSE_TOL;
    assert_true(dev < tol);
    /* the marker layer's settlement against the series of its sub-layer, no correction: ±0.05 with
     * PN_TOL (oedometer.ini), its measured deviation + 0.02 on the coarse column */
    assert_true(dev_marker < (getenv("PN_TOL") ? tol : COARSE_MARKER_TOL));
    /* the corrected zero is an immediate compression: positive, and a minor part of ΔH
     * (measured 0.10 on 600 spheres); 0 would mean the window was not reached */
    if (ntv >= 2) assert_true(w.ds > 0 && w.ds < 0.3);
    /* the raw U (the immediate compression included) of the coarse column: a regression bound */
    if (!getenv("PN_TOL")) assert_true(dev_raw < COARSE_RAW_TOL);
    if (mpi_rank() == 0) {
        char pk[600];
        snprintf(pk, sizeof pk, "%s/%s", dir, cfg_string(cfg, "packing", "output"));
        unlink(s0);
        unlink(pk);
        rmdir(dir);
    }
    free(o.top);
    free(o.marker);
    dem_free(d);
    cfg_free(cfg);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_consolidation),
    };
    TEST_MPI_RUN("porenet_consolidation", tests);
}
