/* grid.c — staggered grid geometry, slab decomposition in x, halo exchange. */
#include "grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

static const cfg_key_t grid_keys[] = {
    {"domain", "geometry", CFG_ENUM, "3d", 1, 0, "3d|2d|axisymmetric",
     "3d Cartesian, 2d planar (x, y), or axisymmetric (x = r from the axis, y = axial)"},
    {"domain", "nx", CFG_INT, NULL, 1, 1 << 20, NULL,
     "cells in x (r when axisymmetric); must divide by the rank count; or give cells_per_diameter",
     CFG_CONDITIONAL},
    {"domain", "ny", CFG_INT, NULL, 1, 1 << 20, NULL, "cells in y; or give cells_per_diameter", CFG_CONDITIONAL},
    {"domain", "nz", CFG_INT, "1", 1, 1 << 20, NULL, "cells in z (must be 1 in 2d and axisymmetric)"},
    {"domain", "cells_per_diameter", CFG_DOUBLE, NULL, 1e-300, 1e300, NULL,
     "the resolution D/Δx instead of nx, ny, nz: each direction gets length/diameter × cells_per_diameter cells "
     "(a whole number: bad input otherwise), the cells are cubes; uniform grids only", CFG_OPTIONAL},
    {"domain", "diameter", CFG_DOUBLE, NULL, 1e-300, 1e300, NULL,
     "the diameter D (m) of cells_per_diameter (e.g. the sphere's)", CFG_CONDITIONAL},
    {"domain", "length", CFG_VEC3, NULL, 1e-300, 1e300, NULL, "domain size Lx Ly Lz (Lz ignored in 2-D)"},
    {"domain", "origin", CFG_VEC3, "0 0 0", -1e300, 1e300, NULL, "low corner of the domain (x must be 0 when axisymmetric)"},
    {"domain", "x_stretch", CFG_ENUM, "uniform", 1, 0, "uniform|tanh_low|tanh_high|tanh_both|uniform_arithmetic",
     "spacing in x: uniform, tanh clustering at the low, high or both x faces, or uniform_arithmetic (uniform "
     "from the low face over x_uniform_length in x_uniform_cells cells, then growing in arithmetic progression)"},
    {"domain", "x_uniform_cells", CFG_INT, "0", 1, 1 << 20, NULL, "uniform_arithmetic: cells of the uniform part"},
    {"domain", "x_uniform_length", CFG_DOUBLE, "0", 0, 1e300, NULL, "uniform_arithmetic: length of the uniform part"},
    {"domain", "x_stretch_beta", CFG_DOUBLE, "2.0", 1e-6, 20, NULL, "strength of the tanh clustering"},
#define FACE_KEYS(F)                                                                                        \
    {"boundary", F, CFG_ENUM, "periodic", 1, 0, "periodic|noslip|freeslip|axis",                             \
     "boundary condition on this face (axis: only x_lo of an axisymmetric grid)"},                          \
        {"boundary", F "_velocity", CFG_VEC3, "0 0 0", -1e300, 1e300, NULL,                                    \
         "velocity (u v w) of a no-slip wall on this face; the normal component must be 0"}
    FACE_KEYS("x_lo"), FACE_KEYS("x_hi"), FACE_KEYS("y_lo"), FACE_KEYS("y_hi"), FACE_KEYS("z_lo"),
    FACE_KEYS("z_hi"),
#undef FACE_KEYS
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void grid_register_keys(void) { cfg_schema_add(grid_keys); }

static const char *face_name[3][2] = {{"x_lo", "x_hi"}, {"y_lo", "y_hi"}, {"z_lo", "z_hi"}};

/* [domain] cells_per_diameter = D/Δx with diameter = D: n_d = L_d D⁻¹ (D/Δx) cells
 * in each direction, which must be a whole number (to 1e-9 of it), so that the
 * cells are cubes of side D/(D/Δx). */
static void cells_from_diameter(cfg_t *cfg, geom_t geom, stretch_t st, const double L[3], int n[3])
{
    static const char *nkey[3] = {"nx", "ny", "nz"};
    for (int d = 0; d < 3; d++)
        if (cfg_has(cfg, "domain", nkey[d]))
            cfg_fail(cfg, "domain", nkey[d], "give the cell counts or cells_per_diameter, not both");
    if (st != STRETCH_UNIFORM)
        cfg_fail(cfg, "domain", "cells_per_diameter", "needs a uniform grid (x_stretch = uniform)");
    const double cpd = cfg_double(cfg, "domain", "cells_per_diameter"), D = cfg_double(cfg, "domain", "diameter");
    const int dims = geom == GEOM_3D ? 3 : 2;
    n[2] = 1;
    for (int d = 0; d < dims; d++) {
        const double c = L[d] / D * cpd;
        if (!(c >= 0.5 && c < (1 << 20)) || fabs(c - nearbyint(c)) > 1e-9 * c)
            cfg_fail(cfg, "domain", "cells_per_diameter",
                     "length %c / diameter × cells_per_diameter = %.10g / %.10g × %.10g = %.10g is not a whole number of "
                     "cells: change the length or the resolution",
                     "xyz"[d], L[d], D, cpd, c);
        n[d] = (int)nearbyint(c);
    }
    msg("domain: D/dx = %g with D = %g: %d x %d x %d cells\n", cpd, D, n[0], n[1], n[2]);
}

grid_t *grid_create_from_config(cfg_t *cfg, MPI_Comm comm)
{
    geom_t geom = (geom_t)cfg_enum(cfg, "domain", "geometry");
    double L[3], x0[3];
    cfg_vec3(cfg, "domain", "length", L);
    cfg_vec3(cfg, "domain", "origin", x0);
    stretch_t st = (stretch_t)cfg_enum(cfg, "domain", "x_stretch");
    int n[3];
    if (cfg_has(cfg, "domain", "cells_per_diameter"))
        cells_from_diameter(cfg, geom, st, L, n);
    else {
        if (cfg_has(cfg, "domain", "diameter"))
            cfg_fail(cfg, "domain", "diameter", "the diameter of cells_per_diameter, which is not given");
        n[0] = cfg_int(cfg, "domain", "nx");
        n[1] = cfg_int(cfg, "domain", "ny");
        n[2] = cfg_int(cfg, "domain", "nz");
    }
    double beta = cfg_double(cfg, "domain", "x_stretch_beta");
    bc_t bc;
    memset(&bc, 0, sizeof bc);
    for (int d = 0; d < 3; d++)
        for (int s = 0; s < 2; s++) {
            char vk[32];
            bc.type[d][s] = (bc_type_t)cfg_enum(cfg, "boundary", face_name[d][s]);
            snprintf(vk, sizeof vk, "%s_velocity", face_name[d][s]);
            cfg_vec3(cfg, "boundary", vk, bc.vel[d][s]);
        }
    int nranks;
    MPI_Comm_size(comm, &nranks);

    /* Consistency checks, each naming the key at fault. */
    if (geom != GEOM_3D) {
        if (n[2] != 1) cfg_fail(cfg, "domain", "nz", "must be 1 for a %s grid (got %d)",
                                geom == GEOM_2D ? "2d" : "axisymmetric", n[2]);
        for (int s = 0; s < 2; s++)
            if (bc.type[2][s] != BC_PERIODIC)
                cfg_fail(cfg, "boundary", face_name[2][s], "a 2-D grid has no z faces: leave it periodic");
        L[2] = 1.0;
    }
    for (int d = 0; d < 3; d++) {
        if ((bc.type[d][0] == BC_PERIODIC) != (bc.type[d][1] == BC_PERIODIC))
            cfg_fail(cfg, "boundary", face_name[d][bc.type[d][0] == BC_PERIODIC ? 1 : 0],
                     "periodic on one %c face only: both %s and %s must be periodic, or neither", "xyz"[d],
                     face_name[d][0], face_name[d][1]);
        for (int s = 0; s < 2; s++) {
            if (bc.type[d][s] == BC_AXIS && !(geom == GEOM_AXI && d == 0 && s == 0))
                cfg_fail(cfg, "boundary", face_name[d][s], "'axis' is only valid for x_lo of an axisymmetric grid");
            char vk[32];
            snprintf(vk, sizeof vk, "%s_velocity", face_name[d][s]);
            if (bc.vel[d][s][d] != 0.0)
                cfg_fail(cfg, "boundary", vk, "the normal component (%c) of a wall velocity must be 0",
                         "uvw"[d]);
            if (bc.type[d][s] != BC_NOSLIP && (bc.vel[d][s][0] || bc.vel[d][s][1] || bc.vel[d][s][2]))
                cfg_fail(cfg, "boundary", vk, "a wall velocity needs %s = noslip", face_name[d][s]);
        }
    }
    if (geom == GEOM_AXI) {
        if (bc.type[0][0] != BC_AXIS) cfg_fail(cfg, "boundary", "x_lo", "an axisymmetric grid needs x_lo = axis");
        if (x0[0] != 0.0) cfg_fail(cfg, "domain", "origin", "an axisymmetric grid starts at the axis: x must be 0");
    }
    if (st != STRETCH_UNIFORM && bc.type[0][0] == BC_PERIODIC)
        cfg_fail(cfg, "domain", "x_stretch", "a periodic x direction must be uniform");
    if (geom == GEOM_AXI && (st == STRETCH_TANH_LOW || st == STRETCH_TANH_BOTH))
        cfg_fail(cfg, "domain", "x_stretch", "clustering at the axis is not allowed (use uniform or tanh_high)");
    if (n[0] % nranks != 0)
        cfg_fail(cfg, "domain", "nx", "%d cells do not divide among %d ranks (slabs in x)", n[0], nranks);
    if (n[0] / nranks < 2)
        cfg_fail(cfg, "domain", "nx", "%d cells among %d ranks leaves fewer than 2 per rank", n[0], nranks);
    /* one cell between walls leaves no unknown of the normal velocity */
    for (int d = 1; d < (geom == GEOM_3D ? 3 : 2); d++)
        if (n[d] < 2 && bc.type[d][0] != BC_PERIODIC)
            cfg_fail(cfg, "domain", d == 1 ? "ny" : "nz", "at least 2 cells between walls (got %d)", n[d]);
    /* a grid no machine of this size holds: the fluid keeps at least 8 fields
     * of doubles (2-D: u, v, their two Runge-Kutta stores, p and a work
     * field; 3-D: 11), each of (nx/ranks + 2)(ny + 2)(nz + 2) values a rank */
    const double bytes = 64.0 * (n[0] / nranks + 2) * (n[1] + 2.0) * (geom == GEOM_3D ? n[2] + 2.0 : 1.0);
    if (bytes > physical_memory_bytes()) {
        const int big = n[1] > n[0] && n[1] >= n[2] ? 1 : n[2] > n[0] ? 2 : 0;
        cfg_fail(cfg, "domain", big == 0 ? "nx" : big == 1 ? "ny" : "nz",
                 "a grid of %d x %d x %d cells needs at least %.3g GB a rank, more than the %.3g GB of this machine",
                 n[0], n[1], n[2], bytes / 1e9, physical_memory_bytes() / 1e9);
    }
    if (st == STRETCH_UNIFORM_ARITHMETIC) {
        const int nu = cfg_int(cfg, "domain", "x_uniform_cells");
        const double lu = cfg_double(cfg, "domain", "x_uniform_length");
        if (nu < 1 || nu >= n[0]) cfg_fail(cfg, "domain", "x_uniform_cells", "must be between 1 and nx - 1 (got %d)", nu);
        if (!(lu > 0) || lu >= L[0]) cfg_fail(cfg, "domain", "x_uniform_length", "must be in (0, Lx) (got %g)", lu);
        const int m = n[0] - nu;
        const double h = lu / nu, a = 2 * (L[0] - lu - m * h) / ((double)m * (m + 1));
        if (a < 0)
            cfg_fail(cfg, "domain", "x_uniform_cells",
                     "the stretched part would shrink: %d cells of %g leave %g for %d cells (lower nx or the uniform size)",
                     nu, h, L[0] - lu, m);
        return grid_create_uniform_arithmetic(geom, n, L, x0, &bc, nu, lu, comm);
    }
    return grid_create(geom, n, L, x0, &bc, st, beta, comm);
}

/* Face positions in x: uniform, or a tanh map of the uniform coordinate s in
 * [0,1] that clusters faces near the chosen walls (Vinokur-type). */
static double stretch_map(stretch_t st, double beta, double s)
{
    switch (st) {
    case STRETCH_UNIFORM: return s;
    case STRETCH_TANH_LOW: return 1.0 + tanh(beta * (s - 1.0)) / tanh(beta);
    case STRETCH_TANH_HIGH: return tanh(beta * s) / tanh(beta);
    case STRETCH_TANH_BOTH: return 0.5 * (1.0 + tanh(beta * (s - 0.5)) / tanh(0.5 * beta));
    case STRETCH_UNIFORM_ARITHMETIC: break; /* uniform_arithmetic_face */
    }
    return s;
}

static grid_t *grid_build(geom_t geom, const int n[3], const double L[3], const double x0[3], const bc_t *bc,
                          stretch_t stretch, double beta, int nu, double lu, MPI_Comm comm);

grid_t *grid_create(geom_t geom, const int n[3], const double L[3], const double x0[3], const bc_t *bc,
                    stretch_t stretch, double beta, MPI_Comm comm)
{
    return grid_build(geom, n, L, x0, bc, stretch, beta, 0, 0.0, comm);
}

grid_t *grid_create_uniform_arithmetic(geom_t geom, const int n[3], const double L[3], const double x0[3], const bc_t *bc,
                                       int nu, double lu, MPI_Comm comm)
{
    return grid_build(geom, n, L, x0, bc, STRETCH_UNIFORM_ARITHMETIC, 0.0, nu, lu, comm);
}

/* Face i (0..n) of the uniform_arithmetic spacing, as a fraction of L:
 * nu cells of h = lu/nu, then h + k a (k = 1..m), a = 2(L − lu − m h)/(m(m+1)). */
static double uniform_arithmetic_face(int i, int n, int nu, double lu, double L)
{
    const int m = n - nu;
    const double h = lu / nu, a = 2 * (L - lu - m * h) / ((double)m * (m + 1));
    if (i <= nu) return i * h / L;
    const int k = i - nu;
    return (lu + k * h + a * k * (k + 1) / 2.0) / L;
}

static grid_t *grid_build(geom_t geom, const int n[3], const double L[3], const double x0[3], const bc_t *bc,
                          stretch_t stretch, double beta, int nu, double lu, MPI_Comm comm)
{
    grid_t *g = xcalloc(1, sizeof *g);
    g->geom = geom;
    g->dim = geom == GEOM_3D ? 3 : 2;
    for (int d = 0; d < 3; d++) {
        g->n[d] = n[d];
        g->L[d] = L[d];
        g->x0[d] = x0 ? x0[d] : 0.0;
    }
    if (g->dim == 2) g->n[2] = 1;
    if (bc)
        g->bc = *bc;
    else
        memset(&g->bc, 0, sizeof g->bc); /* BC_PERIODIC == 0 */
    for (int d = 0; d < 3; d++) g->periodic[d] = g->bc.type[d][0] == BC_PERIODIC;
    if (g->dim == 2) g->periodic[2] = 1;
    g->stretch = stretch;
    g->stretch_beta = beta;

    g->comm = comm;
    MPI_Comm_rank(comm, &g->rank);
    MPI_Comm_size(comm, &g->nranks);
    if (g->n[0] % g->nranks) die("nx = %d does not divide among %d ranks", g->n[0], g->nranks);
    g->nxl = g->n[0] / g->nranks;
    g->ix0 = g->rank * g->nxl;
    g->left = g->rank > 0 ? g->rank - 1 : (g->periodic[0] ? g->nranks - 1 : MPI_PROC_NULL);
    g->right = g->rank < g->nranks - 1 ? g->rank + 1 : (g->periodic[0] ? 0 : MPI_PROC_NULL);

    g->gz = g->dim == 3 ? 1 : 0;
    g->sy = g->n[2] + 2 * g->gz;
    g->sx = (long)(g->n[1] + 2) * g->sy;
    g->nalloc = (long)(g->nxl + 2) * g->sx;
    g->ncell_local = (long)g->nxl * g->n[1] * g->n[2];

    g->dy = g->L[1] / g->n[1];
    g->dz = g->L[2] / g->n[2];

    /* Global x arrays, index -1..nx stored at offset +1. */
    int nx = g->n[0];
    double *buf = xcalloc((size_t)4 * (nx + 2), sizeof(double));
    g->gxf = buf + 1;
    g->gxc = buf + (nx + 2) + 1;
    g->gdxf = buf + 2 * (nx + 2) + 1;
    g->gdxc = buf + 3 * (nx + 2) + 1;
    g->stretch_uniform_cells = nu;
    g->stretch_uniform_length = lu;
    for (int i = -1; i < nx; i++)
        g->gxf[i] = g->x0[0] + g->L[0] * (stretch == STRETCH_UNIFORM_ARITHMETIC
                                              ? uniform_arithmetic_face(i + 1, nx, nu, lu, g->L[0])
                                              : stretch_map(stretch, beta, (double)(i + 1) / nx));
    g->gxf[-1] = g->x0[0];
    g->gxf[nx - 1] = g->x0[0] + g->L[0];
    /* Ghost face beyond the high boundary: mirror of the last cell. */
    g->gxf[nx] = g->gxf[nx - 1] + (g->gxf[nx - 1] - g->gxf[nx - 2]);
    for (int i = 0; i <= nx; i++) g->gdxf[i] = g->gxf[i] - g->gxf[i - 1];
    g->gdxf[-1] = g->gdxf[0]; /* ghost cell mirrors the first cell (periodic or wall) */
    if (g->periodic[0]) {
        g->gdxf[-1] = g->gdxf[nx - 1];
        g->gdxf[nx] = g->gdxf[0];
    }
    for (int i = 0; i < nx; i++) g->gxc[i] = 0.5 * (g->gxf[i] + g->gxf[i - 1]);
    g->gxc[-1] = g->gxf[-1] - 0.5 * g->gdxf[-1];
    g->gxc[nx] = g->gxf[nx - 1] + 0.5 * g->gdxf[nx];
    for (int i = -1; i < nx; i++) g->gdxc[i] = g->gxc[i + 1] - g->gxc[i];
    g->gdxc[nx] = g->gdxc[nx - 1];

    /* Local views. */
    double *lb = xcalloc((size_t)4 * (g->nxl + 2), sizeof(double));
    g->xf = lb + 1;
    g->xc = lb + (g->nxl + 2) + 1;
    g->dxf = lb + 2 * (g->nxl + 2) + 1;
    g->dxc = lb + 3 * (g->nxl + 2) + 1;
    for (int i = -1; i <= g->nxl; i++) {
        int ig = i + g->ix0;
        g->xf[i] = g->gxf[ig];
        g->xc[i] = g->gxc[ig];
        g->dxf[i] = g->gdxf[ig];
        g->dxc[i] = g->gdxc[ig];
    }
    return g;
}

void grid_free(grid_t *g)
{
    if (!g) return;
    free(g->gxf - 1);
    free(g->xf - 1);
    free(g);
}

double *field_alloc(const grid_t *g) { return xcalloc((size_t)g->nalloc, sizeof(double)); }
void field_copy(const grid_t *g, double *dst, const double *src) { memcpy(dst, src, (size_t)g->nalloc * sizeof(double)); }
void field_zero(const grid_t *g, double *f) { memset(f, 0, (size_t)g->nalloc * sizeof(double)); }

void grid_halo_yz(const grid_t *g, double *f) { grid_halo_yz_planes(g, f, -1, g->nxl); }

void grid_halo_yz_planes(const grid_t *g, double *f, int ilo, int ihi)
{
    int ny = g->n[1], nz = g->n[2];
    for (int i = ilo; i <= ihi; i++) {
        if (g->dim == 3 && g->periodic[2])
            for (int j = 0; j < ny; j++) {
                f[G_IDX(g, i, j, -1)] = f[G_IDX(g, i, j, nz - 1)];
                f[G_IDX(g, i, j, nz)] = f[G_IDX(g, i, j, 0)];
            }
        if (g->periodic[1]) {
            double *dst_lo = f + G_IDX(g, i, -1, -g->gz), *dst_hi = f + G_IDX(g, i, ny, -g->gz);
            const double *src_lo = f + G_IDX(g, i, ny - 1, -g->gz), *src_hi = f + G_IDX(g, i, 0, -g->gz);
            memcpy(dst_lo, src_lo, (size_t)g->sy * sizeof(double));
            memcpy(dst_hi, src_hi, (size_t)g->sy * sizeof(double));
        }
    }
}

void grid_halo_x(const grid_t *g, double *f)
{
    /* Planes i = 0 and i = nxl-1 (with their y/z ghosts) go to the neighbours'
     * ghost planes i = nxl and i = -1. */
    long np = g->sx;
    double *first = f + G_IDX(g, 0, -1, -g->gz), *last = f + G_IDX(g, g->nxl - 1, -1, -g->gz);
    double *ghost_lo = f + G_IDX(g, -1, -1, -g->gz), *ghost_hi = f + G_IDX(g, g->nxl, -1, -g->gz);
    if (g->nranks == 1) {
        if (g->periodic[0]) {
            memcpy(ghost_lo, last, (size_t)np * sizeof(double));
            memcpy(ghost_hi, first, (size_t)np * sizeof(double));
        }
        return;
    }
    MPI_Sendrecv(last, (int)np, MPI_DOUBLE, g->right, 11, ghost_lo, (int)np, MPI_DOUBLE, g->left, 11, g->comm,
                 MPI_STATUS_IGNORE);
    MPI_Sendrecv(first, (int)np, MPI_DOUBLE, g->left, 12, ghost_hi, (int)np, MPI_DOUBLE, g->right, 12, g->comm,
                 MPI_STATUS_IGNORE);
}

void grid_halo(const grid_t *g, double *f)
{
    grid_halo_yz(g, f);
    grid_halo_x(g, f);
}

double grid_sum(const grid_t *g, double v)
{
    double r;
    MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, MPI_SUM, g->comm);
    return r;
}

double grid_max(const grid_t *g, double v)
{
    double r;
    MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, MPI_MAX, g->comm);
    return r;
}

double grid_min(const grid_t *g, double v)
{
    double r;
    MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, MPI_MIN, g->comm);
    return r;
}

double grid_cell_volume(const grid_t *g, int i)
{
    if (g->geom == GEOM_AXI) return g->xc[i] * g->dxf[i] * g->dy;
    return g->dxf[i] * g->dy * (g->dim == 3 ? g->dz : 1.0);
}

double grid_min_spacing(const grid_t *g)
{
    double h = fmin(g->dy, g->dim == 3 ? g->dz : g->dy);
    for (int i = 0; i < g->n[0]; i++) h = fmin(h, g->gdxf[i]);
    return h;
}
