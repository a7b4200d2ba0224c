/* sim_ibm.c — the immersed boundary as a part of a run (sim.h).  The work
 * is done inside the fluid step through the fluid's stage hooks (ibm.h);
 * this part adds the spheres' time step limit, their time-series columns,
 * divergence checks and rollback, the solid fraction in the fluid
 * snapshots, sphere snapshots (spheres_NNNNN.h5 + spheres.xmf for ParaView,
 * and rows of spheres.csv), their exact state in checkpoints, and
 * summary.json entries. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "ibm.h"
#include "overlap.h"
#include "sim.h"
#include "util.h"

#define MAX_SERIES_SPHERES 4

typedef struct {
    sim_t *sim;
    ibm_t *ibm;
    ibm_sphere_t *prev;   /* spheres at the start of the step (rollback) */
    int nseries;          /* spheres with columns in series.csv */
    int ncol_per;         /* columns per sphere */
    char names[MAX_SERIES_SPHERES * 15][24];
    const char *col[MAX_SERIES_SPHERES * 15];
    /* sphere snapshots */
    int nsnap;            /* written so far, including earlier runs */
    double *snap_time;
    int snap_cap;
    io_series_t *csv;     /* spheres.csv (rank 0) */
    long csv_last_step;   /* step of its last rows (-1: none) */
    double *cell;         /* scratch field for the solid fraction */
    double wall_steps;    /* wall time of the fluid steps of this run */
} ibm_part_t;

/* Columns per sphere: what the geometry has. */
static int columns(const grid_t *g, const char **what)
{
    static const char *c3[] = {"x", "y", "z", "u", "v", "w", "ox", "oy", "oz", "fx", "fy", "fz", "tx", "ty", "tz"};
    static const char *c2[] = {"x", "y", "u", "v", "oz", "fx", "fy", "tz"};
    static const char *ca[] = {"y", "v", "fy"};
    const char **src = g->geom == GEOM_AXI ? ca : g->dim == 2 ? c2 : c3;
    int n = g->geom == GEOM_AXI ? 3 : g->dim == 2 ? 8 : 15;
    for (int i = 0; i < n; i++) what[i] = src[i];
    return n;
}

/* The values of those columns for sphere s. */
static void sphere_values(const grid_t *g, const ibm_sphere_t *s, double *v)
{
    if (g->geom == GEOM_AXI) {
        v[0] = s->x[1], v[1] = s->u[1], v[2] = s->force[1];
    } else if (g->dim == 2) {
        v[0] = s->x[0], v[1] = s->x[1], v[2] = s->u[0], v[3] = s->u[1], v[4] = s->omega[2];
        v[5] = s->force[0], v[6] = s->force[1], v[7] = s->torque[2];
    } else {
        for (int c = 0; c < 3; c++) {
            v[c] = s->x[c];
            v[3 + c] = s->u[c];
            v[6 + c] = s->omega[c];
            v[9 + c] = s->force[c];
            v[12 + c] = s->torque[c];
        }
    }
}

static double part_stable_dt(void *ctx)
{
    ibm_part_t *ip = ctx;
    const fluid_t *f = ip->ibm->f;
    if (f->prm.dt_fixed > 0) return INFINITY; /* the user's fixed step rules */
    return ibm_stable_dt(ip->ibm, f->prm.cfl);
}

static void part_diagnostics(void *ctx, double *c)
{
    ibm_part_t *ip = ctx;
    for (int p = 0; p < ip->nseries; p++) sphere_values(ip->ibm->g, &ip->ibm->s[p], c + p * ip->ncol_per);
}

/* A sphere state that is not finite, or a free sphere whose centre left the
 * domain through a wall. */
static int part_diverged(void *ctx, char *why, size_t n)
{
    ibm_part_t *ip = ctx;
    const ibm_t *ibm = ip->ibm;
    const grid_t *g = ibm->g;
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        for (int c = 0; c < 3; c++)
            if (!isfinite(s->x[c]) || !isfinite(s->u[c]) || !isfinite(s->omega[c]) || !isfinite(s->force[c])) {
                snprintf(why, n, "sphere %d has a non-finite position, velocity or force", p + 1);
                return 1;
            }
        for (int d = 0; d < g->dim; d++)
            if (!g->periodic[d] && (s->x[d] < g->x0[d] || s->x[d] > g->x0[d] + g->L[d])) {
                snprintf(why, n, "the centre of sphere %d left the domain through a %c wall (%c = %g)", p + 1, "xyz"[d],
                         "xyz"[d], s->x[d]);
                return 1;
            }
    }
    return 0;
}

/* A free sphere touching a wall or another sphere: the immersed boundary
 * has no contact model (the fluid alone would let it sink slowly through),
 * so the run stops there (sim.h, halt).  Contacts need the DEM: spheres given
 * as [particles] of a coupled scene. */
static int part_halt(void *ctx, char *why, size_t n)
{
    ibm_part_t *ip = ctx;
    const ibm_t *ibm = ip->ibm;
    const grid_t *g = ibm->g;
    static const char *face[3][2] = {{"x_lo", "x_hi"}, {"y_lo", "y_hi"}, {"z_lo", "z_hi"}};
    int nfree = 0;
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        if (s->kind != IBM_FREE) continue;
        nfree++;
        for (int d = 0; d < g->dim; d++)
            for (int side = 0; side < 2; side++) {
                if (g->bc.type[d][side] == BC_PERIODIC || g->bc.type[d][side] == BC_AXIS) continue;
                const double gap = side ? g->x0[d] + g->L[d] - (s->x[d] + s->radius) : s->x[d] - s->radius - g->x0[d];
                if (gap < 0) {
                    snprintf(why, n, "free sphere %d touched the %s wall (%c = %g, radius %g): immersed spheres have "
                             "no contact model (give them one as [particles] of a coupled scene)", p + 1,
                             face[d][side], "xyz"[d], s->x[d], s->radius);
                    return 1;
                }
            }
    }
    if (nfree == 0 || ibm->n < 2) return 0;
    overlap_box_t box = {.dim = g->dim};
    double *x = xcalloc(3 * (size_t)ibm->n, sizeof(double)), *r = xcalloc((size_t)ibm->n, sizeof(double));
    unsigned char *act = xcalloc((size_t)ibm->n, 1);
    for (int d = 0; d < 3; d++) {
        box.lo[d] = g->x0[d];
        box.L[d] = g->L[d];
        box.periodic[d] = g->periodic[d];
    }
    for (int p = 0; p < ibm->n; p++) {
        memcpy(&x[3 * p], ibm->s[p].x, 3 * sizeof(double));
        r[p] = ibm->s[p].radius;
        act[p] = ibm->s[p].kind == IBM_FREE;
    }
    int i = 0, j = 0;
    double delta = 0;
    const int hit = overlap_find(&box, ibm->n, x, r, act, 0.0, &i, &j, &delta);
    free(x);
    free(r);
    free(act);
    if (hit)
        snprintf(why, n, "spheres %d and %d touched (overlap %.3g): immersed spheres have no contact model (give them "
                 "one as [particles] of a coupled scene)", i + 1, j + 1, delta);
    return hit;
}

static void part_keep_previous(void *ctx)
{
    ibm_part_t *ip = ctx;
    if (!ip->prev) ip->prev = xcalloc((size_t)ip->ibm->n + 1, sizeof *ip->prev);
    memcpy(ip->prev, ip->ibm->s, (size_t)ip->ibm->n * sizeof *ip->prev);
}

static void part_restore_previous(void *ctx)
{
    ibm_part_t *ip = ctx;
    if (!ip->prev) return;
    memcpy(ip->ibm->s, ip->prev, (size_t)ip->ibm->n * sizeof *ip->prev);
    ibm_rebuild_geometry(ip->ibm); /* the fluid part restored its fields first */
}

/* max |u(n+1) − u(n)| / (Δt max|u(n+1)|) over the spheres' velocities, and
 * with steady_measure = integrals the same of the forces on the spheres */
static double part_change_rate(void *ctx, double dt)
{
    ibm_part_t *ip = ctx;
    if (!ip->prev) return INFINITY;
    double du = 0, um = 0, df = 0, fm = 0;
    for (int p = 0; p < ip->ibm->n; p++)
        for (int c = 0; c < 3; c++) {
            du = fmax(du, fabs(ip->ibm->s[p].u[c] - ip->prev[p].u[c]));
            um = fmax(um, fabs(ip->ibm->s[p].u[c]));
            df = fmax(df, fabs(ip->ibm->s[p].force[c] - ip->prev[p].force[c]));
            fm = fmax(fm, fabs(ip->ibm->s[p].force[c]));
        }
    const double rate = um > 0 ? du / (dt * um) : 0.0;
    if (!ip->sim->prm.steady_integrals) return rate;
    return fmax(rate, fm > 0 ? df / (dt * fm) : 0.0);
}

/* The solid fraction at the cell centres, in every fluid snapshot. */
static void write_solid_fraction(void *ctx, io_snapshots_t *snap)
{
    ibm_part_t *ip = ctx;
    if (!ip->cell) ip->cell = field_alloc(ip->ibm->g);
    ibm_solid_fraction_cell(ip->ibm, ip->cell);
    io_snapshot_cell_scalar(snap, "solid_fraction", ip->cell);
}

/* spheres.xmf: the sphere snapshots as a temporal collection of point sets
 * (rank 0; rewritten whole, so it is valid whenever the run stops). */
static void write_xmf(const ibm_part_t *ip)
{
    if (mpi_rank() != 0) return;
    char path[IO_PATH_MAX + 32], tmp[IO_PATH_MAX + 40];
    snprintf(path, sizeof path, "%s/spheres.xmf", ip->sim->out.dir);
    FILE *f = atomic_open(path, tmp, sizeof tmp);
    if (!f) return;
    int n = ip->ibm->n;
    fprintf(f, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n"
               "  <Domain>\n  <Grid Name=\"spheres\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    static const char *vec[] = {"velocity", "omega", "force", "torque"};
    static const char *sca[] = {"radius", "density", "kind"};
    for (int i = 0; i < ip->nsnap; i++) {
        char file[64];
        snprintf(file, sizeof file, "spheres_%05d.h5", i);
        fprintf(f,
                "    <Grid Name=\"spheres_%05d\" GridType=\"Uniform\">\n      <Time Value=\"%.17g\"/>\n"
                "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%d\"/>\n"
                "      <Geometry GeometryType=\"XYZ\">\n"
                "        <DataItem Dimensions=\"%d 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/position</DataItem>\n"
                "      </Geometry>\n",
                i, ip->snap_time[i], n, n, file);
        for (int a = 0; a < 7; a++) {
            int vector = a < 4;
            const char *name = vector ? vec[a] : sca[a - 4];
            fprintf(f,
                    "      <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n"
                    "        <DataItem Dimensions=\"%d%s\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/%s</DataItem>\n"
                    "      </Attribute>\n",
                    name, vector ? "Vector" : "Scalar", n, vector ? " 3" : "", file, name);
        }
        fprintf(f, "    </Grid>\n");
    }
    fprintf(f, "  </Grid>\n  </Domain>\n</Xdmf>\n");
    atomic_commit(f, tmp, path);
}

/* Per-sphere arrays: 3-vectors [n][3] and scalars [n]. */
static void gather(const ibm_t *ibm, size_t off, int ncomp, double *buf)
{
    for (int p = 0; p < ibm->n; p++) {
        const double *v = (const double *)((const char *)&ibm->s[p] + off);
        for (int c = 0; c < ncomp; c++) buf[(long)p * ncomp + c] = v[c];
    }
}

static void write_sphere_arrays(const ibm_t *ibm, hid_t loc, int full)
{
    int n = ibm->n;
    double *buf = xcalloc(3 * (size_t)n + 1, sizeof(double));
    static const struct {
        const char *name;
        size_t off;
        int ncomp, state;
    } a[] = {{"position", offsetof(ibm_sphere_t, x), 3, 0},
             {"velocity", offsetof(ibm_sphere_t, u), 3, 0},
             {"omega", offsetof(ibm_sphere_t, omega), 3, 0},
             {"force", offsetof(ibm_sphere_t, force), 3, 0},
             {"torque", offsetof(ibm_sphere_t, torque), 3, 0},
             {"radius", offsetof(ibm_sphere_t, radius), 1, 0},
             {"density", offsetof(ibm_sphere_t, density), 1, 0},
             {"alpha_centre", offsetof(ibm_sphere_t, xa), 3, 1},
             {"du_prev", offsetof(ibm_sphere_t, du_prev), 3, 1},
             {"dw_prev", offsetof(ibm_sphere_t, dw_prev), 3, 1},
             {"predicted_centre", offsetof(ibm_sphere_t, xpred), 3, 1}};
    for (size_t i = 0; i < sizeof a / sizeof a[0]; i++) {
        if (a[i].state && !full) continue;
        gather(ibm, a[i].off, a[i].ncomp, buf);
        if (a[i].ncomp == 3)
            io_h5_write_matrix(loc, a[i].name, n, 3, buf);
        else
            io_h5_write_array(loc, a[i].name, n, buf);
    }
    for (int p = 0; p < n; p++) buf[p] = ibm->s[p].kind;
    io_h5_write_array(loc, "kind", n, buf);
    free(buf);
}

/* spheres.csv (collective): a new file, or (r) the one a restart continues */
static void open_csv(ibm_part_t *ip, const io_series_resume_t *r)
{
    static const char *names[] = {"step", "time", "sphere", "x",  "y",  "z",  "u",  "v",  "w",
                                  "ox",   "oy",   "oz",     "fx", "fy", "fz", "tx", "ty", "tz"};
    char path[IO_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/spheres.csv", ip->sim->out.dir);
    ip->csv = io_series_open(path, 18, names, r);
}

static void part_write_fields(void *ctx, double time, long step)
{
    ibm_part_t *ip = ctx;
    const ibm_t *ibm = ip->ibm;
    char path[IO_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/spheres_%05d.h5", ip->sim->out.dir, ip->nsnap);
    hid_t f = io_h5_create(path, ibm->g->comm);
    io_h5_attr_double(f, "time", time);
    io_h5_attr_long(f, "step", step);
    io_h5_attr_string(f, "force", "hydrodynamic force of the pressure relative to hydrostatic and the viscous "
                                  "stress, mean over the last step (the buoyancy -rho V g is not included)");
    write_sphere_arrays(ibm, f, 0);
    io_h5_close(f);
    if (ip->nsnap == ip->snap_cap) {
        ip->snap_cap = ip->snap_cap ? 2 * ip->snap_cap : 64;
        ip->snap_time = realloc(ip->snap_time, (size_t)ip->snap_cap * sizeof(double));
    }
    ip->snap_time[ip->nsnap++] = time;
    write_xmf(ip);
    /* spheres.csv: one row per sphere */
    if (!ip->csv) open_csv(ip, NULL);
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        double row[18] = {(double)step, time, p + 1};
        for (int c = 0; c < 3; c++) {
            row[3 + c] = s->x[c];
            row[6 + c] = s->u[c];
            row[9 + c] = s->omega[c];
            row[12 + c] = s->force[c];
            row[15 + c] = s->torque[c];
        }
        io_series_row(ip->csv, row);
    }
    ip->csv_last_step = step;
}

static void part_checkpoint_write(void *ctx, hid_t grp)
{
    ibm_part_t *ip = ctx;
    io_h5_attr_long(grp, "spheres", ip->ibm->n);
    io_h5_attr_long(grp, "snapshots", ip->nsnap);
    io_h5_attr_long(grp, "csv_last_step", ip->csv_last_step);
    if (ip->csv) io_h5_attr_hash(grp, "csv_hash", io_series_hash(ip->csv, ip->sim->step), ip->ibm->g->comm);
    write_sphere_arrays(ip->ibm, grp, 1);
    double *h = xcalloc((size_t)ip->ibm->n + 1, sizeof(double));
    for (int p = 0; p < ip->ibm->n; p++) h[p] = ip->ibm->s[p].history;
    io_h5_write_array(grp, "history", ip->ibm->n, h);
    free(h);
    if (ip->nsnap > 0) io_h5_write_array(grp, "snapshot_times", ip->nsnap, ip->snap_time);
}

static void part_checkpoint_read(void *ctx, hid_t grp, const char *path)
{
    ibm_part_t *ip = ctx;
    ibm_t *ibm = ip->ibm;
    long n = 0, ns = 0;
    if (io_h5_get_attr_long(grp, "spheres", &n) || n != ibm->n)
        die("%s: /ibm holds %ld spheres, the case has %d", path, n, ibm->n);
    double *buf = xcalloc(3 * (size_t)n + 1, sizeof(double));
    static const struct {
        const char *name;
        size_t off;
        int ncomp;
    } a[] = {{"position", offsetof(ibm_sphere_t, x), 3},      {"velocity", offsetof(ibm_sphere_t, u), 3},
             {"omega", offsetof(ibm_sphere_t, omega), 3},     {"force", offsetof(ibm_sphere_t, force), 3},
             {"torque", offsetof(ibm_sphere_t, torque), 3},   {"alpha_centre", offsetof(ibm_sphere_t, xa), 3},
             {"du_prev", offsetof(ibm_sphere_t, du_prev), 3}, {"dw_prev", offsetof(ibm_sphere_t, dw_prev), 3}};
    for (size_t i = 0; i < sizeof a / sizeof a[0]; i++) {
        if (io_h5_read_array(grp, a[i].name, 3 * n, buf) != a[i].ncomp * n) die("%s: /ibm/%s is missing", path, a[i].name);
        for (int p = 0; p < n; p++) memcpy((char *)&ibm->s[p] + a[i].off, buf + 3 * p, 3 * sizeof(double));
    }
    /* the centre predicted by the last step (external spheres' moves, ibm.h);
     * checkpoints written before it existed: the centre itself */
    if (io_h5_read_array(grp, "predicted_centre", 3 * n, buf) == 3 * n)
        for (int p = 0; p < n; p++) memcpy(ibm->s[p].xpred, buf + 3 * p, 3 * sizeof(double));
    else
        for (int p = 0; p < n; p++) memcpy(ibm->s[p].xpred, ibm->s[p].x, 3 * sizeof(double));
    free(buf);
    if (io_h5_get_attr_long(grp, "snapshots", &ns) == 0 && ns > 0) {
        ip->snap_cap = (int)ns + 64;
        ip->snap_time = realloc(ip->snap_time, (size_t)ip->snap_cap * sizeof(double));
        if (io_h5_read_array(grp, "snapshot_times", ns, ip->snap_time) != ns) die("%s: /ibm/snapshot_times", path);
        ip->nsnap = (int)ns;
    }
    io_series_resume_t r = {ip->sim->step, -1, 0, 0};
    if (io_h5_get_attr_long(grp, "csv_last_step", &r.last_row)) r.last_row = -1;
    r.has_hash = io_h5_get_attr_hash(grp, "csv_hash", &r.hash) == 0;
    ip->csv_last_step = r.last_row;
    if (!ip->csv) open_csv(ip, &r); /* cut after the checkpoint's rows, checked */
    /* the snapshots the lost continuation wrote, and the index of ours */
    io_outdir_remove_numbered(&ip->sim->out, "spheres_", ".h5", ip->nsnap);
    write_xmf(ip);
    ibm_rebuild_geometry(ibm);
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    ibm_part_t *ip = ctx;
    const ibm_t *ibm = ip->ibm;
    char key[160];
#define KEY(...) (snprintf(key, sizeof key, __VA_ARGS__), key)
    io_summary_long(y, KEY("%s.spheres", prefix), ibm->n);
    double g = sqrt(ibm->prm.gravity[0] * ibm->prm.gravity[0] + ibm->prm.gravity[1] * ibm->prm.gravity[1] +
                    ibm->prm.gravity[2] * ibm->prm.gravity[2]);
    for (int p = 0; p < ibm->n && p < MAX_SERIES_SPHERES; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        static const char *comp[] = {"x", "y", "z"};
        for (int c = 0; c < ibm->g->dim; c++) {
            io_summary_double(y, KEY("%s.sphere%d.position_%s", prefix, p + 1, comp[c]), s->x[c]);
            io_summary_double(y, KEY("%s.sphere%d.velocity_%s", prefix, p + 1, comp[c]), s->u[c]);
            io_summary_double(y, KEY("%s.sphere%d.force_%s", prefix, p + 1, comp[c]), s->force[c]);
        }
        if (ibm->g->dim == 3)
            for (int c = 0; c < 3; c++)
                io_summary_double(y, KEY("%s.sphere%d.torque_%s", prefix, p + 1, comp[c]), s->torque[c]);
        if (s->kind == IBM_FREE && g > 0) {
            /* velocity along gravity: the terminal velocity once steady */
            double v = 0;
            for (int c = 0; c < 3; c++) v += s->u[c] * ibm->prm.gravity[c] / g;
            io_summary_double(y, KEY("%s.sphere%d.settling_velocity", prefix, p + 1), v);
        }
    }
    double wall = ibm->wall_alpha + ibm->wall_forcing + ibm->wall_integrals;
    io_summary_double(y, KEY("%s.wall_time", prefix), wall);
    io_summary_double(y, KEY("%s.wall_time_alpha", prefix), ibm->wall_alpha);
    io_summary_double(y, KEY("%s.wall_time_forcing", prefix), ibm->wall_forcing);
    io_summary_double(y, KEY("%s.wall_time_integrals", prefix), ibm->wall_integrals);
#undef KEY
}

static void part_destroy(void *ctx)
{
    ibm_part_t *ip = ctx;
    ibm_free(ip->ibm);
    io_series_close(ip->csv);
    free(ip->prev);
    free(ip->snap_time);
    free(ip->cell);
    free(ip);
}

void sim_add_ibm(sim_t *s, cfg_t *cfg) { sim_add_ibm_with(s, cfg, NULL, 0); }

struct ibm *sim_add_ibm_with(sim_t *s, cfg_t *cfg, const void *extra, int nextra)
{
    ibm_part_t *ip = xcalloc(1, sizeof *ip);
    ip->sim = s;
    ip->csv_last_step = -1;
    ip->ibm = ibm_create_from_config_with(cfg, s->fluid, extra, nextra);
    const grid_t *g = ip->ibm->g;
    ip->nseries = cfg_int(cfg, "ibm", "series_spheres");
    if (ip->nseries > ip->ibm->n) ip->nseries = ip->ibm->n;
    const char *what[15];
    ip->ncol_per = columns(g, what);
    for (int p = 0; p < ip->nseries; p++)
        for (int c = 0; c < ip->ncol_per; c++) {
            char *nm = ip->names[p * ip->ncol_per + c];
            snprintf(nm, sizeof ip->names[0], "s%d_%s", p + 1, what[c]);
            ip->col[p * ip->ncol_per + c] = nm;
        }
    sim_add_field_writer(s, write_solid_fraction, ip);
    sim_part_t part = {
        .name = "ibm",
        .ctx = ip,
        .stable_dt = part_stable_dt,
        .ncol = ip->nseries * ip->ncol_per,
        .col_names = ip->col,
        .diagnostics = part_diagnostics,
        .diverged = part_diverged,
        .keep_previous = part_keep_previous,
        .restore_previous = part_restore_previous,
        .change_rate = part_change_rate,
        .write_fields = part_write_fields,
        .checkpoint_write = part_checkpoint_write,
        .checkpoint_read = part_checkpoint_read,
        .summary = part_summary,
        .halt = part_halt,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
    return ip->ibm;
}
