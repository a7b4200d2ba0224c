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

/* Each kernel below computes, on the unknowns of one component,
 *     out = ca · ∇·(u⊗u) + cv · L u,
 * the explicit right-hand side of a Runge–Kutta stage in one sweep (the
 * viscous part is the stencil of viscous.c, fused here for speed; the tests
 * check that both agree).  The innermost loop runs along a contiguous line
 * (k in 3-D, j in 2-D: FLUID_FOR_LINES) and is written once for 3-D and once
 * for 2-D (is3d is a constant after inlining) so that it vectorises. */
#define KERNEL static inline __attribute__((always_inline)) void

/* per-i coefficients of a line */
typedef struct {
    double rv, wa, wb, afw, af0, afe; /* advection metric */
    double cw, ce, cd, cy, cz, xw;    /* cv · viscous stencil, wall term */
} coef_t;

/* u-momentum: control volume a_f,i Δx_c,i × Δy × Δz around face i. */
KERNEL u_line(const double *restrict u, const double *restrict v, const double *restrict w, double *restrict out,
              long c0, long len, long sx, long sy, double ca, double rdy, double rdz, const coef_t *k, int is3d)
{
    for (long c = c0; c < c0 + len; c++) {
        double uc = u[c];
        double Fe = k->af0 * uc + k->afe * u[c + sx], Fw = k->afw * u[c - sx] + k->af0 * uc;
        double X = (Fe * (uc + u[c + sx]) - Fw * (u[c - sx] + uc)) * 0.5 * k->rv;
        double Vn = k->wa * v[c] + k->wb * v[c + sx], Vs = k->wa * v[c - sy] + k->wb * v[c + sx - sy];
        double Y = (Vn * (uc + u[c + sy]) - Vs * (u[c - sy] + uc)) * 0.5 * rdy;
        double V = k->cw * u[c - sx] + k->ce * u[c + sx] - k->cd * uc + k->cy * (u[c + sy] + u[c - sy]);
        double Z = 0.0;
        if (is3d) {
            double Wt = k->wa * w[c] + k->wb * w[c + sx], Wb = k->wa * w[c - 1] + k->wb * w[c + sx - 1];
            Z = (Wt * (uc + u[c + 1]) - Wb * (u[c - 1] + uc)) * 0.5 * rdz;
            V += k->cz * (u[c + 1] + u[c - 1]);
        }
        out[c] = ca * (X + Y + Z) + V;
    }
}

/* v-momentum: control volume a_c,i Δx_f,i × Δy × Δz around y-face j. */
KERNEL v_line(const double *restrict u, const double *restrict v, const double *restrict w, double *restrict out,
              long c0, long len, long sx, long sy, double ca, double rdy, double rdz, const coef_t *k, int is3d)
{
    for (long c = c0; c < c0 + len; c++) {
        double vc = v[c];
        double Ue = k->af0 * (u[c] + u[c + sy]), Uw = k->afw * (u[c - sx] + u[c - sx + sy]);
        double X = (Ue * (vc + v[c + sx]) - Uw * (v[c - sx] + vc)) * k->rv;
        double Vn = vc + v[c + sy], Vs = v[c - sy] + vc;
        double Y = (Vn * Vn - Vs * Vs) * 0.25 * rdy;
        double V = k->cw * v[c - sx] + k->ce * v[c + sx] - k->cd * vc + k->cy * (v[c + sy] + v[c - sy]) + k->xw;
        double Z = 0.0;
        if (is3d) {
            double Wt = w[c] + w[c + sy], Wb = w[c - 1] + w[c - 1 + sy];
            Z = (Wt * (vc + v[c + 1]) - Wb * (v[c - 1] + vc)) * 0.25 * rdz;
            V += k->cz * (v[c + 1] + v[c - 1]);
        }
        out[c] = ca * (X + Y + Z) + V;
    }
}

/* w-momentum (3-D only): control volume Δx_f,i × Δy × Δz around z-face k. */
KERNEL w_line(const double *restrict u, const double *restrict v, const double *restrict w, double *restrict out,
              long c0, long len, long sx, long sy, double ca, double rdy, double rdz, const coef_t *k)
{
    for (long c = c0; c < c0 + len; c++) {
        double wc = w[c];
        double Ue = u[c] + u[c + 1], Uw = u[c - sx] + u[c - sx + 1];
        double X = (Ue * (wc + w[c + sx]) - Uw * (w[c - sx] + wc)) * k->rv;
        double Vn = v[c] + v[c + 1], Vs = v[c - sy] + v[c - sy + 1];
        double Y = (Vn * (wc + w[c + sy]) - Vs * (w[c - sy] + wc)) * 0.25 * rdy;
        double Wt = wc + w[c + 1], Wb = w[c - 1] + wc;
        double Z = (Wt * Wt - Wb * Wb) * 0.25 * rdz;
        double V = k->cw * w[c - sx] + k->ce * w[c + sx] - k->cd * wc + k->cy * (w[c + sy] + w[c - sy]) +
                   k->cz * (w[c + 1] + w[c - 1]) + k->xw;
        out[c] = ca * (X + Y + Z) + V;
    }
}

/* The per-i coefficients of component c at local x index i. */
static void line_coefs(const fluid_t *f, int c, int i, double cv, coef_t *k)
{
    const grid_t *g = f->g;
    const fluid_priv_t *q = fluid_priv(f);
    const double *af = q->af, *ac = q->ac;
    const poisson_t *L = q->pv[c];
    int ig = i + g->ix0;
    if (c == 0) {
        k->rv = 1.0 / (af[i] * g->dxc[i]);
        /* v, w at the u-cell's y/z faces: the volume-weighted mean of the two
         * pressure cells (weights a_c Δx_f, summing to 2 a_f Δx_c up to O(h³)) */
        k->wa = 0.5 * ac[i] * g->dxf[i] * k->rv;
        k->wb = 0.5 * ac[i + 1] * g->dxf[i + 1] * k->rv;
        k->afw = 0.5 * af[i - 1];
        k->af0 = 0.5 * af[i];
        k->afe = 0.5 * af[i + 1];
    } else {
        /* v, w: radial fluxes a_f u at the cell's x faces, all products ¼ */
        k->rv = 0.25 / (ac[i] * g->dxf[i]);
        k->af0 = af[i];
        k->afw = af[i - 1];
        k->wa = k->wb = k->afe = 0.0;
    }
    k->cy = cv * L->cy;
    k->cz = cv * L->cz;
    k->cw = cv * L->cw[ig];
    k->ce = cv * L->ce[ig];
    k->cd = cv * L->cd[ig] + 2.0 * (k->cy + k->cz);
    k->xw = cv * ((ig == 0 ? q->xwall[c][0] : 0.0) + (ig == g->n[0] - 1 ? q->xwall[c][1] : 0.0));
}

/* out[c] = ca · ∇·(u⊗u)_c + cv · L u_c on the unknowns (ghosts of u must be
 * valid; cv includes ν). */
void fluid_rhs(const fluid_t *f, double ca, double cv, double *const out[3])
{
    const grid_t *g = f->g;
    const double *u = f->u[0], *v = f->u[1], *w = g->dim == 3 ? f->u[2] : NULL;
    long sx = g->sx, sy = g->sy;
    double rdy = 1.0 / g->dy, rdz = g->dim == 3 ? 1.0 / g->dz : 0.0;
    int is3d = g->dim == 3;
    for (int c = 0; c < fluid_ncomp(g); c++) {
        int iend = fluid_iend(g, c), nj = fluid_nu(g, c, 1), nk = fluid_nu(g, c, 2);
        double *o = out[c];
        for (int i = 0; i < iend; i++) {
            coef_t k;
            line_coefs(f, c, i, cv, &k);
            FLUID_FOR_LINES(g, i, nj, nk, c0, len)
            {
                if (c == 0) {
                    if (is3d) u_line(u, v, w, o, c0, len, sx, sy, ca, rdy, rdz, &k, 1);
                    else u_line(u, v, w, o, c0, len, sx, sy, ca, rdy, rdz, &k, 0);
                } else if (c == 1) {
                    if (is3d) v_line(u, v, w, o, c0, len, sx, sy, ca, rdy, rdz, &k, 1);
                    else v_line(u, v, w, o, c0, len, sx, sy, ca, rdy, rdz, &k, 0);
                } else
                    w_line(u, v, w, o, c0, len, sx, sy, ca, rdy, rdz, &k);
            }
        }
    }
}

void fluid_advection(const fluid_t *f, double *const out[3]) { fluid_rhs(f, 1.0, 0.0, out); }
