/* ibm.c — the [ibm] keys, the spheres of a case (keys sphere1..sphere9 and
 * a file of many), creation, velocity histories, sphere properties. */
#include <ctype.h>
#include <hdf5.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "ibm_internal.h"
#include "io.h"
#include "overlap.h"
#include "util.h"

#define IBM_KEYED_SPHERES 9
#define SPHERE_HELP                                                                                                \
    "a sphere: KIND then tagged values in any order — KIND = free|fixed|prescribed; center X Y Z; radius R "     \
    "(or diameter D); density RHO (free: required); velocity U V W; omega WX WY WZ; history FILE (prescribed: "  \
    "CSV t,u,v,w[,ox,oy,oz], linear in t). Example: free center 0 10 0 diameter 1 density 4"
#define SPHERE_KEY(N) {"ibm", "sphere" #N, CFG_STRING, NULL, 1, 0, NULL, N == 1 ? SPHERE_HELP : "as sphere1", CFG_OPTIONAL}

static const cfg_key_t ibm_keys[] = {
    {"ibm", "force_model", CFG_ENUM, "momentum", 1, 0, "momentum|rigid",
     "hydrodynamic force: forcing integral + rate of change of the fluid momentum inside the sphere "
     "(momentum: any density ratio), or the seed's rigid-body formula -ρρp/(ρp-ρ)∫f dV (rigid: ρp/ρ well above 1)"},
    {"ibm", "virtual_mass", CFG_DOUBLE, "0.1", 0, 10, NULL,
     "momentum model: C_v of the stabilisation (m + C_v ρ V) Δu = ... + C_v ρ V Δu_previous (0: plain explicit "
     "coupling, unstable below ρp/ρ = 0.25; 0.1: stable down to about 0.05, see docs/theory.md)"},
    {"ibm", "forcing_iterations", CFG_INT, "0", 0, 20, NULL,
     "extra (force, project) passes per Runge-Kutta stage before the final forcing (each costs a pressure solve)"},
    {"ibm", "gravity", CFG_VEC3, "0 0 0", -1e300, 1e300, NULL,
     "gravity acting on the free spheres (their immersed weight (ρp-ρ)V g; the fluid pressure is relative to "
     "hydrostatic)"},
    {"ibm", "forcing_time", CFG_DOUBLE, "0.2", 0, 1e6, NULL,
     "κ: a node of solid fraction α < 1 is forced by u ← u + β(U − u), β = αΔt_k/((1−α)κh²/ν + αΔt_k), whose "
     "steady state does not depend on the time step; 0: the seed's β = α at every stage (depends on Δt; for "
     "comparisons with the thesis)"},
    {"ibm", "free_alpha", CFG_ENUM, "stage", 1, 0, "stage|step",
     "where a free sphere's solid fraction is over a fluid step: moved to the predicted centre after every "
     "Runge-Kutta stage (stage), or held where the step started and moved between steps, the fluid momentum "
     "over the jump counted in the next force (step: one rebuild per step instead of three, see "
     "docs/theory.md)"},
    {"ibm", "cn_forcing", CFG_ENUM, "predictor", 1, 0, "after_solve|predictor",
     "with the Crank-Nicolson viscous term ([fluid] viscous = implicit, or auto on its implicit steps): the forcing "
     "is computed from the explicit predictor with the whole viscous term and applied as a source term of the "
     "implicit solve (predictor: stable at large Δt ν/Δx², steady states independent of Δt, see docs/theory.md "
     "§4.6), or computed from the Crank-Nicolson solution and applied after the solve (after_solve: the seed's "
     "order, porous to the implicit viscous term at large Δt ν/Δx²); no effect with the explicit viscous term"},
    {"ibm", "band_width", CFG_DOUBLE, "1", 0.25, 1, NULL,
     "s: the solid fraction's smoothed transition is s times the seed's width (about 3 cells at 1, docs/theory.md "
     "§6b); a narrower band with a stiffer forcing (0.5 with forcing_time = 0.05) is the boundary that thin boundary "
     "layers need (docs/validation.md); 1: the seed's (needed by radius_correction calibrated and gaps)"},
    {"ibm", "retraction", CFG_DOUBLE, "0", -1, 1, NULL,
     "the solid fraction is that of a sphere of radius R - retraction × Δx (cells): compensates the effective "
     "thickening of the forced sphere (0: the seed's method)"},
    {"ibm", "radius_correction", CFG_ENUM, "none", 1, 0, "none|calibrated|gaps",
     "calibrated: the solid fraction is moreover that of the radius R - (r(κ) - 0.282 Δx/R) Δx, the hydrodynamic "
     "thickening of the band measured on Stokes flow through sphere arrays (needs forcing_time in [0.1, 0.3] and "
     "forcing_iterations = 0; see docs/theory.md); gaps (3-D): the radius R - (r(κ) - 0.084 Δx/R) Δx + "
     "min(0.45 Δx²/(G + Δx), 0.4 Δx) at each node, G its distance to the nearest other sphere's surface "
     "(at most 2 diameters): also corrects the narrow gaps of dense arrays and beds (same conditions; the "
     "neighbour search, a cell list, costs O(N) per rebuild of the solid fraction); none: the seed's volume fraction"},
    {"ibm", "spheres_file", CFG_STRING, NULL, 1, 0, NULL,
     "many spheres: a CSV file (header with x,y,z,radius or diameter; optional density,u,v,w,ox,oy,oz,kind or "
     "fixed) or an HDF5 packing (.h5: datasets position [n][3], radius; optional density, velocity, omega, fixed)", CFG_CONDITIONAL},
    {"ibm", "density", CFG_DOUBLE, NULL, 1e-300, 1e300, NULL,
     "density of the spheres of spheres_file that give none (required if one is free and has none)", CFG_CONDITIONAL},
    {"ibm", "series_spheres", CFG_INT, "4", 0, 4, NULL,
     "the first this many spheres have their position, velocity, ω, force and torque as columns of series.csv"},
    SPHERE_KEY(1), SPHERE_KEY(2), SPHERE_KEY(3), SPHERE_KEY(4), SPHERE_KEY(5), SPHERE_KEY(6), SPHERE_KEY(7),
    SPHERE_KEY(8), SPHERE_KEY(9),
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void ibm_register_keys(void) { cfg_schema_add(ibm_keys); }

ibm_params_t ibm_default_params(void)
{
    ibm_params_t p;
    memset(&p, 0, sizeof p);
    p.force_model = IBM_FORCE_MOMENTUM;
    p.virtual_mass = 0.1;
    p.band_width = 1.0;
    return p;
}

/* The hydrodynamic radius of a sphere forced with the smoothed indicator of
 * radius R and forcing_time κ exceeds R by (r(κ) − 0.282 h/R) h, measured on
 * Stokes flow through the simple cubic array (c = 0.064, D/Δx = 7.9–23.8:
 * the K of each run gives the radius a_h of Sangani & Acrivos' K(c) for the
 * same drag; docs/theory.md §6b): r(κ) at κ = 0.1, 0.15, …, 0.3 from the
 * runs at D/Δx = 11.9 and 15.9, interpolated linearly.  Below D/Δx = 4
 * (h/R > 0.5, far outside the calibration) the term of D/Δx = 4 is kept, so
 * that the forced band stays within the margin of sphere_box(). */
static double retraction_fit(double kappa, double h_over_R, double d)
{
    if (h_over_R > 0.5) h_over_R = 0.5;
    static const double r_of_kappa[5] = {0.3135, 0.1903, 0.1027, 0.0335, -0.0229};
    double x = (kappa - 0.1) / 0.05;
    int i = x < 0 ? 0 : (x >= 4 ? 3 : (int)x);
    double w = x - i;
    return (1 - w) * r_of_kappa[i] + w * r_of_kappa[i + 1] - d * h_over_R;
}

double ibm_calibrated_retraction(double kappa, double h_over_R) { return retraction_fit(kappa, h_over_R, 0.282); }

/* `radius_correction = gaps`: the same r(κ), and a second-order part split
 * into −0.084 h/R and the local term 0.45 h²/(G + h) of each node
 * (G its distance to the nearest other sphere's surface), fitted on Stokes
 * flow through the simple cubic arrays c = 0.064 (which sets the 0.084, the
 * gap term being part of the 0.282 of `calibrated` there), 0.216 and 0.343
 * at D/Δx ≈ 8 and 12 with κ = 0.2 (docs/theory.md §6b): the drag of a narrow
 * gap is underestimated by a smoothed band, as by a sphere smaller by about
 * 0.17 h²/g (g the gap), which a radius fitted on a dilute array leaves. */
double ibm_gap_retraction(double kappa, double h_over_R) { return retraction_fit(kappa, h_over_R, 0.084); }

double ibm_gap_thickening(double G, double h)
{
    double e = 0.45 * h * h / (G + h);
    return e < IBM_GAP_MAX * h ? e : IBM_GAP_MAX * h;
}

double ibm_forced_radius(const ibm_t *ibm, double R, double h)
{
    double r = ibm->prm.retraction;
    const double kappa = ibm->prm.forcing_time;
    if (ibm->prm.radius_calibrated == IBM_RADIUS_CALIBRATED) r += ibm_calibrated_retraction(kappa, h / R);
    if (ibm->prm.radius_calibrated == IBM_RADIUS_GAPS) r += ibm_gap_retraction(kappa, h / R);
    return R - r * h;
}

/* ---- sphere properties --------------------------------------------------------- */

double ibm_volume(const ibm_t *ibm, int p)
{
    double R = ibm->s[p].radius;
    return ibm->g->dim == 3 || ibm->g->geom == GEOM_AXI ? 4.0 / 3.0 * M_PI * R * R * R : M_PI * R * R;
}

double ibm_mass(const ibm_t *ibm, int p) { return ibm->s[p].density * ibm_volume(ibm, p); }

double ibm_inertia(const ibm_t *ibm, int p)
{
    double R = ibm->s[p].radius;
    double k = ibm->g->dim == 3 || ibm->g->geom == GEOM_AXI ? 0.4 : 0.5;
    return k * ibm_mass(ibm, p) * R * R;
}

double ibm_stable_dt(const ibm_t *ibm, double cfl)
{
    const grid_t *g = ibm->g;
    double h = fmin(g->dy, g->dim == 3 ? g->dz : g->dy);
    for (int i = 0; i < g->n[0]; i++) h = fmin(h, g->gdxf[i]);
    double rate = 0.0;
    for (int p = 0; p < ibm->n; p++) {
        const ibm_sphere_t *s = &ibm->s[p];
        double u = hypot(hypot(s->u[0], s->u[1]), s->u[2]); /* no overflow of the squares */
        double w = hypot(hypot(s->omega[0], s->omega[1]), s->omega[2]);
        rate = fmax(rate, (u + w * s->radius) / h);
        if (s->kind == IBM_FREE) {
            /* from rest, the sphere accelerates at most by |g|(1 − ρ/ρp): it
             * moves one cell in √(2h/a) */
            double gg = sqrt(ibm->prm.gravity[0] * ibm->prm.gravity[0] + ibm->prm.gravity[1] * ibm->prm.gravity[1] +
                             ibm->prm.gravity[2] * ibm->prm.gravity[2]);
            double a = gg * fabs(1.0 - ibm->f->prm.rho / s->density);
            rate = fmax(rate, sqrt(a / h));
        }
    }
    return rate > 0 ? cfl / rate : INFINITY;
}

/* ---- prescribed velocity histories ------------------------------------------------ */

int ibm_add_history(ibm_t *ibm, int n, const double *rows)
{
    ibm_priv_t *q = ibm_priv(ibm);
    if (n < 1) die("immersed boundary: an empty velocity history");
    q->hist = realloc(q->hist, (size_t)(q->nhist + 1) * sizeof *q->hist);
    ibm_history_t *h = &q->hist[q->nhist];
    h->n = n;
    h->t = xcalloc((size_t)n, sizeof(double));
    h->v = xcalloc((size_t)n * 6, sizeof(double));
    for (int i = 0; i < n; i++) {
        h->t[i] = rows[7 * i];
        if (i > 0 && !(h->t[i] > h->t[i - 1])) die("immersed boundary: velocity history times must increase");
        for (int c = 0; c < 6; c++) h->v[6 * i + c] = rows[7 * i + 1 + c];
    }
    return q->nhist++;
}

void ibm_prescribed_velocity(const ibm_t *ibm, const ibm_sphere_t *s, double t, double u[3], double w[3])
{
    const ibm_priv_t *q = ibm_priv(ibm);
    if (s->history < 0 || s->history >= q->nhist) {
        memmove(u, s->u, 3 * sizeof(double));
        memmove(w, s->omega, 3 * sizeof(double));
        return;
    }
    const ibm_history_t *h = &q->hist[s->history];
    double v[6];
    if (t <= h->t[0] || h->n == 1) {
        memcpy(v, h->v, sizeof v);
    } else if (t >= h->t[h->n - 1]) {
        memcpy(v, h->v + 6 * (h->n - 1), sizeof v);
    } else {
        int i = 0, j = h->n - 1; /* bisection: h->t[i] < t <= h->t[j] */
        while (j - i > 1) {
            int m = (i + j) / 2;
            if (h->t[m] < t) i = m;
            else j = m;
        }
        double a = (t - h->t[i]) / (h->t[i + 1] - h->t[i]);
        for (int c = 0; c < 6; c++) v[c] = (1 - a) * h->v[6 * i + c] + a * h->v[6 * (i + 1) + c];
    }
    for (int c = 0; c < 3; c++) {
        u[c] = v[c];
        w[c] = v[3 + c];
    }
}

/* ---- creation ------------------------------------------------------------------------ */

/* Why sphere s does not fit grid g (NULL if it does). */
static const char *sphere_misfit(const grid_t *g, const ibm_sphere_t *s)
{
    for (int c = 0; c < 3; c++)
        if (!isfinite(s->x[c]) || !isfinite(s->u[c]) || !isfinite(s->omega[c]))
            return "a position, velocity or omega that is not a finite number";
    if (!(s->radius > 0) || !isfinite(s->radius)) return "the radius must be > 0 (and finite)";
    if (s->kind == IBM_FREE && !(s->density > 0 && isfinite(s->density))) return "a free sphere needs a finite density > 0";
    for (int d = 0; d < g->dim; d++)
        if (!(s->x[d] >= g->x0[d] && s->x[d] <= g->x0[d] + g->L[d])) return "the centre is outside the domain";
    if (g->geom == GEOM_AXI) {
        if (s->x[0] != 0.0 || s->x[2] != 0.0) return "an axisymmetric sphere must be on the axis (x = 0, z = 0)";
        if (s->u[0] != 0.0 || s->u[2] != 0.0) return "an axisymmetric sphere moves along the axis: u and w must be 0";
        if (s->omega[0] != 0.0 || s->omega[1] != 0.0 || s->omega[2] != 0.0)
            return "an axisymmetric sphere cannot rotate (no swirl): omega must be 0";
    } else if (g->dim == 2) {
        if (s->u[2] != 0.0 || s->omega[0] != 0.0 || s->omega[1] != 0.0)
            return "a disc of a 2-D grid moves in the plane: w, omega_x and omega_y must be 0";
    }
    return NULL;
}

ibm_t *ibm_create(fluid_t *f, const ibm_params_t *prm, const ibm_sphere_t *s, int n)
{
    const grid_t *g = f->g;
    if (f->stage_begin_hook || f->plane_hook || f->stage_hook || f->stage_end_hook)
        die("immersed boundary: the fluid's stage hooks are already in use");
    if (g->nalloc >= INT32_MAX) die("immersed boundary: a field of %ld values is too large for the node lists", g->nalloc);
    if (prm->forcing_predictor && prm->forcing_iterations > 0 && f->prm.implicit_viscous)
        die("immersed boundary: forcing iterations act after the Crank-Nicolson solve, not with the predictor forcing");
    for (int d = 0; d < g->dim; d++)
        if (g->periodic[d] && g->n[d] > 127 * 1000000) die("immersed boundary: grid too large");
    ibm_t *ibm = xcalloc(1, sizeof *ibm);
    ibm_priv_t *q = xcalloc(1, sizeof *q);
    ibm->f = f;
    ibm->g = g;
    ibm->prm = *prm;
    ibm->n = n;
    ibm->s = xcalloc((size_t)(n > 0 ? n : 1), sizeof *ibm->s);
    if (n > 0) memcpy(ibm->s, s, (size_t)n * sizeof *s);
    ibm->priv = q;
    for (int p = 0; p < n; p++) {
        const char *why = sphere_misfit(g, &ibm->s[p]);
        if (why) die("immersed boundary: sphere %d: %s", p + 1, why);
        if (prm->force_model == IBM_FORCE_RIGID && ibm->s[p].kind == IBM_FREE &&
            fabs(ibm->s[p].density - f->prm.rho) < 1e-12 * f->prm.rho)
            die("immersed boundary: sphere %d: the rigid force model divides by ρp − ρ = 0 (use force_model = "
                "momentum)",
                p + 1);
        if (ibm->s[p].kind != IBM_PRESCRIBED) ibm->s[p].history = -1;
        if (g->dim == 2) ibm->s[p].x[2] = 0.0;
        memcpy(ibm->s[p].xpred, ibm->s[p].x, sizeof ibm->s[p].x);
    }
    for (int c = 0; c < g->dim; c++) {
        q->vol[c] = (double *)xcalloc((size_t)g->nxl + 2, sizeof(double)) + 1;
        q->hcell[c] = (double *)xcalloc((size_t)g->nxl + 2, sizeof(double)) + 1;
        for (int i = 0; i < g->nxl; i++) {
            q->vol[c][i] = fluid_cell_volume(f, c, i) * (g->geom == GEOM_AXI ? 2.0 * M_PI : 1.0);
            double hx = c == 0 ? g->dxc[i] : g->dxf[i];
            q->hcell[c][i] = g->dim == 3 ? cbrt(hx * g->dy * g->dz) : sqrt(hx * g->dy);
        }
    }
    size_t nn = (size_t)(n > 0 ? n : 1);
    q->line_head = xcalloc((size_t)(g->dim == 3 ? g->n[1] : 1) + 1, sizeof(int32_t));
    q->rdir = g->dim == 3 ? 2 : 1;
    q->rstride = g->dim == 3 ? 1 : g->sy;
    q->rstep = g->dim == 3 ? g->dz : g->dy;
    q->sum = xcalloc(nn * IBM_NSUM, sizeof(double));
    q->mom_prev = xcalloc(nn * 6, sizeof(double));
    q->target_vel = xcalloc(nn * 6, sizeof(double));
    q->imp_step = xcalloc(nn * 6, sizeof(double));
    q->plane_nrun = xcalloc((size_t)g->dim * ((size_t)g->nxl + 1), sizeof *q->plane_nrun);
    f->stage_begin_hook = ibm_stage_begin;
    f->plane_hook = ibm_force_plane;
    f->stage_hook = ibm_stage_force;
    f->stage_end_hook = ibm_stage_end;
    f->hook_ctx = ibm;
    f->hook_flags = 0;
    ibm_update_geometry(ibm);
    return ibm;
}

void ibm_free(ibm_t *ibm)
{
    if (!ibm) return;
    ibm_priv_t *q = ibm_priv(ibm);
    if (ibm->f->hook_ctx == ibm) {
        ibm->f->stage_begin_hook = NULL;
        ibm->f->plane_hook = NULL;
        ibm->f->stage_hook = NULL;
        ibm->f->stage_end_hook = NULL;
        ibm->f->hook_ctx = NULL;
        ibm->f->hook_flags = 0;
    }
    for (int c = 0; c < 3; c++) {
        if (q->vol[c]) free(q->vol[c] - 1);
        if (q->hcell[c]) free(q->hcell[c] - 1);
    }
    for (int h = 0; h < q->nhist; h++) {
        free(q->hist[h].t);
        free(q->hist[h].v);
    }
    free(q->hist);
    free(q->runs);
    free(q->alpha);
    free(q->nruns_f);
    free(q->node_asum);
    free(q->node_target);
    free(q->node_imp);
    free(q->line_head);
    free(q->entry_node);
    free(q->nb_head);
    free(q->nb);
    free(q->tmp);
    free(q->cnt);
    free(q->sum);
    free(q->mom_prev);
    free(q->target_vel);
    free(q->imp_step);
    free(q->plane_nrun);
    free(q);
    free(ibm->s);
    free(ibm);
}

/* ---- the case file ------------------------------------------------------------------------ */

/* Read a numeric CSV file with a header line: returns the rows (malloc'd,
 * ncol per row), the number of rows, the column names in `names`. */
static double *read_csv(cfg_t *cfg, const char *key, const char *path, int *nrow, int *ncol, char names[][32], int maxcol)
{
    FILE *fp = fopen(path, "r");
    if (!fp) cfg_fail(cfg, "ibm", key, "cannot open %s", path);
    char *line = NULL;
    size_t lcap = 0;
    *ncol = 0;
    /* header (the first line that is not a comment) */
    while (getline(&line, &lcap, fp) > 0) {
        if (line[0] == '#' || line[strspn(line, " \t\r\n")] == 0) continue;
        for (char *tok = strtok(line, ", \t\r\n"); tok; tok = strtok(NULL, ", \t\r\n")) {
            if (*ncol == maxcol) cfg_fail(cfg, "ibm", key, "%s: more than %d columns", path, maxcol);
            snprintf(names[*ncol], 32, "%s", tok);
            for (char *c = names[*ncol]; *c; c++) *c = (char)tolower((unsigned char)*c);
            (*ncol)++;
        }
        break;
    }
    if (*ncol == 0) cfg_fail(cfg, "ibm", key, "%s: no header line", path);
    int cap = 64, n = 0, lineno = 1;
    double *rows = xcalloc((size_t)cap * *ncol, sizeof(double));
    while (getline(&line, &lcap, fp) > 0) {
        lineno++;
        if (line[0] == '#' || line[strspn(line, " \t\r\n")] == 0) continue;
        if (n == cap) {
            cap *= 2;
            rows = realloc(rows, (size_t)cap * *ncol * sizeof(double));
        }
        int k = 0;
        for (char *tok = strtok(line, ", \t\r\n"); tok; tok = strtok(NULL, ", \t\r\n"), k++) {
            if (k >= *ncol) cfg_fail(cfg, "ibm", key, "%s:%d: more values than header columns", path, lineno);
            double v;
            if (!cfg_parse_real(tok, &v)) {
                /* a kind column may hold a word */
                if (!strcmp(tok, "free")) v = IBM_FREE;
                else if (!strcmp(tok, "fixed")) v = IBM_FIXED;
                else if (!strcmp(tok, "prescribed")) v = IBM_PRESCRIBED;
                else cfg_fail(cfg, "ibm", key, "%s:%d: '%.40s' is not a number", path, lineno, tok);
            }
            rows[(long)n * *ncol + k] = v;
        }
        if (k != *ncol) cfg_fail(cfg, "ibm", key, "%s:%d: %d values for %d columns", path, lineno, k, *ncol);
        n++;
    }
    fclose(fp);
    free(line);
    *nrow = n;
    return rows;
}

static int column(char names[][32], int ncol, const char *a, const char *b)
{
    for (int i = 0; i < ncol; i++)
        if (!strcmp(names[i], a) || (b && !strcmp(names[i], b))) return i;
    return -1;
}

/* Spheres of a CSV file, appended to *s. */
static void spheres_from_csv(cfg_t *cfg, const char *path, double rho_default, ibm_sphere_t **s, int *n)
{
    char names[32][32];
    int nrow, ncol;
    double *rows = read_csv(cfg, "spheres_file", path, &nrow, &ncol, names, 32);
    int cx = column(names, ncol, "x", NULL), cy = column(names, ncol, "y", NULL), cz = column(names, ncol, "z", NULL);
    int cr = column(names, ncol, "radius", "r"), cd = column(names, ncol, "diameter", "d");
    int crho = column(names, ncol, "density", "rho");
    int cu[3] = {column(names, ncol, "u", "vx"), column(names, ncol, "v", "vy"), column(names, ncol, "w", "vz")};
    int cw[3] = {column(names, ncol, "ox", "wx"), column(names, ncol, "oy", "wy"), column(names, ncol, "oz", "wz")};
    int ck = column(names, ncol, "kind", NULL), cf = column(names, ncol, "fixed", NULL);
    if (cx < 0 || cy < 0 || (cr < 0 && cd < 0))
        cfg_fail(cfg, "ibm", "spheres_file", "%s: the header needs x, y (z in 3-D) and radius or diameter", path);
    *s = realloc(*s, (size_t)(*n + nrow + 1) * sizeof **s);
    for (int r = 0; r < nrow; r++) {
        const double *v = rows + (long)r * ncol;
        ibm_sphere_t *t = &(*s)[*n + r];
        memset(t, 0, sizeof *t);
        t->history = -1;
        t->x[0] = v[cx];
        t->x[1] = v[cy];
        t->x[2] = cz >= 0 ? v[cz] : 0.0;
        t->radius = cr >= 0 ? v[cr] : 0.5 * v[cd];
        t->density = crho >= 0 ? v[crho] : rho_default;
        for (int c = 0; c < 3; c++) {
            t->u[c] = cu[c] >= 0 ? v[cu[c]] : 0.0;
            t->omega[c] = cw[c] >= 0 ? v[cw[c]] : 0.0;
        }
        if (ck >= 0 && v[ck] != IBM_FREE && v[ck] != IBM_FIXED && v[ck] != IBM_PRESCRIBED)
            cfg_fail(cfg, "ibm", "spheres_file", "%s: row %d: kind must be free (0), fixed (1) or prescribed (2)", path,
                     r + 1);
        t->kind = ck >= 0 ? (ibm_kind_t)(int)v[ck] : (cf >= 0 && v[cf] != 0 ? IBM_FIXED : IBM_FREE);
    }
    *n += nrow;
    free(rows);
}

/* Read dataset `name` of `n` × `w` doubles (or ints if is_int) if present. */
static int h5_read(hid_t f, const char *name, hid_t type, void *buf)
{
    if (H5Lexists(f, name, H5P_DEFAULT) <= 0) return 0;
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    herr_t e = H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
    H5Dclose(ds);
    return e >= 0;
}

/* Spheres of an HDF5 packing (the DEM's packing/checkpoint layout). */
static void spheres_from_h5(cfg_t *cfg, const char *path, double rho_default, ibm_sphere_t **s, int *n)
{
    long np;
    hid_t f = io_h5_open_packing(cfg, "ibm", "spheres_file", path, &np);
    size_t m = (size_t)np + 1;
    double *x = xcalloc(3 * m, sizeof(double)), *v = xcalloc(3 * m, sizeof(double)), *w = xcalloc(3 * m, sizeof(double));
    double *r = xcalloc(m, sizeof(double)), *rho = xcalloc(m, sizeof(double));
    int *fixed = xcalloc(m, sizeof(int));
    h5_read(f, "position", H5T_NATIVE_DOUBLE, x);
    h5_read(f, "radius", H5T_NATIVE_DOUBLE, r);
    int has_rho = h5_read(f, "density", H5T_NATIVE_DOUBLE, rho);
    h5_read(f, "velocity", H5T_NATIVE_DOUBLE, v);
    h5_read(f, "omega", H5T_NATIVE_DOUBLE, w);
    h5_read(f, "fixed", H5T_NATIVE_INT, fixed);
    H5Fclose(f);
    *s = realloc(*s, (size_t)(*n + np + 1) * sizeof **s);
    for (long i = 0; i < np; i++) {
        ibm_sphere_t *t = &(*s)[*n + i];
        memset(t, 0, sizeof *t);
        t->history = -1;
        t->kind = fixed[i] ? IBM_FIXED : IBM_FREE;
        t->radius = r[i];
        t->density = has_rho ? rho[i] : rho_default;
        for (int c = 0; c < 3; c++) {
            t->x[c] = x[3 * i + c];
            t->u[c] = v[3 * i + c];
            t->omega[c] = w[3 * i + c];
        }
    }
    *n += (int)np;
    free(x), free(v), free(w), free(r), free(rho), free(fixed);
}

/* Parse "KIND tag values ..." of key sphereN. */
static void parse_sphere(cfg_t *cfg, const char *key, const char *text, ibm_sphere_t *t, char **history)
{
    char *buf = strdup(text);
    for (char *p = buf; *p; p++)
        if (*p == ',') *p = ' ';
    memset(t, 0, sizeof *t);
    t->history = -1;
    t->density = -1;
    *history = NULL;
    char *save = NULL, *tok = strtok_r(buf, " \t", &save);
    if (!tok) cfg_fail(cfg, "ibm", key, "empty");
    if (!strcmp(tok, "free")) t->kind = IBM_FREE;
    else if (!strcmp(tok, "fixed")) t->kind = IBM_FIXED;
    else if (!strcmp(tok, "prescribed")) t->kind = IBM_PRESCRIBED;
    else cfg_fail(cfg, "ibm", key, "'%.40s': the first word must be the kind: free, fixed or prescribed", tok);
    int have_center = 0, have_radius = 0;
    while ((tok = strtok_r(NULL, " \t", &save))) {
        int nv;
        double *dst;
        if (!strcmp(tok, "center") || !strcmp(tok, "centre") || !strcmp(tok, "position")) {
            nv = 3, dst = t->x, have_center = 1;
        } else if (!strcmp(tok, "radius")) {
            nv = 1, dst = &t->radius, have_radius = 1;
        } else if (!strcmp(tok, "diameter")) {
            nv = 1, dst = &t->radius, have_radius = 2;
        } else if (!strcmp(tok, "density")) {
            nv = 1, dst = &t->density;
        } else if (!strcmp(tok, "velocity")) {
            nv = 3, dst = t->u;
        } else if (!strcmp(tok, "omega")) {
            nv = 3, dst = t->omega;
        } else if (!strcmp(tok, "history")) {
            char *file = strtok_r(NULL, " \t", &save);
            if (!file) cfg_fail(cfg, "ibm", key, "history needs a file name");
            if (t->kind != IBM_PRESCRIBED) cfg_fail(cfg, "ibm", key, "a velocity history needs the kind prescribed");
            free(*history);
            *history = strdup(file);
            continue;
        } else {
            cfg_fail(cfg, "ibm", key,
                     "'%.40s' is not one of center, radius, diameter, density, velocity, omega, history", tok);
        }
        for (int i = 0; i < nv; i++) {
            char *v = strtok_r(NULL, " \t", &save);
            if (!v) cfg_fail(cfg, "ibm", key, "%s needs %d number%s", tok, nv, nv > 1 ? "s" : "");
            if (!cfg_parse_real(v, &dst[i])) cfg_fail(cfg, "ibm", key, "%s: '%.40s' is not a number", tok, v);
        }
    }
    free(buf);
    if (!have_center) cfg_fail(cfg, "ibm", key, "no center X Y Z");
    if (!have_radius) cfg_fail(cfg, "ibm", key, "no radius (or diameter)");
    if (have_radius == 2) t->radius *= 0.5;
    if (t->kind == IBM_FREE && !(t->density > 0)) cfg_fail(cfg, "ibm", key, "a free sphere needs density RHO > 0");
}

/* Load a history CSV (t,u,v,w[,ox,oy,oz]) as rows of 7 for ibm_add_history. */
static double *read_history(cfg_t *cfg, const char *key, const char *path, int *n)
{
    char names[16][32];
    int ncol;
    double *raw = read_csv(cfg, key, path, n, &ncol, names, 16);
    int ct = column(names, ncol, "t", "time");
    const char *vn[6] = {"u", "v", "w", "ox", "oy", "oz"};
    int cc[6];
    for (int c = 0; c < 6; c++) cc[c] = column(names, ncol, vn[c], NULL);
    if (ct < 0 || *n < 1) cfg_fail(cfg, "ibm", key, "%s: needs a column t and at least one row", path);
    double *rows = xcalloc((size_t)*n * 7, sizeof(double));
    for (int i = 0; i < *n; i++) {
        rows[7 * i] = raw[(long)i * ncol + ct];
        if (i > 0 && !(rows[7 * i] > rows[7 * (i - 1)])) cfg_fail(cfg, "ibm", key, "%s: the times must increase", path);
        for (int c = 0; c < 6; c++) rows[7 * i + 1 + c] = cc[c] >= 0 ? raw[(long)i * ncol + cc[c]] : 0.0;
    }
    free(raw);
    return rows;
}

/* Stop on sphere p with the key that gave it (keynum: see below). */
#define SPHERE_FAIL(p, ...)                                                                                       \
    do {                                                                                                          \
        char key_[24];                                                                                            \
        snprintf(key_, sizeof key_, "sphere%d", keynum[p]);                                                       \
        cfg_fail(cfg, keynum[p] < 0 ? "particles" : "ibm", keynum[p] > 0 ? key_ : keynum[p] == 0 ? "spheres_file" \
                                                                                        : "source",              \
                 __VA_ARGS__);                                                                                   \
    } while (0)

/* The spheres must fit the domain (docs/user-guide.md, "What the code
 * refuses"): smaller than it, with their band within a period, a free sphere
 * inside the walls and overlapping no other sphere (it would stop the run at
 * once: the immersed boundary has no contact model), and no sphere inside
 * another (fixed and prescribed spheres may overlap: their solid fractions
 * add up; pairs of DEM particles are the DEM's check).  keynum[p]: sphere p
 * came from [ibm] sphereK (K), spheres_file (0) or is a particle (-1). */
static void check_spheres(cfg_t *cfg, const grid_t *g, const ibm_sphere_t *s, int n, const int *keynum)
{
    const double band = ibm_band_halfwidth();
    static const char *face[3][2] = {{"x_lo", "x_hi"}, {"y_lo", "y_hi"}, {"z_lo", "z_hi"}};
    for (int p = 0; p < n; p++) {
        const double R = s[p].radius;
        /* the band's width is counted in the largest cell spacing at the sphere (alpha.c's
         * sphere_box), whatever the direction */
        int ic = g->periodic[0] ? 0 : ibm_lower_index(g, -1, s[p].x[0]);
        if (ic >= g->n[0]) ic = g->n[0] - 1;
        const double hmax = fmax(fmax(g->gdxf[ic], g->dy), g->dim == 3 ? g->dz : 0.0);
        for (int d = 0; d < g->dim; d++) {
            const double h = d == 0 ? g->gdxf[ic] : d == 1 ? g->dy : g->dz;
            /* along a periodic direction a sphere and its band must fit in the period */
            if (g->periodic[d] && 2 * (R + (band + 0.5) * hmax) + h > g->L[d])
                SPHERE_FAIL(p, "sphere %d (radius %g) and its band of %.2f cells of %g do not fit in the periodic %c "
                            "length %g: enlarge the domain", p + 1, R, band, hmax, "xyz"[d], g->L[d]);
            if (g->periodic[d]) continue;
            const int radial = g->geom == GEOM_AXI && d == 0; /* on the axis: its radius against the radial extent */
            if ((radial ? R : 2 * R) >= g->L[d])
                SPHERE_FAIL(p, "sphere %d (diameter %g) is larger than the domain in %c (%g)", p + 1, 2 * R, "xyz"[d],
                            g->L[d]);
            if (s[p].kind != IBM_FREE) continue;
            const double out_lo = radial ? 0.0 : g->x0[d] - (s[p].x[d] - R), out_hi = s[p].x[d] + R - (g->x0[d] + g->L[d]);
            if (out_lo > 0 || out_hi > 0)
                SPHERE_FAIL(p, "free sphere %d (radius %g, centre %c = %g) crosses the %s face of the domain: a free "
                            "sphere must start inside the walls", p + 1, R, "xyz"[d], s[p].x[d],
                            face[d][out_hi > out_lo]);
        }
    }
    overlap_box_t box = {.dim = g->dim};
    for (int d = 0; d < 3; d++) {
        box.lo[d] = g->x0[d];
        box.L[d] = g->L[d];
        box.periodic[d] = g->periodic[d];
    }
    double *x = xcalloc(3 * (size_t)n + 1, sizeof(double)), *r = xcalloc((size_t)n + 1, sizeof(double));
    unsigned char *act = xcalloc((size_t)n + 1, 1), *isfree = xcalloc((size_t)n + 1, 1);
    for (int p = 0; p < n; p++) {
        memcpy(&x[3 * p], s[p].x, 3 * sizeof(double));
        r[p] = s[p].radius;
        act[p] = keynum[p] >= 0;
        isfree[p] = s[p].kind == IBM_FREE;
    }
    /* a free sphere touching another would stop the run at once (sim_ibm.c);
     * other spheres may overlap (one solid), but not lie inside another */
    int i = 0, j = 0;
    double delta = 0;
    const int touch = overlap_find(&box, n, x, r, isfree, 0.0, &i, &j, &delta);
    const int inside = !touch && overlap_find(&box, n, x, r, act, 1.0 - 1e-9, &i, &j, &delta);
    free(x);
    free(r);
    free(act);
    free(isfree);
    const int q = keynum[j] >= 0 ? j : i; /* an [ibm] sphere's key rather than a particle's */
    if (touch)
        SPHERE_FAIL(q, "spheres %d and %d (radii %g and %g) overlap by %.3g %% of the smaller diameter, and one is free: "
                    "immersed spheres have no contact model", i + 1, j + 1, s[i].radius, s[j].radius,
                    100 * delta / (2 * fmin(s[i].radius, s[j].radius)));
    if (inside)
        SPHERE_FAIL(q, "sphere %d (radius %g) lies inside sphere %d (radius %g)", s[i].radius < s[j].radius ? i + 1 : j + 1,
                    fmin(s[i].radius, s[j].radius), s[i].radius < s[j].radius ? j + 1 : i + 1,
                    fmax(s[i].radius, s[j].radius));
}

ibm_t *ibm_create_from_config(cfg_t *cfg, fluid_t *f) { return ibm_create_from_config_with(cfg, f, NULL, 0); }

ibm_t *ibm_create_from_config_with(cfg_t *cfg, fluid_t *f, const ibm_sphere_t *extra, int nextra)
{
    const grid_t *g = f->g;
    ibm_params_t prm = ibm_default_params();
    prm.force_model = (ibm_force_model_t)cfg_enum(cfg, "ibm", "force_model");
    prm.virtual_mass = cfg_double(cfg, "ibm", "virtual_mass");
    prm.forcing_iterations = cfg_int(cfg, "ibm", "forcing_iterations");
    cfg_vec3(cfg, "ibm", "gravity", prm.gravity);
    prm.retraction = cfg_double(cfg, "ibm", "retraction");
    prm.forcing_time = cfg_double(cfg, "ibm", "forcing_time");
    prm.radius_calibrated = cfg_enum(cfg, "ibm", "radius_correction");
    prm.band_width = cfg_double(cfg, "ibm", "band_width");
    const char *rc_name = prm.radius_calibrated == IBM_RADIUS_GAPS ? "gaps" : "calibrated";
    if (prm.radius_calibrated && !(prm.forcing_time >= 0.1 && prm.forcing_time <= 0.3))
        cfg_fail(cfg, "ibm", "radius_correction",
                 "%s needs forcing_time in [0.1, 0.3] (the range of the calibration), not %g", rc_name,
                 prm.forcing_time);
    if (prm.radius_calibrated && prm.band_width != 1.0)
        cfg_fail(cfg, "ibm", "radius_correction", "%s is fitted on the seed's band: it needs band_width = 1, not %g",
                 rc_name, prm.band_width);
    if (prm.radius_calibrated && prm.forcing_iterations > 0)
        cfg_fail(cfg, "ibm", "radius_correction", "%s needs forcing_iterations = 0 (the calibrated forcing)", rc_name);
    if (prm.radius_calibrated == IBM_RADIUS_GAPS && g->dim != 3)
        cfg_fail(cfg, "ibm", "radius_correction", "gaps is fitted on 3-D arrays of spheres: not in a 2-D or "
                 "axisymmetric grid");
    prm.free_alpha_per_step = cfg_enum(cfg, "ibm", "free_alpha");
    prm.forcing_predictor = cfg_enum(cfg, "ibm", "cn_forcing") == 1;
    if (prm.forcing_predictor && prm.forcing_iterations > 0 && f->prm.implicit_viscous)
        cfg_fail(cfg, "ibm", "forcing_iterations",
                 "the forcing iterations (project, force) act after the solve: not with cn_forcing = predictor");
    if (g->geom == GEOM_AXI && (prm.gravity[0] != 0.0 || prm.gravity[2] != 0.0))
        cfg_fail(cfg, "ibm", "gravity", "an axisymmetric gravity must be axial (y)");
    if (g->dim == 2 && prm.gravity[2] != 0.0) cfg_fail(cfg, "ibm", "gravity", "a 2-D grid has no z direction");

    ibm_sphere_t *s = NULL;
    int n = 0, *keynum = NULL; /* the key of each sphere: sphereK (K), spheres_file (0), a particle (-1) */
    char *hist[IBM_KEYED_SPHERES];
    int hist_of[IBM_KEYED_SPHERES], hist_key[IBM_KEYED_SPHERES], nh = 0;
    for (int k = 1; k <= IBM_KEYED_SPHERES; k++) {
        char key[24];
        snprintf(key, sizeof key, "sphere%d", k);
        if (!cfg_has(cfg, "ibm", key)) continue;
        s = realloc(s, (size_t)(n + 1) * sizeof *s);
        keynum = realloc(keynum, (size_t)(n + 1) * sizeof *keynum);
        keynum[n] = k;
        char *h;
        parse_sphere(cfg, key, cfg_string(cfg, "ibm", key), &s[n], &h);
        const char *why = sphere_misfit(g, &s[n]);
        if (why) cfg_fail(cfg, "ibm", key, "%s", why);
        if (h) {
            hist[nh] = h;
            hist_key[nh] = k;
            hist_of[nh++] = n;
        }
        n++;
    }
    if (cfg_has(cfg, "ibm", "spheres_file")) {
        const char *path = cfg_string(cfg, "ibm", "spheres_file");
        double rho = cfg_has(cfg, "ibm", "density") ? cfg_double(cfg, "ibm", "density") : -1.0;
        int n0 = n;
        if (io_is_h5_path(path))
            spheres_from_h5(cfg, path, rho, &s, &n);
        else
            spheres_from_csv(cfg, path, rho, &s, &n);
        keynum = realloc(keynum, (size_t)(n + 1) * sizeof *keynum);
        for (int p = n0; p < n; p++) {
            keynum[p] = 0;
            if (g->dim == 2) s[p].x[2] = 0.0;
            if (s[p].kind == IBM_FREE && !(s[p].density > 0))
                cfg_fail(cfg, "ibm", cfg_has(cfg, "ibm", "density") ? "density" : "spheres_file",
                         "sphere %d of %s is free and has no density > 0 (give a density column or [ibm] density)",
                         p - n0 + 1, path);
            const char *why = sphere_misfit(g, &s[p]);
            if (why) cfg_fail(cfg, "ibm", "spheres_file", "sphere %d of %s: %s", p - n0 + 1, path, why);
        }
    }
    if (nextra > 0) {
        s = realloc(s, (size_t)(n + nextra) * sizeof *s);
        keynum = realloc(keynum, (size_t)(n + nextra) * sizeof *keynum);
        for (int p = 0; p < nextra; p++) {
            s[n + p] = extra[p];
            keynum[n + p] = -1;
            const char *why = sphere_misfit(g, &s[n + p]);
            if (why) cfg_fail(cfg, "particles", "source", "particle %d as an immersed sphere: %s", p, why);
        }
        n += nextra;
    }
    if (n == 0) cfg_fail(cfg, "ibm", "sphere1", "the [ibm] section defines no sphere (sphere1.. or spheres_file)");
    check_spheres(cfg, g, s, n, keynum);
    for (int p = 0; p < n; p++)
        if (prm.force_model == IBM_FORCE_RIGID && s[p].kind == IBM_FREE &&
            fabs(s[p].density - f->prm.rho) < 1e-12 * f->prm.rho)
            cfg_fail(cfg, "ibm", "force_model", "rigid divides by ρp − ρ = 0 for sphere %d (neutrally buoyant): use momentum",
                     p + 1);
    ibm_t *ibm = ibm_create(f, &prm, s, n);
    for (int h = 0; h < nh; h++) {
        int nrow;
        char key[24];
        snprintf(key, sizeof key, "sphere%d", hist_key[h]);
        double *rows = read_history(cfg, key, hist[h], &nrow);
        free(hist[h]);
        ibm_sphere_t *sp = &ibm->s[hist_of[h]];
        sp->history = ibm_add_history(ibm, nrow, rows);
        ibm_prescribed_velocity(ibm, sp, f->time, sp->u, sp->omega);
        free(rows);
    }
    if (nh > 0) ibm_update_geometry(ibm);
    free(s);
    free(keynum);
    return ibm;
}
