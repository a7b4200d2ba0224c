/* sim_fluid.c — the fluid as a part of a run (sim.h): its time step, its
 * diagnostics and divergence checks, its snapshots (pressure and the
 * velocity at cell centres) and its exact state in checkpoints. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "grid.h"
#include "sim.h"
#include "util.h"

enum { FLUID_NCOL = 5, FLUID_NCOL_MAX = FLUID_NCOL + 8 };

typedef struct {
    sim_t *sim;
    grid_t *g;
    fluid_t *f;
    double *prev[4];      /* u, v, w, p at the start of the step (rollback) */
    double prev_time, prev_body_force[3];
    double prev_flow[3];  /* superficial velocities at the start of the step (steady_measure = integrals) */
    long prev_step;
    fluid_diag_t prev_diag; /* the diagnostics of the step before */
    int prev_stepped;
    long prev_implicit_steps;
    double ke_now, ke_prev; /* kinetic energy after and before the last step */
    double ke_still;        /* ½ V u_s², u_s = 0.1 CFL target × smallest cell / the last step (part_diverged) */
    double volume, hmin;    /* of the domain (axisymmetric: 2π included), smallest cell size */
    double div_init;      /* max |div u| of the initial state */
    int stepped;          /* a step was taken in this run */
    io_snapshots_t *snaps;
    int snap_first;       /* index of the first snapshot of this run */
    int viscous_reports;  /* viscous = auto: log lines about its choice */
    int nper, per[3];     /* the periodic directions */
    double re_length;     /* [fluid] reynolds_length (0: no Reynolds number) */
    const char *cols[FLUID_NCOL_MAX];
} fluid_part_t;

static const char *const fluid_cols[FLUID_NCOL] = {"cfl", "kinetic_energy", "div_max", "poisson_residual",
                                                   "poisson_iterations"};
static const char *const superficial_cols[3] = {"superficial_u", "superficial_v", "superficial_w"};
static const char *const flux_cols[3] = {"flux_x", "flux_y", "flux_z"};
static const char *const body_force_cols[3] = {"body_force_x", "body_force_y", "body_force_z"};

/* The periodic flow (docs/user-guide.md): along each periodic direction d the
 * superficial velocity U_d (the box mean of u_d) and the flux U_d V/L_d through
 * a cross-section; Re = |U| ℓ/ν.  Returns the number of values (the columns
 * after fluid_cols). */
static int periodic_flow(const fluid_part_t *fp, double *c)
{
    int n = 0;
    double u2 = 0.0;
    for (int m = 0; m < fp->nper; m++) {
        int d = fp->per[m];
        double U = fluid_mean_velocity(fp->f, d);
        c[n++] = U;
        c[n++] = U * fp->volume / fp->g->L[d];
        u2 += U * U;
    }
    if (fp->nper && fp->re_length > 0) c[n++] = sqrt(u2) * fp->re_length / fp->f->prm.nu;
    /* a held flow rate: the body force that drives it */
    if (fp->f->prm.hold_flow) c[n++] = fp->f->prm.body_force[fp->f->prm.hold_dir];
    return n;
}

static int ncomp(const fluid_part_t *fp) { return fp->g->dim == 3 ? 3 : 2; }

static double part_stable_dt(void *ctx) { return fluid_stable_dt(((fluid_part_t *)ctx)->f); }

/* viscous = auto: the choice in the log, at the first step of the run and
 * when it changes (the first few changes; summary.json counts the steps) */
static void report_viscous(fluid_part_t *fp, int was_implicit, double dt)
{
    const fluid_t *f = fp->f;
    if (f->prm.implicit_viscous != FLUID_VISCOUS_AUTO || (fp->stepped && was_implicit == f->implicit_step)) return;
    if (fp->viscous_reports++ == 6) {
        msg("fluid: viscous = auto: further changes of the viscous term are not reported (summary.json: "
            "fluid.implicit_steps)\n");
        return;
    }
    if (fp->viscous_reports > 6) return;
    msg("fluid: viscous = auto: %s viscous term from step %ld (dt = %.4g: %.3g times the explicit limit %.4g, "
        "Fourier number dt nu max sum 1/dx^2 = %.3g)\n",
        f->implicit_step ? "implicit (Crank-Nicolson)" : "explicit", f->step, dt, dt / f->dt_viscous, f->dt_viscous,
        dt / f->dt_viscous * f->prm.fourier);
}

static void part_advance(void *ctx, double dt)
{
    fluid_part_t *fp = ctx;
    fp->ke_prev = fp->ke_now;
    const double us = 0.1 * fp->f->prm.cfl * fp->hmin / dt;
    fp->ke_still = 0.5 * fp->volume * us * us;
    const int was_implicit = fp->f->implicit_step;
    fluid_step(fp->f, dt);
    report_viscous(fp, was_implicit, dt);
    fp->ke_now = fp->f->diag.ke;
    fp->stepped = 1;
}

static void part_diagnostics(void *ctx, double *c)
{
    fluid_part_t *fp = ctx;
    const fluid_diag_t *d = &fp->f->diag;
    periodic_flow(fp, c + FLUID_NCOL);
    if (!fp->stepped) { /* the initial state (or the one restarted from) */
        c[0] = 0;
        c[1] = fp->ke_now;
        c[2] = fp->div_init;
        c[3] = 0;
        c[4] = 0;
        return;
    }
    c[0] = d->cfl;
    c[1] = fp->ke_now;
    c[2] = d->div_max;
    c[3] = d->res_poisson;
    c[4] = d->it_poisson;
}

/* A step is unusable when it produced non-finite values (a NaN or Inf in u
 * makes the kinetic energy non-finite; one in p reaches u and the residual),
 * when its CFL number is above the hard limit (beyond the stability of RK3
 * with central advection, |λΔt| ≤ √3, the solution is noise), or when the
 * kinetic energy jumps by a large factor in one step (an instability).  The
 * jump is counted from at least the energy of a field still at the scale of
 * the step (ke_still: a speed of a tenth of the CFL target's everywhere): a fluid
 * set in motion from rest by particles that the DEM accelerated over a step
 * gains far more than the factor in one step without any instability. */
static int part_diverged(void *ctx, char *why, size_t n)
{
    fluid_part_t *fp = ctx;
    const fluid_diag_t *d = &fp->f->diag;
    const sim_params_t *sp = &fp->sim->prm;
    /* an adaptive step may be taken again with a smaller dt (sim.c, retry_step); a fixed one is the user's */
    fp->sim->retry_ok = fp->f->prm.dt_fixed <= 0;
    if (!isfinite(fp->ke_now) || !isfinite(d->div_max) || !isfinite(d->res_poisson) || !isfinite(d->cfl)) {
        snprintf(why, n, "non-finite values (kinetic energy %g, max |div u| %g, Poisson residual %g)", fp->ke_now,
                 d->div_max, d->res_poisson);
        return 1;
    }
    double limit = sp->cfl_abort;
    const char *src = "time.cfl_abort";
    if (fp->f->prm.dt_fixed <= 0 && 2.0 * fp->f->prm.cfl < limit) {
        limit = 2.0 * fp->f->prm.cfl;
        src = "twice the CFL target of the adaptive step";
    }
    if (d->cfl > limit) {
        snprintf(why, n, "CFL = %.4g is above the hard limit %.4g (%s)", d->cfl, limit, src);
        return 1;
    }
    if (fp->ke_prev > 0 && fp->ke_now > sp->ke_growth_abort * fmax(fp->ke_prev, fp->ke_still)) {
        snprintf(why, n, "the kinetic energy grew by a factor %.4g in one step (limit: time.ke_growth_abort = %g)",
                 fp->ke_now / fp->ke_prev, sp->ke_growth_abort);
        return 1;
    }
    return 0;
}

static void part_keep_previous(void *ctx)
{
    fluid_part_t *fp = ctx;
    fluid_t *f = fp->f;
    for (int c = 0; c < 4; c++) {
        double *src = c < 3 ? f->u[c] : f->p;
        if (!src) continue;
        if (!fp->prev[c]) fp->prev[c] = field_alloc(fp->g);
        field_copy(fp->g, fp->prev[c], src);
    }
    fp->prev_time = f->time;
    memcpy(fp->prev_body_force, f->prm.body_force, sizeof fp->prev_body_force);
    if (fp->sim->prm.steady_integrals && fp->sim->prm.steady_tol > 0)
        for (int m = 0; m < fp->nper; m++) fp->prev_flow[m] = fluid_mean_velocity(f, fp->per[m]);
    fp->prev_step = f->step;
    fp->prev_diag = f->diag;
    fp->prev_stepped = fp->stepped;
    fp->prev_implicit_steps = f->implicit_steps;
}

static void part_restore_previous(void *ctx)
{
    fluid_part_t *fp = ctx;
    fluid_t *f = fp->f;
    for (int c = 0; c < 4; c++) {
        double *dst = c < 3 ? f->u[c] : f->p;
        if (dst && fp->prev[c]) field_copy(fp->g, dst, fp->prev[c]);
    }
    f->time = fp->prev_time;
    memcpy(f->prm.body_force, fp->prev_body_force, sizeof fp->prev_body_force);
    f->step = fp->prev_step;
    f->diag = fp->prev_diag;
    fp->stepped = fp->prev_stepped;
    f->implicit_steps = fp->prev_implicit_steps;
    fp->ke_now = fp->ke_prev;
}

/* max |u(n+1) − u(n)| / (Δt max |u(n+1)|) over the interior: the relative
 * rate of change per unit time, which tends to 0 at a steady state. */
/* steady_measure = integrals: the relative rate of change of the superficial
 * velocities and of a held flow rate's body force */
static double flow_change_rate(const fluid_part_t *fp, double dt)
{
    const fluid_t *f = fp->f;
    double dU = 0, Um = 0;
    for (int m = 0; m < fp->nper; m++) {
        const double U = fluid_mean_velocity(f, fp->per[m]);
        dU = fmax(dU, fabs(U - fp->prev_flow[m]));
        Um = fmax(Um, fabs(U));
    }
    double rate = Um > 0 ? dU / (dt * Um) : 0.0;
    if (f->prm.hold_flow) {
        const double b = f->prm.body_force[f->prm.hold_dir], b0 = fp->prev_body_force[f->prm.hold_dir];
        rate = fmax(rate, b != 0 ? fabs(b - b0) / (dt * fabs(b)) : 0.0);
    }
    return rate;
}

static double part_change_rate(void *ctx, double dt)
{
    fluid_part_t *fp = ctx;
    const grid_t *g = fp->g;
    if (fp->sim->prm.steady_integrals && fp->nper) return flow_change_rate(fp, dt);
    double du = 0, umax = 0;
    for (int c = 0; c < ncomp(fp); c++) {
        const double *u = fp->f->u[c], *u0 = fp->prev[c];
        if (!u0) return INFINITY;
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) {
                    long q = G_IDX(g, i, j, k);
                    du = fmax(du, fabs(u[q] - u0[q]));
                    umax = fmax(umax, fabs(u[q]));
                }
    }
    du = grid_max(g, du);
    umax = grid_max(g, umax);
    return umax > 0 ? du / (dt * umax) : 0.0;
}

static void part_write_fields(void *ctx, double time, long step)
{
    fluid_part_t *fp = ctx;
    if (!fp->snaps) fp->snaps = io_snapshots_create(fp->g, fp->sim->out.dir, fp->snap_first);
    fluid_apply_bc(fp->f); /* the ghost faces enter the interpolation to cell centres */
    io_snapshot_begin(fp->snaps, time, step);
    io_snapshot_cell_scalar(fp->snaps, "pressure", fp->f->p);
    io_snapshot_face_vector(fp->snaps, "velocity", fp->f->u);
    for (int w = 0; w < fp->sim->nfield_writers; w++) fp->sim->field_writer[w](fp->sim->field_writer_ctx[w], fp->snaps);
    io_snapshot_end(fp->snaps);
}

static const char *const field_name[4] = {"u", "v", "w", "p"};

static void part_checkpoint_write(void *ctx, hid_t grp)
{
    fluid_part_t *fp = ctx;
    fluid_t *f = fp->f;
    io_h5_attr_double(grp, "time", f->time);
    io_h5_attr_long(grp, "step", f->step);
    io_h5_attr_long(grp, "snapshots", fp->snaps ? io_snapshots_count(fp->snaps) : fp->snap_first);
    /* the diagnostics of the last step (a restart that takes no step reports them) */
    const double diag[5] = {fp->stepped, f->diag.cfl, f->diag.div_max, f->diag.res_poisson, f->diag.it_poisson};
    io_h5_write_array(grp, "last_step_diagnostics", 5, diag);
    io_h5_attr_long(grp, "implicit_steps", f->implicit_steps);
    /* the drive a held flow rate reached */
    io_h5_write_array(grp, "body_force", 3, f->prm.body_force);
    io_h5_attr_string(grp, "layout", "interior of each staggered field, [nx][ny][nz], k fastest; "
                                     "u(i) on the high x face of cell i (CaNS convention)");
    for (int c = 0; c < 4; c++) {
        const double *src = c < 3 ? f->u[c] : f->p;
        if (c == 2 && fp->g->dim != 3) continue;
        io_h5_write_field(grp, field_name[c], fp->g, src);
    }
    /* the measuring planner's choices: a restart makes the same plans */
    const char *w = poisson_fftw_wisdom_used();
    if (f->prm.poisson.fftw_measure && w) io_h5_write_text(grp, "fftw_wisdom", w);
}

/* Restart with the measuring planner: plan from the FFTW wisdom the
 * checkpoint's run used (/fluid/fftw_wisdom), so that the plans, hence the
 * round-off, are those of the uninterrupted run, whatever the wisdom file
 * holds now. */
static void preset_checkpoint_wisdom(const char *path, MPI_Comm comm)
{
    io_checkpoint_header_t h;
    hid_t f = io_checkpoint_open(path, &h, comm);
    char *w = NULL;
    if (H5Lexists(f, "fluid", H5P_DEFAULT) > 0) {
        hid_t g = H5Gopen2(f, "fluid", H5P_DEFAULT);
        w = io_h5_read_text(g, "fftw_wisdom");
        H5Gclose(g);
    }
    io_checkpoint_header_free(&h);
    io_h5_close(f);
    if (!w)
        warn("%s holds no FFTW wisdom (written with fftw_planner = estimate, or without a fluid): the plans are "
             "measured again, so the continuation agrees to round-off, not bit for bit\n",
             path);
    poisson_fftw_wisdom_preset(w);
    free(w);
}

/* Ghosts of the pressure after a restart: halo exchange, and at a
 * non-periodic face the zero-gradient (Neumann) image, the boundary
 * condition of the pressure at walls and at the axis. */
static void fill_pressure_ghosts(const grid_t *g, double *p)
{
    grid_halo(g, p);
    if (!g->periodic[0]) {
        for (int j = -1; j <= g->n[1]; j++)
            for (int k = -g->gz; k < g->n[2] + g->gz; k++) {
                if (g->left == MPI_PROC_NULL) p[G_IDX(g, -1, j, k)] = p[G_IDX(g, 0, j, k)];
                if (g->right == MPI_PROC_NULL) p[G_IDX(g, g->nxl, j, k)] = p[G_IDX(g, g->nxl - 1, j, k)];
            }
    }
    if (!g->periodic[1])
        for (int i = -1; i <= g->nxl; i++)
            for (int k = -g->gz; k < g->n[2] + g->gz; k++) {
                p[G_IDX(g, i, -1, k)] = p[G_IDX(g, i, 0, k)];
                p[G_IDX(g, i, g->n[1], k)] = p[G_IDX(g, i, g->n[1] - 1, k)];
            }
    if (g->dim == 3 && !g->periodic[2])
        for (int i = -1; i <= g->nxl; i++)
            for (int j = -1; j <= g->n[1]; j++) {
                p[G_IDX(g, i, j, -1)] = p[G_IDX(g, i, j, 0)];
                p[G_IDX(g, i, j, g->n[2])] = p[G_IDX(g, i, j, g->n[2] - 1)];
            }
}

static void part_checkpoint_read(void *ctx, hid_t grp, const char *path)
{
    fluid_part_t *fp = ctx;
    fluid_t *f = fp->f;
    for (int c = 0; c < 4; c++) {
        double *dst = c < 3 ? f->u[c] : f->p;
        if (c == 2 && fp->g->dim != 3) continue;
        if (io_h5_read_field(grp, field_name[c], fp->g, dst))
            die("%s: /fluid/%s is missing or is not a %d x %d x %d field: the checkpoint is of another grid", path,
                field_name[c], fp->g->n[0], fp->g->n[1], fp->g->n[2]);
    }
    long snaps = 0;
    if (io_h5_get_attr_double(grp, "time", &f->time) || io_h5_get_attr_long(grp, "step", &f->step))
        die("%s: /fluid has no time or step attribute", path);
    if (io_h5_get_attr_long(grp, "snapshots", &snaps) == 0) fp->snap_first = (int)snaps;
    /* the snapshots the lost continuation wrote, and the index of ours */
    io_outdir_remove_numbered(&fp->sim->out, "fields_", ".h5", fp->snap_first);
    if (!fp->snaps) fp->snaps = io_snapshots_create(fp->g, fp->sim->out.dir, fp->snap_first);
    io_snapshots_write_index(fp->snaps);
    if (io_h5_get_attr_long(grp, "implicit_steps", &f->implicit_steps)) f->implicit_steps = 0;
    double bf[3];
    if (f->prm.hold_flow && io_h5_read_array(grp, "body_force", 3, bf) == 3) memcpy(f->prm.body_force, bf, sizeof bf);
    fluid_apply_bc(f);
    fill_pressure_ghosts(fp->g, f->p);
    fp->ke_now = fluid_kinetic_energy(f);
    fp->div_init = fluid_max_divergence(f);
    double diag[5];
    if (io_h5_read_array(grp, "last_step_diagnostics", 5, diag) == 5) {
        fp->stepped = diag[0] != 0;
        f->diag.cfl = diag[1], f->diag.div_max = diag[2], f->diag.res_poisson = diag[3];
        f->diag.it_poisson = (int)diag[4];
    }
}

static void part_summary(void *ctx, io_summary_t *y, const char *prefix)
{
    fluid_part_t *fp = ctx;
    const fluid_diag_t *d = &fp->f->diag;
    const grid_t *g = fp->g;
    char key[128];
    double umax = 0;
    for (int c = 0; c < ncomp(fp); c++)
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) umax = fmax(umax, fabs(fp->f->u[c][G_IDX(g, i, j, k)]));
    umax = grid_max(g, umax);
#define KEY(name) (snprintf(key, sizeof key, "%s.%s", prefix, name), key)
    io_summary_long(y, KEY("cells"), (long)g->n[0] * g->n[1] * g->n[2]);
    io_summary_double(y, KEY("kinetic_energy"), fp->ke_now);
    io_summary_double(y, KEY("max_velocity_component"), umax);
    io_summary_double(y, KEY("cfl"), d->cfl);
    io_summary_double(y, KEY("div_max"), fp->stepped ? d->div_max : fp->div_init);
    io_summary_double(y, KEY("poisson_residual"), d->res_poisson);
    io_summary_long(y, KEY("poisson_iterations"), d->it_poisson);
    static const char *visc[3] = {"explicit", "implicit", "auto"};
    io_summary_string(y, KEY("viscous"), visc[fp->f->prm.implicit_viscous]);
    io_summary_long(y, KEY("implicit_steps"), fp->f->implicit_steps);
    if (isfinite(fp->f->dt_viscous)) io_summary_double(y, KEY("explicit_viscous_limit"), fp->f->dt_viscous);
    double pf[8];
    int npf = periodic_flow(fp, pf);
    for (int m = 0; m < fp->nper; m++) {
        int dd = fp->per[m];
        char name[40];
        snprintf(name, sizeof name, "superficial_velocity_%c", "xyz"[dd]);
        io_summary_double(y, KEY(name), pf[2 * m]);
        io_summary_double(y, KEY(flux_cols[dd]), pf[2 * m + 1]);
    }
    if (fp->nper && fp->re_length > 0) io_summary_double(y, KEY("reynolds"), pf[2 * fp->nper]);
    if (fp->f->prm.hold_flow) io_summary_double(y, KEY(body_force_cols[fp->f->prm.hold_dir]), pf[npf - 1]);
#undef KEY
}

static void part_destroy(void *ctx)
{
    fluid_part_t *fp = ctx;
    for (int c = 0; c < 4; c++) free(fp->prev[c]);
    io_snapshots_free(fp->snaps);
    fluid_free(fp->f);
    grid_free(fp->g);
    free(fp);
}

void sim_add_fluid(sim_t *s, cfg_t *cfg)
{
    fluid_part_t *fp = xcalloc(1, sizeof *fp);
    fp->sim = s;
    fp->g = grid_create_from_config(cfg, s->comm);
    fluid_params_t prm;
    fluid_params_from_config(cfg, fp->g, &prm);
    /* ibmdem check writes nothing: the wisdom file was validated, it is not written */
    if (s->check_only) prm.poisson.fftw_wisdom[0] = 0;
    if (prm.poisson.method == POISSON_FFT && prm.poisson.fftw_measure && s->restart_path[0])
        preset_checkpoint_wisdom(s->restart_path, s->comm);
    fp->f = fluid_create(fp->g, &prm);
    fluid_init_from_config(fp->f, cfg);
    fluid_apply_bc(fp->f);
    fp->ke_now = fluid_kinetic_energy(fp->f);
    fp->div_init = fluid_max_divergence(fp->f);
    const grid_t *g = fp->g;
    fp->hmin = grid_min_spacing(g);
    fp->volume = g->geom == GEOM_AXI ? M_PI * g->L[0] * g->L[0] * g->L[1] : g->L[0] * g->L[1] * (g->dim == 3 ? g->L[2] : 1.0);
    s->fluid = fp->f;
    int ncol = FLUID_NCOL;
    for (int c = 0; c < FLUID_NCOL; c++) fp->cols[c] = fluid_cols[c];
    for (int d = 0; d < g->dim; d++)
        if (g->periodic[d]) {
            fp->per[fp->nper++] = d;
            fp->cols[ncol++] = superficial_cols[d];
            fp->cols[ncol++] = flux_cols[d];
        }
    fp->re_length = cfg_double(cfg, "fluid", "reynolds_length");
    if (fp->re_length > 0 && !fp->nper)
        cfg_fail(cfg, "fluid", "reynolds_length", "the Reynolds number is that of a flow periodic in some direction: "
                                                  "this domain has no periodic direction");
    if (fp->nper && fp->re_length > 0) fp->cols[ncol++] = "reynolds";
    if (prm.hold_flow) fp->cols[ncol++] = body_force_cols[prm.hold_dir];
    sim_part_t part = {
        .name = "fluid",
        .ctx = fp,
        .stable_dt = part_stable_dt,
        .advance = part_advance,
        .ncol = ncol,
        .col_names = fp->cols,
        .diagnostics = part_diagnostics,
        .diverged = part_diverged,
        .keep_previous = part_keep_previous,
        .restore_previous = part_restore_previous,
        .change_rate = part_change_rate,
        .write_fields = part_write_fields,
        .checkpoint_write = part_checkpoint_write,
        .checkpoint_read = part_checkpoint_read,
        .summary = part_summary,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}
