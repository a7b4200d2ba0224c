/* sim_avalanche.c — the measurements of a flow down a rough inclined plane
 * ([avalanche], avalanche.h) as a part of a run.
 *
 * It advances last: after every step it samples the particles (and the
 * resolved fluid, inside the averaging window), adds AV_NCOL columns to
 * series.csv, and writes the profiles over the window to profiles.csv at
 * every checkpoint and at the end.  summary.json gets the scene's numbers (St,
 * r, Ar, T_v, T_i, T_ff), the means over the window, the flow time T and its
 * ratios, the shares of the force balance, and the cost of each part of the
 * coupled step. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "avalanche.h"
#include "fluid_model.h"
#include "sim.h"
#include "util.h"

static const cfg_key_t avalanche_keys[] = {
    {"avalanche", "average_from", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "start of the averaging window of the profiles and means (s)"},
    {"avalanche", "average_to", CFG_DOUBLE, "1e300", 0, 1e300, NULL, "end of the averaging window (s)"},
    {"avalanche", "flow_length", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "the length L of the flow time T = L W h_g / Q_g (m; the thesis' eq. 4.12 with its box's L): 0: the "
     "domain's downslope length; 5 D compares a box of another length with the thesis' production box"},
    {"avalanche", "bin", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "height of the profile slabs (m); 0: a fifth of the mean mobile grain diameter"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL},
};

void sim_avalanche_register_keys(void) { cfg_schema_add(avalanche_keys); }

static const char *const av_cols[AV_NCOL] = {"Q_g",         "h_g",         "phi_bed",    "U_g",
                                             "St_mean",     "F_c_contact", "F_lub_pair", "F_c_grain",
                                             "F_lub_grain", "F_h_grain"};

typedef struct {
    sim_t *sim;
    cfg_t *cfg;
    struct ibm *ibm;
    dem_t *d;
    avalanche_t a, prev;
    double bin, t1, t2, zmax, L[3], z0;
    double flow_length; /* L of the flow time (0: the domain's downslope length) */
    int an;
    double rho, eta;
    double *Fh;        /* hydrodynamic force by particle id (resolved fluid) */
    int started;
} av_part_t;

static void start(av_part_t *ap)
{
    if (ap->started) return;
    ap->started = 1;
    ap->d = sim_dem_engine(ap->sim);
    double g[3];
    dem_get_gravity(ap->d, g);
    avalanche_init(&ap->a, ap->d, ap->an, ap->z0, ap->zmax, ap->L, g, ap->rho, ap->eta, ap->bin, ap->t1, ap->t2);
    avalanche_init(&ap->prev, ap->d, ap->an, ap->z0, ap->zmax, ap->L, g, ap->rho, ap->eta, ap->bin, ap->t1, ap->t2);
    dem_force_stats_enable(ap->d, 1);
    const avalanche_t *a = &ap->a;
    static const char ax[] = "xyz";
    msg("avalanche: D = %.4g m, rho_p/rho = %.4g, theta = %.4g deg (downslope %c, normal %c); St = %.4g, r = %.4g, "
        "Ar = %.4g; T_v = %.4g, T_i = %.4g, T_ff = %.4g sqrt(D/g) (%.4g, %.4g, %.4g ms)\n",
        a->D, a->rho_p / a->rho, asin(a->sin_theta) * 180 / M_PI, ax[a->as], ax[a->an], a->St, a->r, a->Ar,
        a->Tv / sqrt(a->D / a->g), a->Ti / sqrt(a->D / a->g), a->Tff / sqrt(a->D / a->g), 1e3 * a->Tv, 1e3 * a->Ti,
        1e3 * a->Tff);
}

static void part_advance(void *ctx, double dt)
{
    av_part_t *ap = ctx;
    start(ap);
    dem_force_stats_t fs;
    dem_force_stats_take(ap->d, &fs);
    const double *Fh = NULL;
    if (ap->ibm) {
        if (!ap->Fh) ap->Fh = xcalloc(3 * (size_t)ap->ibm->n, sizeof(double));
        for (int p = 0; p < ap->ibm->n; p++) memcpy(ap->Fh + 3 * p, ap->ibm->s[p].force, 3 * sizeof(double));
        Fh = ap->Fh;
    } else {
        Fh = dem_drag_forces(ap->d);
    }
    const double t = ap->sim->time + dt; /* the driver advances its clock after the parts */
    avalanche_sample_grains(&ap->a, ap->d, &fs, Fh, t, dt);
    if (ap->sim->fluid) avalanche_sample_fluid(&ap->a, ap->sim->fluid, ap->ibm, t, dt);
}

static void part_diagnostics(void *ctx, double *c)
{
    av_part_t *ap = ctx;
    start(ap);
    memcpy(c, ap->a.now, sizeof ap->a.now);
}

static void part_keep_previous(void *ctx)
{
    av_part_t *ap = ctx;
    start(ap);
    avalanche_copy_sums(&ap->prev, &ap->a);
}

static void part_restore_previous(void *ctx)
{
    av_part_t *ap = ctx;
    avalanche_copy_sums(&ap->a, &ap->prev);
}

static void write_profiles(av_part_t *ap)
{
    if (mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 16];
    io_outdir_path(&ap->sim->out, "profiles.csv", path, sizeof path);
    avalanche_write_profiles(&ap->a, path);
}

static void part_checkpoint_write(void *ctx, hid_t g)
{
    av_part_t *ap = ctx;
    start(ap);
    avalanche_state_write(&ap->a, g);
    write_profiles(ap);
}

static void part_checkpoint_read(void *ctx, hid_t g, const char *path)
{
    av_part_t *ap = ctx;
    start(ap);
    if (avalanche_state_read(&ap->a, g)) die("%s: avalanche: the averages are missing or of another size", path);
}

/* Shares of the three forces, each over their sum. */
static void shares(io_summary_t *y, const char *prefix, const char *name, double c, double l, double h)
{
    char key[160];
    const double s = c + l + h;
    snprintf(key, sizeof key, "%s.%s.contact", prefix, name);
    io_summary_double(y, key, s > 0 ? c / s : 0.0);
    snprintf(key, sizeof key, "%s.%s.lubrication", prefix, name);
    io_summary_double(y, key, s > 0 ? l / s : 0.0);
    snprintf(key, sizeof key, "%s.%s.hydrodynamic", prefix, name);
    io_summary_double(y, key, s > 0 ? h / s : 0.0);
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    av_part_t *ap = ctx;
    start(ap);
    const avalanche_t *a = &ap->a;
    char key[160];
#define KEY(name) (snprintf(key, sizeof key, "%s.%s", prefix, name), key)
    const double tg = sqrt(a->D / a->g);
    io_summary_double(y, KEY("D"), a->D);
    io_summary_double(y, KEY("density_ratio"), a->rho_p / a->rho);
    io_summary_double(y, KEY("theta_deg"), asin(a->sin_theta) * 180 / M_PI);
    io_summary_double(y, KEY("St"), a->St);
    io_summary_double(y, KEY("r"), a->r);
    io_summary_double(y, KEY("Ar"), a->Ar);
    io_summary_double(y, KEY("T_v"), a->Tv);
    io_summary_double(y, KEY("T_i"), a->Ti);
    io_summary_double(y, KEY("T_ff"), a->Tff);
    io_summary_double(y, KEY("sqrt_D_over_g"), tg);
    io_summary_double(y, KEY("average_from"), a->t1);
    io_summary_double(y, KEY("averaged_seconds"), a->tw);
    for (int c = 0; c < AV_NCOL; c++) {
        char nm[64];
        snprintf(nm, sizeof nm, "mean.%s", av_cols[c]);
        io_summary_double(y, KEY(nm), avalanche_mean(a, c));
    }
    /* T = L W h_g / Q_g grows with L (T = L/(phi U)): the box's downslope length, or flow_length */
    const double Lbox = ap->L[a->as], Lflow = ap->flow_length > 0 ? ap->flow_length : Lbox;
    const double T = avalanche_flow_time(a) * Lflow / Lbox;
    io_summary_double(y, KEY("flow_length"), Lflow);
    io_summary_double(y, KEY("T"), a->tw > 0 ? T : NAN);
    io_summary_double(y, KEY("T_over_Tv"), a->tw > 0 ? T / a->Tv : NAN);
    io_summary_double(y, KEY("T_over_Ti"), a->tw > 0 ? T / a->Ti : NAN);
    io_summary_double(y, KEY("T_over_Tff"), a->tw > 0 ? T / a->Tff : NAN);
    shares(y, prefix, "share_per_contact", avalanche_mean(a, AV_FC_PAIR), avalanche_mean(a, AV_FLUB_PAIR),
           avalanche_mean(a, AV_FH_GRAIN));
    shares(y, prefix, "share_per_grain", avalanche_mean(a, AV_FC_GRAIN), avalanche_mean(a, AV_FLUB_GRAIN),
           avalanche_mean(a, AV_FH_GRAIN));
    /* the cost of the coupled step: the driver's time per part, split further by the immersed
     * boundary's and the DEM's own timers */
    const sim_t *s = ap->sim;
    double fluid = 0, dem = 0, stats = 0;
    for (int i = 0; i < s->npart; i++) {
        if (!strcmp(s->part[i].name, "fluid") || !strcmp(s->part[i].name, "ibm")) fluid += s->part_wall[i];
        if (!strcmp(s->part[i].name, "coupling") || !strcmp(s->part[i].name, "dem")) dem += s->part_wall[i];
        if (!strcmp(s->part[i].name, prefix)) stats += s->part_wall[i];
    }
    const double ibmw = ap->ibm ? ap->ibm->wall_alpha + ap->ibm->wall_forcing + ap->ibm->wall_integrals : 0.0;
    const double lub = dem_lubrication_seconds(ap->d);
    const long steps = s->step - s->step0;
    io_summary_double(y, KEY("cost.fluid_seconds"), fluid - ibmw);
    io_summary_double(y, KEY("cost.ibm_seconds"), ibmw);
    io_summary_double(y, KEY("cost.dem_seconds"), dem - lub);
    io_summary_double(y, KEY("cost.lubrication_seconds"), lub);
    io_summary_double(y, KEY("cost.statistics_seconds"), stats);
    io_summary_double(y, KEY("cost.output_seconds"), s->output_wall);
    io_summary_double(y, KEY("cost.steps"), (double)steps);
#undef KEY
    write_profiles(ap);
}

static void part_destroy(void *ctx)
{
    av_part_t *ap = ctx;
    if (ap->started) {
        avalanche_free(&ap->a);
        avalanche_free(&ap->prev);
    }
    free(ap->Fh);
    free(ap);
}

void sim_add_avalanche(sim_t *s, cfg_t *cfg, struct ibm *ibm)
{
    av_part_t *ap = xcalloc(1, sizeof *ap);
    ap->sim = s;
    ap->cfg = cfg;
    ap->ibm = ibm;
    ap->t1 = cfg_double(cfg, "avalanche", "average_from");
    ap->t2 = cfg_double(cfg, "avalanche", "average_to");
    if (ap->t2 <= ap->t1) cfg_fail(cfg, "avalanche", "average_to", "must be after average_from (%g s)", ap->t1);
    ap->bin = cfg_double(cfg, "avalanche", "bin");
    ap->flow_length = cfg_double(cfg, "avalanche", "flow_length");
    /* the bed's normal and plane: those of [bed] (the domain's low face without a bed) */
    double x0[3];
    cfg_vec3(cfg, "domain", "length", ap->L);
    cfg_vec3(cfg, "domain", "origin", x0);
    ap->an = cfg_enum(cfg, "bed", "axis");
    ap->z0 = cfg_enum(cfg, "bed", "type") != 0 ? cfg_double(cfg, "bed", "position") : x0[ap->an];
    ap->zmax = x0[ap->an] + ap->L[ap->an];
    if (ap->bin >= ap->zmax - ap->z0) cfg_fail(cfg, "avalanche", "bin", "larger than the height above the bed");
    ap->eta = fluid_model_viscosity(cfg);
    ap->rho = s->fluid ? s->fluid->prm.rho
                       : (cfg_has_section(cfg, "fluid") ? cfg_double(cfg, "fluid", "rho")
                                                        : cfg_double(cfg, "drag", "fluid_density"));
    if (!(ap->eta > 0) || !(ap->rho > 0))
        cfg_fail(cfg, "avalanche", "average_from", "needs a fluid (its density and viscosity) for its numbers");
    sim_add_output_name(s, "profiles.csv");
    sim_part_t part = {
        .name = "avalanche",
        .ctx = ap,
        .advance = part_advance,
        .ncol = AV_NCOL,
        .col_names = av_cols,
        .diagnostics = part_diagnostics,
        .keep_previous = part_keep_previous,
        .restore_previous = part_restore_previous,
        .checkpoint_write = part_checkpoint_write,
        .checkpoint_read = part_checkpoint_read,
        .summary = part_summary,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}
