/* advection.c — the advection term ∇·(u⊗u) in the energy-conserving
 * divergence form on the MAC grid (Morinishi et al. 1998; Verstappen &
 * Veldman 2003).
 *
 * For each momentum control volume (the cell centred on the unknown: for u_i
 * from x_c,i to x_c,i+1, for v and w the pressure cell shifted by half a cell
 * along their own direction) the term is
 *     N = (1/V) Σ_faces F_f ū_f,
 * with F_f the convecting volume flux through the face and ū_f the ARITHMETIC
 * MEAN of the two unknowns the face separates.  The fluxes are the half sums
 * of the mass fluxes of the two pressure cells the control volume overlaps,
 * so Σ_f F_f = ½(V_a D_a + V_b D_b) = 0 whenever the pressure cells are
 * divergence-free.  Then Σ V u·N = Σ_f F_f ½(u_a u_b − u_b u_a) + Σ ½u²·Σ F = 0:
 * the term neither creates nor destroys discrete kinetic energy
 * E = ½ Σ V u² (V: fluid_cell_volume), on uniform and stretched grids, with
 * walls (zero normal flux) and periodic faces, and in axisymmetric geometry,
 * where areas and volumes carry the factor r (fluxes r_f u, volumes r dr dz).
 * In the axisymmetric (r, z) equations without swirl the divergence form
 * (1/r)∂r(r u_r u_r) + ∂z(u_z u_r) has no extra metric term: the hoop term
 * −u_θ²/r vanishes.  On a stretched x grid the mean ū_f is first order
 * locally but the scheme stays second order globally (Verstappen & Veldman).
 */
#include "fluid_internal.h"

/* u-momentum: control volume a_f,i Δx_c,i × Δy × Δz around face i. */
static void advect_u(const fluid_t *f, double scale, double *out)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    const double *af = q->af, *ac = q->ac;
    long sx = g->sx, sy = g->sy;
    int iend = fluid_iend(g, 0), nj = fluid_nu(g, 0, 1), nk = fluid_nu(g, 0, 2);
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    for (int i = 0; i < iend; i++) {
        double rv = 1.0 / (af[i] * g->dxc[i]);
        /* v, w at the u-cell's y/z faces: the volume-weighted mean of the two
         * pressure cells (weights a_c Δx_f, summing to 2 a_f Δx_c up to O(h³)) */
        double wa = 0.5 * ac[i] * g->dxf[i] * rv, wb = 0.5 * ac[i + 1] * g->dxf[i + 1] * rv;
        double afw = 0.5 * af[i - 1], af0 = 0.5 * af[i], afe = 0.5 * af[i + 1];
        for (int j = 0; j < nj; j++) {
            long c0 = G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) {
                long c = c0 + k;
                double uc = u[c];
                double Fe = af0 * uc + afe * u[c + sx], Fw = afw * u[c - sx] + af0 * uc;
                double X = (Fe * (uc + u[c + sx]) - Fw * (u[c - sx] + uc)) * 0.5 * rv;
                double Vn = wa * v[c] + wb * v[c + sx], Vs = wa * v[c - sy] + wb * v[c + sx - sy];
                double Y = (Vn * (uc + u[c + sy]) - Vs * (u[c - sy] + uc)) * 0.5 * rdy;
                double Z = 0.0;
                if (w) {
                    double Wt = wa * w[c] + wb * w[c + sx], Wb = wa * w[c - 1] + wb * w[c + sx - 1];
                    Z = (Wt * (uc + u[c + 1]) - Wb * (u[c - 1] + uc)) * 0.5 * rdz;
                }
                out[c] += scale * (X + Y + Z);
            }
        }
    }
}

/* v-momentum: control volume a_c,i Δx_f,i × Δy × Δz around y-face j. */
static void advect_v(const fluid_t *f, double scale, double *out)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    const double *af = q->af, *ac = q->ac;
    long sx = g->sx, sy = g->sy;
    int iend = fluid_iend(g, 1), nj = fluid_nu(g, 1, 1), nk = fluid_nu(g, 1, 2);
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    for (int i = 0; i < iend; i++) {
        double rv = 0.25 / (ac[i] * g->dxf[i]);
        double ae = af[i], aw = af[i - 1];
        for (int j = 0; j < nj; j++) {
            long c0 = G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) {
                long c = c0 + k;
                double vc = v[c];
                double Ue = ae * (u[c] + u[c + sy]), Uw = aw * (u[c - sx] + u[c - sx + sy]);
                double X = (Ue * (vc + v[c + sx]) - Uw * (v[c - sx] + vc)) * rv;
                double Vn = vc + v[c + sy], Vs = v[c - sy] + vc;
                double Y = (Vn * Vn - Vs * Vs) * 0.25 * rdy;
                double Z = 0.0;
                if (w) {
                    double Wt = w[c] + w[c + sy], Wb = w[c - 1] + w[c - 1 + sy];
                    Z = (Wt * (vc + v[c + 1]) - Wb * (v[c - 1] + vc)) * 0.25 * rdz;
                }
                out[c] += scale * (X + Y + Z);
            }
        }
    }
}

/* w-momentum (3-D only): control volume Δx_f,i × Δy × Δz around z-face k. */
static void advect_w(const fluid_t *f, double scale, double *out)
{
    const grid_t *g = f->g;
    const double *u = f->u[0], *v = f->u[1], *w = f->u[2];
    long sx = g->sx, sy = g->sy;
    int iend = fluid_iend(g, 2), nj = fluid_nu(g, 2, 1), nk = fluid_nu(g, 2, 2);
    double rdy = 1.0 / g->dy, rdz = 1.0 / g->dz;
    for (int i = 0; i < iend; i++) {
        double rv = 0.25 / g->dxf[i];
        for (int j = 0; j < nj; j++) {
            long c0 = G_IDX(g, i, j, 0);
            for (int k = 0; k < nk; k++) {
                long c = c0 + k;
                double wc = w[c];
                double Ue = u[c] + u[c + 1], Uw = u[c - sx] + u[c - sx + 1];
                double X = (Ue * (wc + w[c + sx]) - Uw * (w[c - sx] + wc)) * rv;
                double Vn = v[c] + v[c + 1], Vs = v[c - sy] + v[c - sy + 1];
                double Y = (Vn * (wc + w[c + sy]) - Vs * (w[c - sy] + wc)) * 0.25 * rdy;
                double Wt = wc + w[c + 1], Wb = w[c - 1] + wc;
                double Z = (Wt * Wt - Wb * Wb) * 0.25 * rdz;
                out[c] += scale * (X + Y + Z);
            }
        }
    }
}

/* out[c] += scale · ∇·(u⊗u)_c on the unknowns (ghosts of u must be valid). */
void fluid_advection_add(const fluid_t *f, double scale, double *const out[3])
{
    advect_u(f, scale, out[0]);
    advect_v(f, scale, out[1]);
    if (f->g->dim == 3) advect_w(f, scale, out[2]);
}

void fluid_advection(const fluid_t *f, double *const out[3])
{
    const grid_t *g = f->g;
    for (int c = 0; c < fluid_ncomp(g); c++) field_zero(g, out[c]);
    fluid_advection_add(f, 1.0, out);
}
