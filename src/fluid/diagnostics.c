/* diagnostics.c — discrete divergence, kinetic energy, control volumes and
 * the per-step diagnostics. */
#include <math.h>

#include "fluid_internal.h"

double fluid_cell_volume(const fluid_t *f, int c, int i)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    double yz = g->dy * (g->dim == 3 ? g->dz : 1.0);
    /* u: from x_c,i to x_c,i+1 (area factor at the face); v, w: the pressure
     * cell's x extent.  These weights make G = −Dᵀ and the advection
     * skew-symmetric (advection.c). */
    return c == 0 ? q->af[i] * g->dxc[i] * yz : q->ac[i] * g->dxf[i] * yz;
}

static inline __attribute__((always_inline)) void div_line(const double *restrict u, const double *restrict v,
                                                            const double *restrict w, double *restrict div, long c0,
                                                            long len, long sx, long sy, double a, double b, double rdy,
                                                            double rdz, double scale, int is3d)
{
    for (long m = c0; m < c0 + len; m++) {
        double d = a * u[m] - b * u[m - sx] + (v[m] - v[m - sy]) * rdy;
        if (is3d) d += (w[m] - w[m - 1]) * rdz;
        div[m] = scale * d;
    }
}

/* div = scale · D u over the cells (i, j, k), j0 ≤ j < j1, k0 ≤ k < k1 (3-D),
 * of the velocity arrays uu (which need not be f->u). */
static void div_block(const fluid_t *f, const double *const uu[3], double scale, double *div, int i, int j0, int j1,
                      int k0, int k1)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    double a = q->af[i] / (q->ac[i] * g->dxf[i]), b = q->af[i - 1] / (q->ac[i] * g->dxf[i]);
    for (int j = j0; j < j1; j++)
        div_line(uu[0], uu[1], uu[2], div, G_IDX(g, i, j, k0), k1 - k0, g->sx, g->sy, a, b, 1.0 / g->dy,
                 1.0 / g->dz, scale, 1);
}

void fluid_divergence_scaled(const fluid_t *f, double scale, double *div)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    for (int i = 0; i < g->nxl; i++) {
        double a = q->af[i] / (q->ac[i] * g->dxf[i]), b = q->af[i - 1] / (q->ac[i] * g->dxf[i]);
        FLUID_FOR_LINES(g, i, g->n[1], g->n[2], c0, len)
        {
            if (w) div_line(u, v, w, div, c0, len, g->sx, g->sy, a, b, rdy, rdz, scale, 1);
            else div_line(u, v, w, div, c0, len, g->sx, g->sy, a, b, rdy, rdz, scale, 0);
        }
    }
}

/* The cells whose divergence stencil reads only unknowns of this rank (no
 * ghost, no halo, no boundary value): 3-D only, i in [1, ihi), j in [1, jhi),
 * k in [1, khi), where the high bound excludes the last cell when the face
 * beyond it is a wall (its normal velocity is a boundary value, set by
 * fluid_apply_bc) and, for x, when the last local plane borders a wall.
 * The cells next to a wall are also where the quadratic-ghost wall terms
 * change u* after the sweep, so they are never in the interior. */
typedef struct {
    int ilo, ihi, jlo, jhi, klo, khi;
} fluid_interior_t;

static fluid_interior_t fluid_interior(const grid_t *g)
{
    fluid_interior_t b;
    b.ilo = 1;
    b.ihi = !g->periodic[0] && g->right == MPI_PROC_NULL ? g->nxl - 1 : g->nxl;
    b.jlo = 1;
    b.jhi = g->periodic[1] ? g->n[1] : g->n[1] - 1;
    b.klo = 1;
    b.khi = g->periodic[2] ? g->n[2] : g->n[2] - 1;
    return b;
}

/* What a pass split by fluid_interior computes on a block of cells: the
 * scaled divergence of uu into div, or (div NULL) max |D u| and the
 * convective rate of f->u into m. */
typedef struct {
    const double *const *uu;
    double scale, *div, *m;
} split_pass_t;

static void div_cfl_block(const fluid_t *f, double *m, int i, int j0, int j1, int k0, int k1);

static void split_block(const fluid_t *f, const split_pass_t *sp, int i, int j0, int j1, int k0, int k1)
{
    if (sp->div) div_block(f, sp->uu, sp->scale, sp->div, i, j0, j1, k0, k1);
    else div_cfl_block(f, sp->m, i, j0, j1, k0, k1);
}

/* the interior cells of plane i */
static void split_interior_plane(const fluid_t *f, const split_pass_t *sp, int i)
{
    fluid_interior_t b = fluid_interior(f->g);
    if (i >= b.ilo && i < b.ihi) split_block(f, sp, i, b.jlo, b.jhi, b.klo, b.khi);
}

/* the cells of interior plane i (ilo ≤ i < ihi) outside the interior */
static void split_rest_plane(const fluid_t *f, const split_pass_t *sp, const fluid_interior_t *b, int i)
{
    int ny = f->g->n[1], nz = f->g->n[2];
    split_block(f, sp, i, 0, b->jlo, 0, nz);
    split_block(f, sp, i, b->jhi, ny, 0, nz);
    split_block(f, sp, i, b->jlo, b->jhi, 0, b->klo);
    split_block(f, sp, i, b->jlo, b->jhi, b->khi, nz);
}

/* every cell outside the interior (edges_only: those of the planes outside
 * [ilo, ihi) only, the others' done by split_rest_plane) */
static void split_rest(const fluid_t *f, const split_pass_t *sp, int edges_only)
{
    const grid_t *g = f->g;
    fluid_interior_t b = fluid_interior(g);
    int ny = g->n[1], nz = g->n[2];
    for (int i = 0; i < g->nxl; i++) {
        if (i < b.ilo || i >= b.ihi) split_block(f, sp, i, 0, ny, 0, nz);
        else if (!edges_only) split_rest_plane(f, sp, &b, i);
    }
}

/* Fused divergence (docs/theory.md §1, step 1.1): a sweep that writes u plane by plane
 * calls this once plane i of every component is final, while the plane is
 * still in cache; fluid_divergence_rest completes the field once the ghosts
 * are valid.  Together they give exactly fluid_divergence_scaled (the same
 * expression per cell). */
void fluid_divergence_interior_plane(const fluid_t *f, const double *const uu[3], double scale, double *div, int i)
{
    split_interior_plane(f, &(split_pass_t){.uu = uu, .scale = scale, .div = div}, i);
}

void fluid_divergence_rest(const fluid_t *f, double scale, double *div, int edges_only)
{
    const double *uu[3] = {f->u[0], f->u[1], f->u[2]};
    split_rest(f, &(split_pass_t){.uu = uu, .scale = scale, .div = div}, edges_only);
}

/* The planes whose every cell the sweep can complete (ilo ≤ i < ihi). */
void fluid_interior_planes(const grid_t *g, int *ilo, int *ihi)
{
    fluid_interior_t b = fluid_interior(g);
    *ilo = b.ilo;
    *ihi = b.ihi;
}

/* The cells of interior plane i that fluid_divergence_interior_plane leaves
 * (next to a y or z face), once the ghosts of plane i of uu are filled: the
 * plane's divergence complete inside the sweep (a plane of the edges is
 * left to fluid_divergence_rest with edges_only). */
void fluid_divergence_rest_plane(const fluid_t *f, const double *const uu[3], double scale, double *div, int i)
{
    fluid_interior_t b = fluid_interior(f->g);
    if (i >= b.ilo && i < b.ihi) split_rest_plane(f, &(split_pass_t){.uu = uu, .scale = scale, .div = div}, &b, i);
}

void fluid_divergence(const fluid_t *f, double *div) { fluid_divergence_scaled(f, 1.0, div); }

/* max |D u| (into m[0]) and max over the cells of the convective rate
 * Σ_d max(|u_d| at the two faces)/Δ_d (into m[1]) along one line: the
 * divergence is the one of div_line (the same per-i coefficients), written
 * without branches or divisions so that the loop vectorises. */
static inline __attribute__((always_inline)) void div_cfl_line(const double *restrict u, const double *restrict v,
                                                                const double *restrict w, long c0, long len, long sx,
                                                                long sy, double a, double b, double rdx, double rdy,
                                                                double rdz, double *m, int is3d)
{
    double dm = m[0], sm = m[1];
    for (long c = c0; c < c0 + len; c++) {
        double d = a * u[c] - b * u[c - sx] + (v[c] - v[c - sy]) * rdy;
        double s = dmax(fabs(u[c]), fabs(u[c - sx])) * rdx + dmax(fabs(v[c]), fabs(v[c - sy])) * rdy;
        if (is3d) {
            d += (w[c] - w[c - 1]) * rdz;
            s += dmax(fabs(w[c]), fabs(w[c - 1])) * rdz;
        }
        dm = dmax(dm, fabs(d));
        sm = dmax(sm, s);
    }
    m[0] = dm;
    m[1] = sm;
}

/* this rank's max |D u| and max convective rate, updating m[0], m[1] */
static void divergence_cfl_rate(const fluid_t *f, double *m)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    for (int i = 0; i < g->nxl; i++) {
        double a = q->af[i] / (q->ac[i] * g->dxf[i]), b = q->af[i - 1] / (q->ac[i] * g->dxf[i]), rdx = 1.0 / g->dxf[i];
        FLUID_FOR_LINES(g, i, g->n[1], g->n[2], c0, len)
        {
            if (w) div_cfl_line(u, v, w, c0, len, g->sx, g->sy, a, b, rdx, rdy, rdz, m, 1);
            else div_cfl_line(u, v, w, c0, len, g->sx, g->sy, a, b, rdx, rdy, rdz, m, 0);
        }
    }
}

/* the same over the cells (i, j0..j1−1, k0..k1−1) of a 3-D grid */
static void div_cfl_block(const fluid_t *f, double *m, int i, int j0, int j1, int k0, int k1)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    double a = q->af[i] / (q->ac[i] * g->dxf[i]), b = q->af[i - 1] / (q->ac[i] * g->dxf[i]), rdx = 1.0 / g->dxf[i];
    for (int j = j0; j < j1; j++)
        div_cfl_line(f->u[0], f->u[1], f->u[2], G_IDX(g, i, j, k0), k1 - k0, g->sx, g->sy, a, b, rdx, 1.0 / g->dy,
                     1.0 / g->dz, m, 1);
}

/* The diagnostic pass split as the fused divergence (fluid_interior): the
 * interior of plane i from the sweep that makes it final, the rest after the
 * ghosts are filled.  A maximum does not depend on the order. */
void fluid_div_cfl_interior_plane(const fluid_t *f, int i, double *m)
{
    split_interior_plane(f, &(split_pass_t){.m = m}, i);
}

void fluid_div_cfl_rest(const fluid_t *f, double *m) { split_rest(f, &(split_pass_t){.m = m}, 0); }

double fluid_max_divergence(const fluid_t *f)
{
    double loc[2] = {0.0, 0.0};
    divergence_cfl_rate(f, loc);
    return grid_max(f->g, loc[0]);
}

/* Σ V u² (this rank) and max |u| over the unknowns of component c. */
static void component_stats(const fluid_t *f, int c, double *e, double *umax)
{
    const grid_t *g = f->g;
    const double *u = f->u[c];
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    double m = 0.0, sum = 0.0;
    for (int i = 0; i < iend; i++) {
        double s = 0.0;
        for (int j = 0; j < nj; j++) {
            const double *r = u + G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) {
                s += r[k] * r[k];
                m = dmax(m, fabs(r[k]));
            }
        }
        sum += fluid_cell_volume(f, c, i) * s;
    }
    *e += sum;
    *umax = dmax(*umax, m);
}

double fluid_kinetic_energy(const fluid_t *f)
{
    const grid_t *g = f->g;
    double e = 0.0, m = 0.0;
    for (int c = 0; c < fluid_ncomp(g); c++) component_stats(f, c, &e, &m);
    e = 0.5 * grid_sum(g, e);
    return g->geom == GEOM_AXI ? 2.0 * M_PI * e : e;
}

/* The mean of velocity component c over the box, weighted by the control
 * volumes of its unknowns (all ranks).  Along a periodic direction c it is the
 * flux through any cross-section normal to c per unit area (discrete
 * continuity: every cross-section carries the same flux): the superficial
 * velocity of a periodic flow, solid included. */
double fluid_mean_velocity(const fluid_t *f, int c)
{
    const grid_t *g = f->g;
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    double sum = 0.0, vol = 0.0;
    for (int i = 0; i < iend; i++) {
        double s = 0.0;
        for (int j = 0; j < nj; j++) {
            const double *r = f->u[c] + G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) s += r[k];
        }
        double v = fluid_cell_volume(f, c, i);
        sum += v * s;
        vol += v * nj * nk;
    }
    sum = grid_sum(g, sum);
    vol = grid_sum(g, vol);
    return vol > 0 ? sum / vol : 0.0;
}

/* Constant flow rate (fluid_params_t hold_flow, docs/theory.md §1 "Constant
 * flow rate"): after a step the superficial velocity U along the periodic
 * direction d is brought to the target U_t by adding Δ = U_t − U to every
 * unknown of u_d (a uniform field: divergence-free, and it raises the mean by
 * exactly Δ), as the mean pressure gradient Δ/Δt would over the step; the
 * body force along d becomes f + Δ/Δt, the drive of the next step.  At a
 * steady state Δ = 0 and f is the force the flow needs (the drag of the
 * solid per unit fluid mass), whatever Δt. */
void fluid_hold_flow_rate(fluid_t *f, double dt)
{
    const grid_t *g = f->g;
    const int c = f->prm.hold_dir;
    const double delta = f->prm.hold_velocity - fluid_mean_velocity(f, c);
    int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
    for (int i = 0; i < iend; i++)
        for (int j = 0; j < nj; j++) {
            double *r = f->u[c] + G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) r[k] += delta;
        }
    f->prm.body_force[c] += delta / dt;
    fluid_apply_bc(f);
}

/* One sweep over the cells for the divergence and the convective rate (and,
 * unless the last projection gave them, one per component for the energy and
 * max |u|), two reductions. */
void fluid_update_diagnostics(fluid_t *f, const double *stats, const double *div_cfl)
{
    const grid_t *g = f->g;
    double loc[3] = {0, 0, 0}, glob[3]; /* max |D u|, max Σ|u_d|/Δ_d, max |u| */
    if (div_cfl) {
        loc[0] = div_cfl[0];
        loc[1] = div_cfl[1];
    } else
        divergence_cfl_rate(f, loc);
    double e = 0.0;
    if (stats) {
        e = stats[0];
        loc[2] = stats[1];
    } else
        for (int c = 0; c < fluid_ncomp(g); c++) component_stats(f, c, &e, &loc[2]);
    MPI_Allreduce(loc, glob, 3, MPI_DOUBLE, MPI_MAX, g->comm);
    e = 0.5 * grid_sum(g, e);
    f->diag.ke = g->geom == GEOM_AXI ? 2.0 * M_PI * e : e;
    f->diag.cfl = f->diag.dt * glob[1];
    /* |D u| relative to the largest velocity over the smallest cell */
    const double dmin = grid_min_spacing(g);
    f->diag.div_max = glob[2] > 0 ? glob[0] * dmin / glob[2] : glob[0];
}
