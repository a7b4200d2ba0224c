/* test_porenet_coupled.c — the pore network coupled with the DEM (DEM–PFV,
 * thesis fig. 4.3), on the coarse immersed deposition
 * (cases/porenet_deposition/coarse.ini, catalano_pfv.md §2.3):
 *  - mass balance of the moving skeleton: the net flux out of the domain
 *    equals −Σ dV_i/dt (the pores' volume rates) to round-off, the direct
 *    solver being exact;
 *  - momentum: Σ (fluid force on spheres) + Σ (force on the faces) = 0;
 *  - the settling suspension: once the particles have relaxed to their
 *    hindered settling velocity, the excess pore pressure carries the buoyant
 *    weight of the grains, ∇H = −(ρ_s/ρ_f − 1)(1 − n) ẑ (thesis 4.32–4.34).
 * RANKS: 1 2
 */
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "dem.h"
#include "modules.h"
#include "porenet.h"
#include "testutil.h"
#include "util.h"

/* −dH/dz in the central half of the column, away from the layers at the
 * bottom (grains landing) and the top (the drained face): least-squares slope
 * of the pore pressures against height, H = p/(ρ_f |g|). */
static double central_gradient(const pn_model_t *m, const double g[3])
{
    const double H = m->dom.hi[2] - m->dom.lo[2];
    double sz = 0, sp = 0, szz = 0, szp = 0, cnt = 0;
    for (int i = 0; i < m->net.npore; i++) {
        const double z = m->net.P[3 * i + 2] - m->dom.lo[2];
        if (z < 0.25 * H || z > 0.75 * H) continue;
        sz += z, sp += m->p[i], szz += z * z, szp += z * m->p[i], cnt++;
    }
    const double slope = (cnt * szp - sz * sp) / (cnt * szz - sz * sz);
    return -slope / (m->rho_f * fabs(g[2]));
}

/* 1 − n of the whole box (the suspension fills it) */
static double solid_fraction(const pn_model_t *m)
{
    double vs = 0;
    for (int i = 0; i < m->n; i++) vs += 4.0 / 3.0 * M_PI * pow(m->rid[i], 3);
    return vs / m->net.box_volume;
}

static void test_deposition(void **state)
{
    (void)state;
    cfg_t *cfg = cfg_load(getenv("PN_CASE") ? getenv("PN_CASE") : "cases/porenet_deposition/coarse.ini", 0, NULL);
    dem_t *d = dem_create_from_config(cfg, MPI_COMM_WORLD);
    pn_model_t m;
    pn_model_from_config(cfg, &m);
    double g[3];
    cfg_vec3(cfg, "dem", "gravity", g);
    const double rho_f = m.rho_f, rho_s = cfg_double(cfg, "particles", "density");
    const double t_end = cfg_double(cfg, "time", "t_end");

    assert_int_equal(dem_advance(d, dem_time(d)), DEM_OK); /* lists, forces and step of the initial state */
    assert_int_equal(pn_model_couple_dem(&m, d, g, 0.0), 0);
    /* the coupled step (driver rule: one DEM step within the viscous limit) */
    const double dt = pn_coupled_step(&m, d);
    const double dt_mv = pn_coupled_dt(&m, d) / m.dt_factor;
    int nstep = (int)ceil(t_end / dt);
    double mass_err = 0, mom_err = 0, gsum = 0;
    int gcount = 0;
    for (int s = 0; s < nstep; s++) {
        assert_int_equal(dem_advance(d, dem_time(d) + dt), DEM_OK);
        assert_int_equal(pn_model_couple_dem(&m, d, g, dt), 0);
        /* mass: Σ_faces q_in = Σ_i dV_i/dt (incompressible fluid, rigid grains) */
        double q[6], qin = 0, dv = 0, dvs = 0;
        pn_face_fluxes(&m.dom, &m.net, m.p, q);
        for (int f = 0; f < 6; f++) qin += q[f];
        for (int i = 0; i < m.net.npore; i++)
            if (m.net.dirichlet[i] < 0) dv += m.dvdt[i], dvs += fabs(m.dvdt[i]);
        if (dvs > 0) mass_err = fmax(mass_err, fabs(qin - dv) / dvs);
        /* momentum of the fluid: forces on spheres and faces cancel */
        double F[6][3], fs[3] = {0, 0, 0}, fa = 0;
        pn_face_forces(&m.dom, &m.net, m.p, F);
        for (int i = 0; i < m.n; i++)
            for (int a = 0; a < 3; a++) fs[a] += m.f[3 * i + a], fa += fabs(m.f[3 * i + a]);
        for (int f = 0; f < 6; f++)
            for (int a = 0; a < 3; a++) fs[a] += F[f][a];
        for (int a = 0; a < 3; a++) mom_err = fmax(mom_err, fabs(fs[a]) / fa);
        /* the mean over the last third of the run: the suspension has relaxed
         * (velocity relaxation time ≈ 1.2 ms measured, t_end = 30 ms) */
        if (s >= 2 * nstep / 3) gsum += central_gradient(&m, g), gcount++;
        if (getenv("PN_TRACE") && s % 20 == 0 && mpi_rank() == 0) {
            dem_diag_t dg;
            dem_diag_light(d, &dg);
            printf("# t %.4g  -dH/dz %.4f  vz %.4g  contacts %ld\n", dem_time(d), central_gradient(&m, g),
                   dg.momentum[2], dg.n_contacts);
        }
    }
    const double grad_H = gsum / gcount, phi = solid_fraction(&m);
    const double expect = (rho_s / rho_f - 1) * phi;
    dem_diag_t dg;
    dem_diag(d, &dg);
    if (mpi_rank() == 0)
        printf("# deposition: %d spheres, %d pores, dt %.3g s (viscous limit %.3g s, DEM %.3g s), %d steps, "
               "%ld triangulations; mass %.2e, momentum %.2e; -dH/dz = %.4f, (rho_s/rho_f - 1)(1 - n) = %.4f "
               "(ratio %.4f), contacts %ld\n",
               m.n, m.net.npore, dt, dt_mv, dem_dt(d), nstep, m.n_retri, mass_err, mom_err, grad_H, expect,
               grad_H / expect, dg.n_contacts);
    /* direct solver: the mass balance of every pore holds to round-off, so
     * does its sum (relative to Σ|dV/dt|) */
    assert_true(mass_err < 1e-9);
    /* the forces are built face by face with opposite signs on both sides */
    assert_true(mom_err < 1e-9);
    /* 3 %: the central band's solid fraction differs from the box's by the
     * randomness of ~200 grains and the wall layering; the measured gradient
     * fluctuates by ±1 % from step to step as the grains land (20 contacts at
     * the end) and the network is re-triangulated */
    assert_true(fabs(grad_H / expect - 1) < 0.03);
    pn_model_free(&m);
    dem_free(d);
    cfg_free(cfg);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_deposition),
    };
    TEST_MPI_RUN("porenet_coupled", tests);
}
