/* test_ibm_fused.c — the immersed-boundary forcing inside the fluid's
 * predictor sweep (the plane hook, docs/theory.md §1 step 1.1b), with the
 * divergence and the deferred correction the fluid then fuses too, makes
 * the same operations on the same values as the forcing after the sweep:
 * after several steps u, v, w, p and every sphere's position, velocity,
 * force and torque must be bit-identical to the run with
 * fluid_params_t.unfused (every pass on its own).  A plane forced twice,
 * skipped, forced before the sweep wrote it, or a correction deferred past
 * a reader would differ at O(Δt) — the sabotages tried (the last plane of
 * the sweep not forced; the stage-end hook's promise ignored for a free
 * sphere) changed thousands of values.
 *
 * Scenes (3-D, explicit viscous term; x and z periodic, no-slip walls in y,
 * the box 24 × 20 × 16 cells, D/Δx = 5):
 *  external  three DEM-kind spheres moved between steps (bands overlapping,
 *            one across the periodic x face, one next to a wall) and a
 *            fixed one: forcing, divergence and the corrections of stages 1
 *            and 2 all fused (nothing moves within the step);
 *  free      a free sphere (ρ_p/ρ = 2, gravity) and a fixed one across the
 *            periodic x face: forcing and divergence fused, the corrections
 *            not (the free sphere reads u^k at every stage end);
 *  iterate   the external scene with one extra forcing iteration and the
 *            relaxed forcing (forcing_time): the first forcing in the sweep,
 *            the iteration after it, nothing else fused.
 * RANKS: 1 2
 */
#include "ibmtest.h"
#include "modules.h"
#include "testutil.h"

static const char *box = "[domain]\nnx = 24\nny = 20\nnz = 16\nlength = 4.8 4 3.2\n"
                         "[boundary]\ny_lo = noslip\ny_hi = noslip\n"
                         "[fluid]\nnu = 0.05\nviscous = explicit\ndt = 0.004\n";

/* Run `steps` steps of the scene (externals moved by u Δt before each
 * step) fused or not; the fields and spheres into the returned case. */
static it_case_t run(const char *ibm_section, int unfused, int steps)
{
    char text[2048];
    snprintf(text, sizeof text, "%s%s", box, ibm_section);
    it_case_t tc = it_from_case(text);
    tc.f->prm.unfused = unfused;
    for (int p = 0; p < tc.ibm->n; p++)
        if (tc.ibm->s[p].kind == IBM_FIXED && (tc.ibm->s[p].u[0] != 0.0 || tc.ibm->s[p].u[1] != 0.0))
            tc.ibm->s[p].kind = IBM_EXTERNAL; /* the fixed spheres given a velocity: moved by the "DEM" */
    ibm_update_geometry(tc.ibm);
    double dt = 0.004;
    for (int s = 0; s < steps; s++) {
        for (int p = 0; p < tc.ibm->n; p++) {
            ibm_sphere_t *sp = &tc.ibm->s[p];
            if (sp->kind != IBM_EXTERNAL) continue;
            for (int d = 0; d < 3; d++) sp->x[d] += dt * sp->u[d];
        }
        ibm_update_geometry(tc.ibm);
        fluid_step(tc.f, dt);
    }
    return tc;
}

/* Values of a and b that differ (fields with ghosts, then the spheres). */
static long differences(const it_case_t *a, const it_case_t *b, long *compared)
{
    const grid_t *g = a->g;
    long differ = 0, n = 0;
    for (int c = 0; c <= 3; c++) {
        const double *x = c < 3 ? a->f->u[c] : a->f->p, *y = c < 3 ? b->f->u[c] : b->f->p;
        for (long m = 0; m < g->nalloc; m++, n++) differ += memcmp(&x[m], &y[m], sizeof(double)) != 0;
    }
    differ = (long)grid_sum(g, (double)differ);
    n = (long)grid_sum(g, (double)n);
    for (int p = 0; p < a->ibm->n; p++) {
        const ibm_sphere_t *s = &a->ibm->s[p], *t = &b->ibm->s[p];
        const double *va[] = {s->x, s->u, s->omega, s->force, s->torque}, *vb[] = {t->x, t->u, t->omega, t->force, t->torque};
        for (int k = 0; k < 5; k++, n += 3) differ += memcmp(va[k], vb[k], 3 * sizeof(double)) != 0;
    }
    *compared = n;
    return differ;
}

static void check_scene(const char *name, const char *ibm_section)
{
    it_case_t a = run(ibm_section, 0, 6), b = run(ibm_section, 1, 6);
    long n, differ = differences(&a, &b, &n);
    double F = 0.0;
    for (int p = 0; p < a.ibm->n; p++)
        for (int d = 0; d < 3; d++) F = fmax(F, fabs(a.ibm->s[p].force[d]));
    print_message("  %-8s fused vs unfused: %ld of %ld values differ (fields with ghosts, spheres); largest force "
                  "component %.4g\n",
                  name, differ, n, F);
    assert_true(F > 1e-3); /* the spheres do force the flow */
    assert_int_equal(differ, 0);
    it_free(&a);
    it_free(&b);
}

/* fixed spheres with a velocity become external (run()) */
static const char *externals = "[ibm]\n"
                               "sphere1 = fixed center 0.3 2.0 1.6 diameter 1 velocity 0.4 0.1 -0.2\n"
                               "sphere2 = fixed center 1.35 2.2 1.5 diameter 1 velocity -0.3 0.05 0.1\n"
                               "sphere3 = fixed center 3.0 0.75 1.0 diameter 1 velocity 0.1 -0.05 0.3\n"
                               "sphere4 = fixed center 3.4 2.9 2.4 diameter 0.8\n";

static void test_fused_external(void **state)
{
    (void)state;
    check_scene("external", externals);
}

static void test_fused_free(void **state)
{
    (void)state;
    check_scene("free", "[ibm]\ngravity = 0 -1 0\n"
                        "sphere1 = free center 1.3 2.2 1.6 diameter 1 density 2\n"
                        "sphere2 = fixed center 4.5 1.2 1.6 diameter 1\n");
}

static void test_fused_iterate(void **state)
{
    (void)state;
    char text[1024];
    snprintf(text, sizeof text, "%sforcing_iterations = 1\nforcing_time = 0.5\n", externals);
    check_scene("iterate", text);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    modules_register_keys();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fused_external),
        cmocka_unit_test(test_fused_free),
        cmocka_unit_test(test_fused_iterate),
    };
    TEST_MPI_RUN("ibm_fused", tests);
}
