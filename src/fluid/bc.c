/* bc.c — ghost values of the velocity: periodic images and halos, no-slip
 * walls with a wall velocity, free-slip walls, the axis of an axisymmetric
 * grid.
 *
 * A component normal to a face has its boundary value ON the face (index −1
 * at the low side, n−1 at the high side, grid.h): it is 0 at every wall and
 * on the axis (no penetration; u_r = 0 on the axis).  A tangential component
 * is cell-centred normal to the face; its ghost mirrors the first interior
 * value so that the face value (the mean of the two) is the wall's:
 *   no-slip:            ghost = 2 U_wall − interior   (second order, the
 *                       value the Laplacian of poisson.c assumes: its
 *                       homogeneous part ghost = −interior plus 2 U_wall)
 *   free-slip and axis: ghost = interior               (zero normal gradient;
 *                       on the axis u_z is even in r)
 * These stored ghosts are the same with [fluid] wall_ghost = quadratic: the
 * quadratic ghost enters the viscous operator only, as a wall term
 * (viscous.c), so the face value read by everyone else is still U_wall.
 */
#include <string.h>

#include "fluid_internal.h"

/* ghost value of a tangential component at a face of type t with wall velocity U */
static inline double tangential_ghost(bc_type_t t, double U, double interior)
{
    return t == BC_NOSLIP ? 2.0 * U - interior : interior;
}

/* Ghost planes in x of nf fields at once (one message each way instead of
 * nf): the planes i = 0 and nxl−1 (with their y/z ghosts) go to the
 * neighbours' i = nxl and −1, as grid_halo_x does for one field. */
static void halo_x_fields(const fluid_t *f, double *const *u, int nf)
{
    const grid_t *g = f->g;
    if (g->nranks == 1 || nf == 1) {
        for (int c = 0; c < nf; c++) grid_halo_x(g, u[c]);
        return;
    }
    fluid_priv_t *q = fluid_priv(f);
    long np = g->sx, off_first = G_IDX(g, 0, -1, -g->gz), off_last = G_IDX(g, g->nxl - 1, -1, -g->gz);
    long off_lo = G_IDX(g, -1, -1, -g->gz), off_hi = G_IDX(g, g->nxl, -1, -g->gz);
    double *sb = q->halo_buf, *rb = q->halo_buf + nf * np;
    size_t bytes = (size_t)np * sizeof(double);
    for (int c = 0; c < nf; c++) memcpy(sb + c * np, u[c] + off_last, bytes);
    MPI_Sendrecv(sb, (int)(nf * np), MPI_DOUBLE, g->right, 21, rb, (int)(nf * np), MPI_DOUBLE, g->left, 21, g->comm,
                 MPI_STATUS_IGNORE);
    if (g->left != MPI_PROC_NULL)
        for (int c = 0; c < nf; c++) memcpy(u[c] + off_lo, rb + c * np, bytes);
    for (int c = 0; c < nf; c++) memcpy(sb + c * np, u[c] + off_first, bytes);
    MPI_Sendrecv(sb, (int)(nf * np), MPI_DOUBLE, g->left, 22, rb, (int)(nf * np), MPI_DOUBLE, g->right, 22, g->comm,
                 MPI_STATUS_IGNORE);
    if (g->right != MPI_PROC_NULL)
        for (int c = 0; c < nf; c++) memcpy(u[c] + off_hi, rb + c * np, bytes);
}

/* x-face ghosts of component c (after the halo exchange): the ghost planes
 * from planes 0 and nxl−1, u on the boundary face. */
static void fill_x_face_ghosts(const fluid_t *f, int c, double *u)
{
    const grid_t *g = f->g;
    const bc_t *bc = &g->bc;
    int nxl = g->nxl, ny = g->n[1], nz = g->n[2], gz = g->gz;

    /* only the ranks that own them */
    if (!g->periodic[0]) {
        for (int s = 0; s < 2; s++) {
            if ((s == 0 && g->left != MPI_PROC_NULL) || (s == 1 && g->right != MPI_PROC_NULL)) continue;
            bc_type_t t = bc->type[0][s];
            double U = bc->vel[0][s][c];
            int ib = s == 0 ? -1 : nxl - 1; /* boundary face of u, or the ghost cell of v, w */
            for (int j = -1; j <= ny; j++)
                for (int k = -gz; k < nz + gz; k++) {
                    if (c == 0) {
                        u[G_IDX(g, ib, j, k)] = 0.0;
                        if (s == 1) u[G_IDX(g, nxl, j, k)] = 0.0; /* beyond the wall: unused */
                    } else {
                        int ig = s == 0 ? -1 : nxl, ii = s == 0 ? 0 : nxl - 1;
                        u[G_IDX(g, ig, j, k)] = tangential_ghost(t, U, u[G_IDX(g, ii, j, k)]);
                    }
                }
        }
    }
}

/* y- and z-face ghosts of component c on the x planes ilo..ihi: each plane's
 * from the same plane, y before z (the z ghosts of the y ghost rows last). */
static void fill_yz_face_ghosts(const fluid_t *f, int c, double *u, int ilo, int ihi)
{
    const grid_t *g = f->g;
    const bc_t *bc = &g->bc;
    int ny = g->n[1], nz = g->n[2], gz = g->gz;
    /* y faces (every rank, ghost planes in x included) */
    if (!g->periodic[1]) {
        for (int i = ilo; i <= ihi; i++)
            for (int k = -gz; k < nz + gz; k++) {
                if (c == 1) {
                    u[G_IDX(g, i, -1, k)] = 0.0;
                    u[G_IDX(g, i, ny - 1, k)] = 0.0;
                    u[G_IDX(g, i, ny, k)] = 0.0;
                } else {
                    u[G_IDX(g, i, -1, k)] = tangential_ghost(bc->type[1][0], bc->vel[1][0][c], u[G_IDX(g, i, 0, k)]);
                    u[G_IDX(g, i, ny, k)] =
                        tangential_ghost(bc->type[1][1], bc->vel[1][1][c], u[G_IDX(g, i, ny - 1, k)]);
                }
            }
    }
    /* z faces */
    if (g->dim == 3 && !g->periodic[2]) {
        for (int i = ilo; i <= ihi; i++)
            for (int j = -1; j <= ny; j++) {
                if (c == 2) {
                    u[G_IDX(g, i, j, -1)] = 0.0;
                    u[G_IDX(g, i, j, nz - 1)] = 0.0;
                    u[G_IDX(g, i, j, nz)] = 0.0;
                } else {
                    u[G_IDX(g, i, j, -1)] = tangential_ghost(bc->type[2][0], bc->vel[2][0][c], u[G_IDX(g, i, j, 0)]);
                    u[G_IDX(g, i, j, nz)] =
                        tangential_ghost(bc->type[2][1], bc->vel[2][1][c], u[G_IDX(g, i, j, nz - 1)]);
                }
            }
    }
}

void fluid_apply_bc(fluid_t *f)
{
    const grid_t *g = f->g;
    int nc = fluid_ncomp(g);
    for (int c = 0; c < nc; c++) grid_halo_yz(g, f->u[c]);
    halo_x_fields(f, f->u, nc);
    for (int c = 0; c < nc; c++) {
        fill_x_face_ghosts(f, c, f->u[c]);
        fill_yz_face_ghosts(f, c, f->u[c], -1, g->nxl);
    }
}

/* fluid_apply_bc in two parts (for u^k corrected plane by plane, step.c): the
 * ghosts the edge planes 0 and nxl−1 determine — their own, the x halo and
 * the ghost planes —, then those of an inner plane i, which only plane i
 * determines.  The same operations as fluid_apply_bc on the same values, so
 * every ghost ends with the value fluid_apply_bc gives. */
void fluid_apply_bc_edges(fluid_t *f)
{
    const grid_t *g = f->g;
    int nc = fluid_ncomp(g);
    for (int c = 0; c < nc; c++) {
        grid_halo_yz_planes(g, f->u[c], -1, 0);
        grid_halo_yz_planes(g, f->u[c], g->nxl - 1, g->nxl);
    }
    halo_x_fields(f, f->u, nc);
    for (int c = 0; c < nc; c++) {
        fill_x_face_ghosts(f, c, f->u[c]);
        fill_yz_face_ghosts(f, c, f->u[c], -1, 0);
        fill_yz_face_ghosts(f, c, f->u[c], g->nxl - 1, g->nxl);
    }
}

void fluid_apply_bc_plane_of(const fluid_t *f, double *const u[3], int i)
{
    for (int c = 0; c < fluid_ncomp(f->g); c++) {
        grid_halo_yz_planes(f->g, u[c], i, i);
        fill_yz_face_ghosts(f, c, u[c], i, i);
    }
}

void fluid_apply_bc_plane(fluid_t *f, int i) { fluid_apply_bc_plane_of(f, f->u, i); }

/* The pressure (and its correction φ) has zero normal gradient at walls and
 * on the axis: the ghosts of the VAR_P operator. */
void fluid_fill_pressure_ghosts(const fluid_t *f, double *p) { poisson_fill_ghosts(fluid_priv(f)->pp, p); }
