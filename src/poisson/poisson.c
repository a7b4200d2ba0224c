/* poisson.c — the discrete Laplacian of each variable location on the MAC
 * grid (the single definition every solver and the fluid use), its boundary
 * conditions, and dispatch to the solver back-ends (fft.c, multigrid.c). */
#include "poisson.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

static const cfg_key_t poisson_keys[] = {
    {"poisson", "method", CFG_ENUM, "fft", 1, 0, "fft|multigrid",
     "pressure/Helmholtz solver: direct FFT eigen-expansion or geometric multigrid"},
    {"poisson", "mg_tol", CFG_DOUBLE, "1e-10", 1e-15, 1e-2, NULL, "multigrid: relative residual to reach"},
    {"poisson", "mg_max_cycles", CFG_INT, "100", 1, 10000, NULL, "multigrid: maximum number of V-cycles"},
    {"poisson", "mg_pre", CFG_INT, "2", 0, 20, NULL, "multigrid: pre-smoothing sweeps"},
    {"poisson", "mg_post", CFG_INT, "2", 0, 20, NULL, "multigrid: post-smoothing sweeps"},
    {"poisson", "fftw_planner", CFG_ENUM, "estimate", 1, 0, "estimate|measure",
     "fft: FFTW planner; measure times candidate algorithms at start-up (at 128^3 the solve is 0-3 % faster "
     "than estimate's on 1 rank, 12-16 % on 2, docs/performance.md); its choices "
     "are kept as FFTW wisdom in the checkpoints and OUT/fftw.wisdom, so restarts are exact, and runs are "
     "bit-identical to each other when they share a wisdom file (fftw_wisdom)"},
    {"poisson", "fftw_wisdom", CFG_STRING, "none", 1, 0, NULL,
     "fft, measure planner only: FFTW wisdom file read before planning (by rank 0) and written when missing or "
     "when new transforms were measured; runs given the same file make the same plans (bit-identical results); "
     "none: no file"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void poisson_register_keys(void) { cfg_schema_add(poisson_keys); }

void poisson_opts_from_config(cfg_t *cfg, poisson_opts_t *o)
{
    o->method = (poisson_method_t)cfg_enum(cfg, "poisson", "method");
    o->mg_tol = cfg_double(cfg, "poisson", "mg_tol");
    o->mg_max_cycles = cfg_int(cfg, "poisson", "mg_max_cycles");
    o->mg_pre = cfg_int(cfg, "poisson", "mg_pre");
    o->mg_post = cfg_int(cfg, "poisson", "mg_post");
    o->fftw_measure = cfg_enum(cfg, "poisson", "fftw_planner") == 1;
    const char *w = cfg_string(cfg, "poisson", "fftw_wisdom");
    o->fftw_wisdom[0] = 0;
    if (strcmp(w, "none") != 0) {
        if (!o->fftw_measure)
            cfg_fail(cfg, "poisson", "fftw_wisdom",
                     "a wisdom file is used by fftw_planner = measure only (estimate plans are the same in every "
                     "run without one)");
        if (strlen(w) >= sizeof o->fftw_wisdom) cfg_fail(cfg, "poisson", "fftw_wisdom", "path too long");
        char why[4400];
        if (poisson_fftw_wisdom_check(w, why, sizeof why)) cfg_fail(cfg, "poisson", "fftw_wisdom", "%s", why);
        snprintf(o->fftw_wisdom, sizeof o->fftw_wisdom, "%s", w);
    }
}

/* Homogeneous BC of face (d, s) for location loc. */
static ebc_t face_ebc(const grid_t *g, var_loc_t loc, int d, int s)
{
    bc_type_t t = g->bc.type[d][s];
    if (t == BC_PERIODIC) return EBC_PERIODIC;
    if (loc == VAR_P) return EBC_NEUMANN;
    if ((int)loc == d) return EBC_DIRICHLET_FACE; /* normal component: no penetration (u_r = 0 on the axis) */
    if (t == BC_NOSLIP) return EBC_DIRICHLET_GHOST;
    return EBC_NEUMANN;                           /* free slip, or a tangential component on the axis */
}

poisson_t *poisson_create_operator(const grid_t *g, var_loc_t loc)
{
    poisson_t *p = xcalloc(1, sizeof *p);
    p->g = g;
    p->loc = loc;
    p->singular = 1;
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++) {
            p->ebc[d][s] = d < g->dim ? face_ebc(g, loc, d, s) : EBC_PERIODIC;
            if (p->ebc[d][s] == EBC_DIRICHLET_FACE || p->ebc[d][s] == EBC_DIRICHLET_GHOST) p->singular = 0;
        }
    for (int d = 0; d < 3; d++) p->nu[d] = g->n[d] - (p->ebc[d][1] == EBC_DIRICHLET_FACE ? 1 : 0);

    /* x coefficients on the global grid.  a(f) is the face area factor (r in
     * axisymmetric geometry, 1 otherwise). */
    int nx = g->n[0], axi = g->geom == GEOM_AXI;
    double *buf = xcalloc((size_t)3 * nx, sizeof(double));
    p->cw = buf;
    p->ce = buf + nx;
    p->cd = buf + 2 * nx;
    for (int i = 0; i < p->nu[0]; i++) {
        double w, e, d;
        if (loc == VAR_U && axi) {
            /* u_r: ∂r[(1/r)∂r(r u_r)], the r-derivative of the discrete
             * divergence g_i = (r_f,i u_i − r_f,i−1 u_{i−1})/(r_c,i Δr_i); equal
             * to the vector Laplacian (1/r)∂r(r ∂r u_r) − u_r/r² and second
             * order up to the axis. */
            e = g->gxf[i + 1] / (g->gxc[i + 1] * g->gdxf[i + 1] * g->gdxc[i]);
            w = g->gxf[i - 1] / (g->gxc[i] * g->gdxf[i] * g->gdxc[i]);
            d = (g->gxf[i] / (g->gxc[i + 1] * g->gdxf[i + 1]) + g->gxf[i] / (g->gxc[i] * g->gdxf[i])) / g->gdxc[i];
        } else if (loc == VAR_U) {
            /* u at face i: fluxes at the cell centres i and i+1 */
            e = 1.0 / (g->gdxf[i + 1] * g->gdxc[i]);
            w = 1.0 / (g->gdxf[i] * g->gdxc[i]);
            d = w + e;
        } else {
            /* cell-centred in x: fluxes at faces i−1 and i */
            double ae = axi ? g->gxf[i] : 1.0, aw = axi ? g->gxf[i - 1] : 1.0;
            double vol = axi ? g->gxc[i] * g->gdxf[i] : g->gdxf[i];
            e = ae / (g->gdxc[i] * vol);
            w = aw / (g->gdxc[i - 1] * vol);
            d = w + e;
        }
        if (i == 0 && p->ebc[0][0] != EBC_PERIODIC) {
            if (p->ebc[0][0] == EBC_DIRICHLET_GHOST) d += w; /* ghost = −interior */
            if (p->ebc[0][0] == EBC_NEUMANN) d -= w;         /* zero flux */
            w = 0.0;                                          /* Dirichlet face: boundary value 0 */
        }
        if (i == p->nu[0] - 1 && p->ebc[0][1] != EBC_PERIODIC) {
            if (p->ebc[0][1] == EBC_DIRICHLET_GHOST) d += e;
            if (p->ebc[0][1] == EBC_NEUMANN) d -= e;
            e = 0.0;
        }
        p->cw[i] = w;
        p->ce[i] = e;
        p->cd[i] = d;
    }
    p->cy = 1.0 / (g->dy * g->dy);
    p->cz = g->dim == 3 ? 1.0 / (g->dz * g->dz) : 0.0;
    return p;
}

poisson_t *poisson_create(const grid_t *g, var_loc_t loc, const poisson_opts_t *opt)
{
    poisson_t *p = poisson_create_operator(g, loc);
    poisson_add_solver(p, opt);
    return p;
}

void poisson_add_solver(poisson_t *p, const poisson_opts_t *opt)
{
    if (p->impl) return;
    if (opt)
        p->opt = *opt;
    else {
        p->opt.method = POISSON_FFT;
        p->opt.mg_tol = 1e-10;
        p->opt.mg_max_cycles = 100;
        p->opt.mg_pre = p->opt.mg_post = 2;
    }
    p->backend = p->opt.method == POISSON_FFT ? &poisson_backend_fft : &poisson_backend_mg;
    p->impl = p->backend->create(p);
}

void poisson_free(poisson_t *p)
{
    if (!p) return;
    if (p->backend && p->impl) p->backend->destroy(p->impl);
    free(p->cw);
    free(p->rhs_scratch);
    free(p);
}

int poisson_is_unknown(const poisson_t *p, int i, int j, int k)
{
    int ig = i + p->g->ix0;
    return ig >= 0 && ig < p->nu[0] && j >= 0 && j < p->nu[1] && k >= 0 && k < p->nu[2] && i >= 0 &&
           i < p->g->nxl;
}

/* The y and z boundary ghosts of the x planes ilo..ihi for the homogeneous
 * BCs (after the periodic copies; for a Dirichlet face the boundary value
 * itself, index n−1, is zero): each plane's ghosts come from the same plane,
 * y before z (the z ghosts of the y ghost rows are set last). */
static void fill_yz_face_ghosts(const poisson_t *p, double *x, int ilo, int ihi)
{
    const grid_t *g = p->g;
    int ny = g->n[1], nz = g->n[2], gz = g->gz;
    /* y faces */
    if (p->ebc[1][0] != EBC_PERIODIC)
        for (int i = ilo; i <= ihi; i++)
            for (int k = -gz; k < nz + gz; k++) {
                double in = x[G_IDX(g, i, 0, k)];
                ebc_t lo = p->ebc[1][0], hi = p->ebc[1][1];
                x[G_IDX(g, i, -1, k)] = lo == EBC_NEUMANN ? in : lo == EBC_DIRICHLET_GHOST ? -in : 0.0;
                if (hi == EBC_DIRICHLET_FACE) {
                    x[G_IDX(g, i, ny - 1, k)] = 0.0;
                    x[G_IDX(g, i, ny, k)] = 0.0;
                } else {
                    double inh = x[G_IDX(g, i, ny - 1, k)];
                    x[G_IDX(g, i, ny, k)] = hi == EBC_NEUMANN ? inh : -inh;
                }
            }
    /* z faces */
    if (g->dim == 3 && p->ebc[2][0] != EBC_PERIODIC)
        for (int i = ilo; i <= ihi; i++)
            for (int j = -1; j <= ny; j++) {
                double in = x[G_IDX(g, i, j, 0)];
                ebc_t lo = p->ebc[2][0], hi = p->ebc[2][1];
                x[G_IDX(g, i, j, -1)] = lo == EBC_NEUMANN ? in : lo == EBC_DIRICHLET_GHOST ? -in : 0.0;
                if (hi == EBC_DIRICHLET_FACE) {
                    x[G_IDX(g, i, j, nz - 1)] = 0.0;
                    x[G_IDX(g, i, j, nz)] = 0.0;
                } else {
                    double inh = x[G_IDX(g, i, j, nz - 1)];
                    x[G_IDX(g, i, j, nz)] = hi == EBC_NEUMANN ? inh : -inh;
                }
            }
}

/* x: the boundary is folded into the coefficients; zero the boundary value of
 * a Dirichlet face so that fields stay clean. */
static void fill_x_face_values(const poisson_t *p, double *x)
{
    const grid_t *g = p->g;
    int nxl = g->nxl, ny = g->n[1], nz = g->n[2], gz = g->gz;
    if (p->ebc[0][1] == EBC_DIRICHLET_FACE && g->right == MPI_PROC_NULL) {
        for (int j = -1; j <= ny; j++)
            for (int k = -gz; k < nz + gz; k++) x[G_IDX(g, nxl - 1, j, k)] = 0.0;
    }
    if (p->ebc[0][0] == EBC_DIRICHLET_FACE && g->left == MPI_PROC_NULL) {
        for (int j = -1; j <= ny; j++)
            for (int k = -gz; k < nz + gz; k++) x[G_IDX(g, -1, j, k)] = 0.0;
    }
}

void poisson_fill_ghosts(const poisson_t *p, double *x)
{
    grid_halo(p->g, x);
    fill_yz_face_ghosts(p, x, -1, p->g->nxl);
    fill_x_face_values(p, x);
}

void poisson_fill_ghosts_plane(const poisson_t *p, double *x, int i)
{
    grid_halo_yz_planes(p->g, x, i, i);
    fill_yz_face_ghosts(p, x, i, i);
}

void poisson_fill_ghosts_edges(const poisson_t *p, double *x)
{
    const grid_t *g = p->g;
    grid_halo_yz_planes(g, x, -1, 0);
    grid_halo_yz_planes(g, x, g->nxl - 1, g->nxl);
    grid_halo_x(g, x);
    fill_yz_face_ghosts(p, x, -1, 0);
    fill_yz_face_ghosts(p, x, g->nxl - 1, g->nxl);
    fill_x_face_values(p, x);
}

void poisson_apply(poisson_t *p, double lambda, double *x, double *y)
{
    const grid_t *g = p->g;
    poisson_fill_ghosts(p, x);
    int nxl = g->nxl, ix0 = g->ix0;
    int nyu = p->nu[1], nzu = p->nu[2];
    long sx = g->sx, sy = g->sy;
    double cy = p->cy, cz = p->cz;
    for (int i = 0; i < nxl; i++) {
        int ig = i + ix0;
        if (ig >= p->nu[0]) continue;
        double cw = p->cw[ig], ce = p->ce[ig], cd = p->cd[ig] + lambda;
        for (int j = 0; j < nyu; j++) {
            long c0 = G_IDX(g, i, j, 0);
            if (g->dim == 3) {
                for (int k = 0; k < nzu; k++) {
                    long c = c0 + k;
                    y[c] = cw * x[c - sx] + ce * x[c + sx] - cd * x[c] + cy * (x[c + sy] - 2.0 * x[c] + x[c - sy]) +
                           cz * (x[c + 1] - 2.0 * x[c] + x[c - 1]);
                }
            } else {
                long c = c0;
                y[c] = cw * x[c - sx] + ce * x[c + sx] - cd * x[c] + cy * (x[c + sy] - 2.0 * x[c] + x[c - sy]);
            }
        }
    }
}

/* Volume weight of unknown i (global) for the compatibility condition of a
 * singular problem: Σ w_i (L x)_i = 0 for every x. */
double poisson_x_weight(const poisson_t *p, int ig)
{
    const grid_t *g = p->g;
    if (p->loc == VAR_U) return g->geom == GEOM_AXI ? g->gxf[ig] * g->gdxc[ig] : g->gdxc[ig];
    return g->geom == GEOM_AXI ? g->gxc[ig] * g->gdxf[ig] : g->gdxf[ig];
}

/* Weighted mean of the unknowns of f. */
double poisson_weighted_mean(const poisson_t *p, const double *f)
{
    const grid_t *g = p->g;
    double s = 0.0, w = 0.0;
    for (int i = 0; i < g->nxl; i++) {
        int ig = i + g->ix0;
        if (ig >= p->nu[0]) continue;
        double wi = poisson_x_weight(p, ig), si = 0.0;
        for (int j = 0; j < p->nu[1]; j++)
            for (int k = 0; k < p->nu[2]; k++) si += f[G_IDX(g, i, j, k)];
        s += wi * si;
        w += wi * p->nu[1] * p->nu[2];
    }
    double sw[2] = {s, w}, r[2];
    MPI_Allreduce(sw, r, 2, MPI_DOUBLE, MPI_SUM, g->comm);
    return r[0] / r[1];
}

void poisson_add_constant(const poisson_t *p, double *f, double c)
{
    const grid_t *g = p->g;
    for (int i = 0; i < g->nxl; i++) {
        if (i + g->ix0 >= p->nu[0]) continue;
        for (int j = 0; j < p->nu[1]; j++)
            for (int k = 0; k < p->nu[2]; k++) f[G_IDX(g, i, j, k)] += c;
    }
}

int poisson_solve(poisson_t *p, double lambda, const double *b, double *x)
{
    if (!p->backend) die("poisson_solve: operator created without a solver (poisson_create_operator)");
    const double *rhs = b;
    int sing = p->singular && lambda == 0.0 && !p->backend_handles_singular;
    if (sing) {
        /* Remove the incompatible part (weighted mean) of b, in a scratch
         * field kept with the solver (this runs every projection). */
        double m = poisson_weighted_mean(p, b);
        if (!p->rhs_scratch) p->rhs_scratch = field_alloc(p->g);
        field_copy(p->g, p->rhs_scratch, b);
        poisson_add_constant(p, p->rhs_scratch, -m);
        rhs = p->rhs_scratch;
    }
    int rc = p->backend->solve(p, p->impl, lambda, rhs, x);
    if (sing) poisson_add_constant(p, x, -poisson_weighted_mean(p, x));
    return rc;
}

double poisson_residual(poisson_t *p, double lambda, const double *b, double *x)
{
    const grid_t *g = p->g;
    double *y = field_alloc(g);
    double *bb = field_alloc(g);
    field_copy(g, bb, b);
    if (p->singular && lambda == 0.0) poisson_add_constant(p, bb, -poisson_weighted_mean(p, b));
    poisson_apply(p, lambda, x, y);
    double rr = 0.0, bn = 0.0;
    for (int i = 0; i < g->nxl; i++)
        for (int j = 0; j < g->n[1]; j++)
            for (int k = 0; k < g->n[2]; k++) {
                if (!poisson_is_unknown(p, i, j, k)) continue;
                long c = G_IDX(g, i, j, k);
                double r = bb[c] - y[c];
                rr += r * r;
                bn += bb[c] * bb[c];
            }
    double v[2] = {rr, bn}, s[2];
    MPI_Allreduce(v, s, 2, MPI_DOUBLE, MPI_SUM, g->comm);
    free(y);
    free(bb);
    return s[1] > 0 ? sqrt(s[0] / s[1]) : sqrt(s[0]);
}
