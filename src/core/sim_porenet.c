/* sim_porenet.c — the pore-network fluid (porenet.h) as a part of a run.
 *
 * The fluid model is chosen in the case file: a scene with a [porenet]
 * section has the pore network and no resolved fluid.  Without DEM particles
 * the skeleton is a fixed packing read from porenet.packing (a permeameter):
 * the network is built and solved once, and the run reports the pore
 * pressures, the fluxes, the forces and the permeability.  With DEM particles
 * ([particles]) the part is coupled with the DEM (thesis fig. 4.3): the DEM
 * part advances first by one step of its own, then this part computes the
 * pore volume rates from the motion, the pressures and the fluid forces,
 * which act on the particles during the next step (pn_model_couple_dem).
 * The step is the smaller of the DEM step and the viscous limit of the
 * coupled problem (pn_coupled_dt).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "dem.h"
#include "io.h"
#include "porenet.h"
#include "sim.h"
#include "util.h"

typedef struct {
    sim_t *sim;
    pn_model_t m;
    int with_dem;
    dem_t *d;           /* the DEM engine (with particles), once started */
    double g[3];        /* gravity (buoyancy) */
    int started;
    int n;
    double *x, *r;      /* the spheres as the model sees them (the packing, or the DEM's in id order) */
    double *xp, *rp;    /* the fixed packing read from porenet.packing */
    double q[6];
    double kappa[3];
    cfg_t *cfg;         /* the input: a network that cannot be built from it at the start is bad input */
    int failed;         /* the last step failed (m.err): the run diverged */
    /* the state at the start of the step (rollback) */
    struct {
        long n_retri, n_steps, kept_count;
        int vol_current, npore, n;
        double eps_acc, q[6], kappa[3], kept_sum, kept_min;
        double *p, *vol, *vol_prev, *x_prev, *f, *x_tri;
    } prev;
    int snapshots;      /* write the network at the run's snapshot times */
    void (*before_start)(void *ctx); /* called once before the first solve (sim_porenet_before_start) */
    void *before_ctx;
} porenet_part_t;

static const char *const pn_cols[] = {"porenet_q_in_max", "porenet_q_out_max", "porenet_p_max", "porenet_pores"};

/* Periodic axes: bring the centres into the box. */
static void wrap_packing(porenet_part_t *pp)
{
    for (int i = 0; i < pp->n; i++)
        for (int a = 0; a < 3; a++)
            if (pp->m.dom.periodic[a]) {
                double L = pp->m.dom.hi[a] - pp->m.dom.lo[a];
                double v = fmod(pp->xp[3 * i + a] - pp->m.dom.lo[a], L);
                if (v < 0) v += L;
                pp->xp[3 * i + a] = pp->m.dom.lo[a] + v;
            }
    pp->x = pp->xp;
    pp->r = pp->rp;
}

/* An HDF5 packing (the DEM's layout, as [ibm] spheres_file reads it):
 * datasets position [n][3] and radius [n]; the same file can then feed the
 * resolved solver and the network (cases/permeability_crosscheck). */
static int read_packing_h5(cfg_t *cfg, const char *path, porenet_part_t *pp)
{
    long n;
    hid_t f = io_h5_open_packing(cfg, "porenet", "packing", path, &n);
    pp->xp = malloc(3 * (size_t)(n + 1) * sizeof *pp->xp);
    pp->rp = malloc((size_t)(n + 1) * sizeof *pp->rp);
    if (io_h5_read_array(f, "radius", n, pp->rp) != n || io_h5_read_array(f, "position", 3 * n, pp->xp) != 3 * n)
        cfg_fail(cfg, "porenet", "packing", "%s: position must hold 3 values per radius", path);
    H5Fclose(f);
    for (long i = 0; i < n; i++)
        if (!(pp->rp[i] > 0) || !isfinite(pp->rp[i]) || !isfinite(pp->xp[3 * i]) || !isfinite(pp->xp[3 * i + 1]) ||
            !isfinite(pp->xp[3 * i + 2]))
            cfg_fail(cfg, "porenet", "packing", "%s: sphere %ld: the radius must be positive, every value finite", path,
                     i + 1);
    return (int)n;
}

/* A text packing: x y z r per line, # comments. */
static int read_packing_text(cfg_t *cfg, const char *path, porenet_part_t *pp)
{
    FILE *f = fopen(path, "r");
    if (!f) cfg_fail(cfg, "porenet", "packing", "cannot open %s", path);
    char *line = NULL;
    size_t lcap = 0;
    int cap = 1024, n = 0, ln = 0;
    pp->xp = malloc(3 * (size_t)cap * sizeof *pp->xp);
    pp->rp = malloc((size_t)cap * sizeof *pp->rp);
    while (getline(&line, &lcap, f) > 0) {
        ln++;
        char *s = line;
        while (*s == ' ' || *s == '\t') s++;
        if (*s == '#' || *s == '\n' || *s == '\r' || *s == 0) continue;
        if (n == cap) {
            cap *= 2;
            pp->xp = realloc(pp->xp, 3 * (size_t)cap * sizeof *pp->xp);
            pp->rp = realloc(pp->rp, (size_t)cap * sizeof *pp->rp);
        }
        double v[4];
        int k = 0;
        char *save = NULL;
        for (char *tok = strtok_r(s, " \t\r\n", &save); tok && k <= 4; tok = strtok_r(NULL, " \t\r\n", &save), k++)
            if (k == 4 || !cfg_parse_real(tok, &v[k])) k = 5;
        if (k != 4 || !(v[3] > 0))
            cfg_fail(cfg, "porenet", "packing", "%s:%d: expected four numbers x y z r with r > 0", path, ln);
        for (int c = 0; c < 3; c++) pp->xp[3 * n + c] = v[c];
        pp->rp[n] = v[3];
        n++;
    }
    fclose(f);
    free(line);
    return n;
}

static void read_packing(cfg_t *cfg, porenet_part_t *pp)
{
    const char *path = cfg_string(cfg, "porenet", "packing");
    int h5 = io_is_h5_path(path);
    int n = h5 ? read_packing_h5(cfg, path, pp) : read_packing_text(cfg, path, pp);
    if (n < 4) cfg_fail(cfg, "porenet", "packing", "%s: %d spheres (at least 4 needed)", path, n);
    pp->n = n;
    wrap_packing(pp);
}

static void after_solve(porenet_part_t *pp)
{
    pn_face_fluxes(&pp->m.dom, &pp->m.net, pp->m.p, pp->q);
    for (int a = 0; a < 3; a++) pp->kappa[a] = pn_model_permeability(&pp->m, a);
}

/* dt <= 0: the initial state (rigid skeleton).  Returns 0, or -1 with the
 * reason in pp->m.err. */
static int solve_now(porenet_part_t *pp, double dt)
{
    if (pp->with_dem) {
        if (pn_model_couple_dem(&pp->m, pp->d, pp->g, dt)) return -1;
        pp->n = pp->m.n;
        pp->x = pp->m.xid;
        pp->r = pp->m.rid;
    } else if (pn_model_step(&pp->m, pp->n, pp->x, pp->r, 0.0)) {
        return -1;
    }
    after_solve(pp);
    return 0;
}

/* Arithmetic mean diameter of the spheres (κ/d²). */
static double mean_diameter(const porenet_part_t *pp)
{
    double s = 0;
    for (int i = 0; i < pp->n; i++) s += 2 * pp->r[i];
    return pp->n ? s / pp->n : NAN;
}

/* The first solve, once the particles exist (the DEM prepares its packing
 * lazily, at the first step of a new run). */
static void ensure_started(porenet_part_t *pp)
{
    if (pp->started) return;
    pp->started = 1;
    if (pp->before_start) pp->before_start(pp->before_ctx);
    if (pp->with_dem) pp->d = sim_dem_engine(pp->sim);
    if (solve_now(pp, 0.0)) {
        if (!pp->with_dem) cfg_fail(pp->cfg, "porenet", "packing", "%s", pp->m.err);
        const int margin = strstr(pp->m.err, "margin") != NULL;
        cfg_fail(pp->cfg, margin ? "porenet" : "particles", margin ? "margin" : "source",
                 "the network of the first packing cannot be built: %s", pp->m.err);
    }
    double re, sr, por;
    char wbuf[1024];
    if (pn_model_validity(&pp->m, pp->r, wbuf, sizeof wbuf, &re, &sr, &por)) warn("porenet: outside the model's validity:\n%s", wbuf);
    msg("porenet: %d spheres, %d pores (%.2f per sphere), %d throats; triangulation %.3g s, network %.3g s, "
        "factorisation %.3g s\n",
        pp->n, pp->m.net.npore, (double)pp->m.net.npore / pp->n, pp->m.net.nthroat, pp->m.t_tri, pp->m.t_net,
        pp->m.t_factor);
    if (pp->m.dom.clear_h > 0) {
        int nc = 0;
        for (int i = 0; i < pp->m.net.npore; i++) nc += pp->m.net.dirichlet[i] == PN_CLEAR;
        msg("porenet: %d pores of the clear fluid (power radius above %g m = porenet.clear_fluid_radius mean "
            "diameters, connected to the outside of the packing): hydrostatic; %d neighbours across a periodic face "
            "taken as the nearest pore of the box\n", nc, pp->m.dom.clear_h, pp->m.net.n_seam);
    }
    if (pp->with_dem)
        msg("porenet: coupled with the DEM, viscous step limit %.4g s (DEM step %.4g s)\n", pn_coupled_dt(&pp->m, pp->d),
            dem_dt(pp->d));
    const double d = mean_diameter(pp);
    for (int a = 0; a < 3; a++)
        if (isfinite(pp->kappa[a]))
            msg("porenet: permeability along %c = %.6e L^2 (L the length unit of the case: m^2 for lengths in m), "
                "kappa/d^2 = %.6e (d = %.6g, the mean diameter)\n",
                'x' + a, pp->kappa[a], pp->kappa[a] / (d * d), d);
}

static double part_stable_dt(void *ctx)
{
    porenet_part_t *pp = ctx;
    ensure_started(pp);
    if (!pp->with_dem) return INFINITY; /* a rigid skeleton sets no limit */
    /* porenet.dem_steps DEM steps per coupled step, within the viscous limit (thesis 4.21) */
    return pn_coupled_step(&pp->m, pp->d);
}

static void part_advance(void *ctx, double dt)
{
    porenet_part_t *pp = ctx;
    ensure_started(pp);
    /* fixed packing: the same steady solution (boundary values may change on restart) */
    pp->failed = solve_now(pp, pp->with_dem ? dt : 0.0) != 0;
}

static void part_diagnostics(void *ctx, double *c)
{
    porenet_part_t *pp = ctx;
    double qin = 0, qout = 0, pmax = 0;
    for (int f = 0; f < 6; f++) {
        qin = fmax(qin, pp->q[f]);
        qout = fmax(qout, -pp->q[f]);
    }
    for (int i = 0; i < pp->m.net.npore; i++) pmax = fmax(pmax, fabs(pp->m.p[i]));
    c[0] = qin;
    c[1] = qout;
    c[2] = pmax;
    c[3] = pp->m.net.npore;
}

static int part_diverged(void *ctx, char *why, size_t n)
{
    porenet_part_t *pp = ctx;
    if (pp->failed) {
        snprintf(why, n, "%s", pp->m.err);
        return 1;
    }
    for (int i = 0; i < pp->m.net.npore; i++)
        if (!isfinite(pp->m.p[i])) {
            snprintf(why, n, "non-finite pore pressure");
            return 1;
        }
    return 0;
}

/* ---- the state: rollback and checkpoints ---- */

static double *copy_of(double *dst, const double *src, size_t n)
{
    dst = realloc(dst, (n ? n : 1) * sizeof *dst);
    if (n) memcpy(dst, src, n * sizeof *dst);
    return dst;
}

static void part_keep_previous(void *ctx)
{
    porenet_part_t *pp = ctx;
    ensure_started(pp);
    pn_model_t *m = &pp->m;
    const size_t np = (size_t)m->net.npore, n3 = 3 * (size_t)m->n;
    pp->prev.n_retri = m->n_retri;
    pp->prev.n_steps = m->n_steps;
    pp->prev.vol_current = m->vol_current;
    pp->prev.npore = m->net.npore;
    pp->prev.n = m->n;
    pp->prev.eps_acc = m->eps_acc;
    pp->prev.kept_count = m->kept_count;
    pp->prev.kept_sum = m->kept_sum;
    pp->prev.kept_min = m->kept_min;
    memcpy(pp->prev.q, pp->q, sizeof pp->q);
    memcpy(pp->prev.kappa, pp->kappa, sizeof pp->kappa);
    pp->prev.p = copy_of(pp->prev.p, m->p, np);
    pp->prev.vol = copy_of(pp->prev.vol, m->vol, np);
    pp->prev.vol_prev = copy_of(pp->prev.vol_prev, m->vol_prev, np);
    pp->prev.x_prev = copy_of(pp->prev.x_prev, m->x_prev, n3);
    pp->prev.f = copy_of(pp->prev.f, m->f, n3);
    pp->prev.x_tri = copy_of(pp->prev.x_tri, m->x_tri, n3);
}

/* The model's state from saved values: the triangulation, network and
 * factorisation rebuilt from the positions they were built from when they
 * are not those (then: the same, bit for bit), and the step's values. */
static void set_state(porenet_part_t *pp, long n_retri, long n_steps, int vol_current, double eps_acc,
                      const double *x_tri, const double *p, const double *vol, const double *vol_prev,
                      const double *x_prev, const double *f)
{
    pn_model_t *m = &pp->m;
    const int n = m->n;
    const double *r = pp->with_dem ? m->rid : pp->r;
    if (!m->built || !m->sol || n_retri != m->n_retri || memcmp(x_tri, m->x_tri, 3 * (size_t)n * sizeof *x_tri))
        if (pn_model_rebuild(m, n, x_tri, r)) die("porenet: %s", m->err);
    const size_t np = (size_t)m->net.npore, n3 = 3 * (size_t)n;
    memcpy(m->p, p, np * sizeof *p);
    memcpy(m->vol, vol, np * sizeof *vol);
    memcpy(m->vol_prev, vol_prev, np * sizeof *vol_prev);
    memcpy(m->x_prev, x_prev, n3 * sizeof *x_prev);
    memcpy(m->f, f, n3 * sizeof *f);
    m->n_retri = n_retri;
    m->n_steps = n_steps;
    m->vol_current = vol_current;
    m->eps_acc = eps_acc;
}

static void part_restore_previous(void *ctx)
{
    porenet_part_t *pp = ctx;
    set_state(pp, pp->prev.n_retri, pp->prev.n_steps, pp->prev.vol_current, pp->prev.eps_acc, pp->prev.x_tri,
              pp->prev.p, pp->prev.vol, pp->prev.vol_prev, pp->prev.x_prev, pp->prev.f);
    /* the re-meshing statistics as before the step (set_state's rebuild is not a re-meshing of the run) */
    pp->m.kept_count = pp->prev.kept_count;
    pp->m.kept_sum = pp->prev.kept_sum;
    pp->m.kept_min = pp->prev.kept_min;
    memcpy(pp->q, pp->prev.q, sizeof pp->q);
    memcpy(pp->kappa, pp->prev.kappa, sizeof pp->kappa);
    pp->failed = 0; /* the DEM part brought back its external forces */
}

static void part_write_fields(void *ctx, double time, long step)
{
    (void)step;
    porenet_part_t *pp = ctx;
    ensure_started(pp);
    if (pp->snapshots) pn_write_snapshot(&pp->m, pp->x, pp->sim->out.dir, time);
}

static void part_checkpoint_write(void *ctx, hid_t g)
{
    porenet_part_t *pp = ctx;
    ensure_started(pp);
    pn_model_state_write(&pp->m, g);
}

/* The state of the run that wrote the checkpoint (state.c): the
 * triangulation of its last rebuild, the strain accumulated since, the
 * previous positions and volumes, the pressures, the forces the DEM holds in
 * its next step and the snapshot index. */
static void part_checkpoint_read(void *ctx, hid_t g, const char *path)
{
    porenet_part_t *pp = ctx;
    pp->started = 1;
    pp->d = sim_dem_engine(pp->sim);
    pn_model_gather(&pp->m, pp->d);
    if (pn_model_state_read(&pp->m, g, dem_count(pp->d), pp->m.rid)) die("%s: porenet: %s", path, pp->m.err);
    if (!pp->m.built) die("%s: porenet: the checkpoint holds no network", path);
    /* the snapshots the lost continuation wrote, and the index of ours */
    io_outdir_remove_numbered(&pp->sim->out, "porenet_", ".h5", pp->m.nsnap);
    pn_write_index(&pp->m, pp->sim->out.dir);
    pn_model_apply_forces(&pp->m, pp->d, pp->g);
    pp->n = pp->m.n;
    pp->x = pp->m.xid;
    pp->r = pp->m.rid;
    after_solve(pp);
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    porenet_part_t *pp = ctx;
    ensure_started(pp);
    pn_model_t *m = &pp->m;
    char key[160];
    static const char *fn[6] = {"x_lo", "x_hi", "y_lo", "y_hi", "z_lo", "z_hi"};
#define KEY(...) (snprintf(key, sizeof key, __VA_ARGS__), key)
    io_summary_long(y, KEY("%s.spheres", prefix), pp->n);
    io_summary_long(y, KEY("%s.pores", prefix), m->net.npore);
    io_summary_long(y, KEY("%s.throats", prefix), m->net.nthroat);
    io_summary_long(y, KEY("%s.triangulations", prefix), m->n_retri);
    io_summary_long(y, KEY("%s.coupled_steps", prefix), m->n_steps);
    if (m->dom.clear_h > 0) {
        /* the last network: its clear-fluid pores and its neighbours across a periodic face taken as the
         * nearest pore of the box (network.c) */
        long nc = 0;
        for (int i = 0; i < m->net.npore; i++) nc += m->net.dirichlet[i] == PN_CLEAR;
        io_summary_long(y, KEY("%s.clear_pores", prefix), nc);
        io_summary_long(y, KEY("%s.seam_neighbours", prefix), m->net.n_seam);
    }
    if (m->kept_count > 0) {
        /* re-meshing: the mean and smallest fraction of a new triangulation's tetrahedra of the box that
         * the one it replaced had */
        io_summary_double(y, KEY("%s.remesh_kept_mean", prefix), m->kept_sum / m->kept_count);
        io_summary_double(y, KEY("%s.remesh_kept_min", prefix), m->kept_min);
        io_summary_double(y, KEY("%s.time_rebuilds", prefix), m->t_rebuild);
    }
    const double d = mean_diameter(pp);
    io_summary_double(y, KEY("%s.mean_diameter", prefix), d);
    for (int a = 0; a < 3; a++)
        if (isfinite(pp->kappa[a])) {
            io_summary_double(y, KEY("%s.permeability_%c", prefix, 'x' + a), pp->kappa[a]);
            io_summary_double(y, KEY("%s.permeability_over_d2_%c", prefix, 'x' + a), pp->kappa[a] / (d * d));
        }
    for (int f = 0; f < 6; f++)
        if (!m->dom.periodic[f / 2]) io_summary_double(y, KEY("%s.flux_in.%s", prefix, fn[f]), pp->q[f]);
    double F[6][3], fs[3] = {0, 0, 0};
    pn_face_forces(&m->dom, &m->net, m->p, F);
    for (int i = 0; i < pp->n; i++)
        for (int a = 0; a < 3; a++) fs[a] += m->f[3 * i + a];
    for (int a = 0; a < 3; a++) io_summary_double(y, KEY("%s.force_on_spheres_%c", prefix, 'x' + a), fs[a]);
    for (int f = 0; f < 6; f++)
        if (!m->dom.periodic[f / 2])
            for (int a = 0; a < 3; a++) io_summary_double(y, KEY("%s.force_on_face.%s_%c", prefix, fn[f], 'x' + a), F[f][a]);
    double re, sr, por;
    char wbuf[1024];
    int nw = pn_model_validity(m, pp->r, wbuf, sizeof wbuf, &re, &sr, &por);
    io_summary_double(y, KEY("%s.pore_reynolds", prefix), re);
    io_summary_double(y, KEY("%s.size_ratio_min", prefix), sr);
    io_summary_double(y, KEY("%s.porosity", prefix), por);
    io_summary_long(y, KEY("%s.validity_warnings", prefix), nw);
    io_summary_double(y, KEY("%s.void_partition", prefix), m->net.void_sum / (m->net.box_volume - m->net.solid_volume));
    io_summary_double(y, KEY("%s.time_triangulation", prefix), m->t_tri);
    io_summary_double(y, KEY("%s.time_network", prefix), m->t_net);
    io_summary_double(y, KEY("%s.time_factorisation", prefix), m->t_factor);
    io_summary_double(y, KEY("%s.time_solves", prefix), m->t_solve);
    io_summary_double(y, KEY("%s.time_forces", prefix), m->t_force);
    io_summary_double(y, KEY("%s.time_volume_rates", prefix), m->t_vol);
#undef KEY
}

static void part_destroy(void *ctx)
{
    porenet_part_t *pp = ctx;
    double *prev[] = {pp->prev.p, pp->prev.vol, pp->prev.vol_prev, pp->prev.x_prev, pp->prev.f, pp->prev.x_tri};
    for (size_t i = 0; i < sizeof prev / sizeof prev[0]; i++) free(prev[i]);
    pn_model_free(&pp->m);
    free(pp->xp);
    free(pp->rp);
    free(pp);
}

void sim_add_porenet(sim_t *s, cfg_t *cfg)
{
    porenet_part_t *pp = xcalloc(1, sizeof *pp);
    pp->sim = s;
    pp->cfg = cfg;
    pn_model_from_config(cfg, &pp->m);
    pp->with_dem = cfg_has_section(cfg, "particles");
    const int snaps = cfg_enum(cfg, "porenet", "snapshots");
    pp->snapshots = snaps == 1 || (snaps == 0 && pp->with_dem);
    if (pp->with_dem) {
        if (cfg_has(cfg, "porenet", "packing"))
            cfg_fail(cfg, "porenet", "packing", "the scene has DEM particles ([particles]): give one or the other");
        cfg_vec3(cfg, "dem", "gravity", pp->g);
        /* the DEM's faces ([boundary]) and the network's must agree on periodicity */
        static const char *fn[6] = {"x_lo", "x_hi", "y_lo", "y_hi", "z_lo", "z_hi"};
        for (int f = 0; f < 6; f++)
            if ((cfg_enum(cfg, "boundary", fn[f]) == 0) != pp->m.dom.periodic[f / 2])
                cfg_fail(cfg, "porenet", fn[f], "must be periodic exactly when boundary.%s is (the DEM's face)", fn[f]);
        /* the network's images of the spheres must fit in the box (pn_triangulate) */
        const dem_t *d = sim_dem_engine_unprepared(s);
        double rmax = 0;
        for (int i = 0; d && i < dem_count(d); i++) rmax = fmax(rmax, dem_radii(d)[i]);
        const double margin = pp->m.margin > 0 ? pp->m.margin : 6 * rmax;
        for (int a = 0; a < 3; a++)
            if (margin >= pp->m.dom.hi[a] - pp->m.dom.lo[a])
                cfg_fail(cfg, pp->m.margin > 0 ? "porenet" : "domain", pp->m.margin > 0 ? "margin" : "length",
                         "the box length along %c (%g) is not larger than the network's image margin %g%s", 'x' + a,
                         pp->m.dom.hi[a] - pp->m.dom.lo[a], margin, pp->m.margin > 0 ? "" : " (3 largest diameters)");
    } else {
        read_packing(cfg, pp);
        ensure_started(pp);
    }
    sim_part_t part = {
        .name = "porenet",
        .ctx = pp,
        .stable_dt = part_stable_dt,
        .advance = part_advance,
        .ncol = 4,
        .col_names = pn_cols,
        .diagnostics = part_diagnostics,
        .diverged = part_diverged,
        .keep_previous = part_keep_previous,
        .restore_previous = part_restore_previous,
        .write_fields = part_write_fields,
        /* a fixed packing is solved once: nothing to restart from */
        .checkpoint_write = pp->with_dem ? part_checkpoint_write : NULL,
        .checkpoint_read = pp->with_dem ? part_checkpoint_read : NULL,
        .summary = part_summary,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}

static porenet_part_t *find_part(sim_t *s)
{
    for (int p = 0; p < s->npart; p++)
        if (!strcmp(s->part[p].name, "porenet")) return s->part[p].ctx;
    return NULL;
}

pn_model_t *sim_porenet_model(sim_t *s)
{
    porenet_part_t *pp = find_part(s);
    return pp ? &pp->m : NULL;
}

void sim_porenet_before_start(sim_t *s, void (*fn)(void *ctx), void *ctx)
{
    porenet_part_t *pp = find_part(s);
    if (!pp) die("sim_porenet_before_start: the scene has no pore network");
    pp->before_start = fn;
    pp->before_ctx = ctx;
}
