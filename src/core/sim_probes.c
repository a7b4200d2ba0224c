/* sim_probes.c — pressure probes as a part of a run ([probes]): the pore
 * pressure (relative to hydrostatic, decision 7) and optionally the velocity
 * of the resolved fluid at points of the case file, as columns of series.csv
 * (interpolation: probes.h).  The part has no state of its own: its columns
 * are functions of the fluid's fields, so a restart writes what the
 * uninterrupted run wrote. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "porenet.h"
#include "probes.h"
#include "sim.h"
#include "util.h"

#define PROBES_MAX 9
#define BIG 1e300

#define POINT_KEY(N)                                                                                      \
    {"probes", "point" #N, CFG_VEC3, NULL, -BIG, BIG, NULL,                                               \
     N == 1 ? "a probe: X Y Z (m), inside the domain; series.csv gets p_probe1 (Pa, relative to hydrostatic "  \
              "and to probes.reference if given) and with velocity = true u_probe1, v_probe1[, w_probe1]; "    \
              "point2 ... point9 the same"                                                                 \
            : "as point1", CFG_OPTIONAL}

static const cfg_key_t probe_keys[] = {
    POINT_KEY(1), POINT_KEY(2), POINT_KEY(3), POINT_KEY(4), POINT_KEY(5),
    POINT_KEY(6), POINT_KEY(7), POINT_KEY(8), POINT_KEY(9),
    {"probes", "reference", CFG_VEC3, NULL, -BIG, BIG, NULL,
     "optional point (m) whose pressure is subtracted from every probe's (e.g. in the clear fluid far from the "
     "grains: the ambient pressure); without it the pressure is the solver's, whose volume-weighted mean over "
     "the domain is zero", CFG_OPTIONAL},
    {"probes", "velocity", CFG_BOOL, "false", 1, 0, NULL, "also write the fluid velocity at each probe (m/s)"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void sim_probes_register_keys(void) { cfg_schema_add(probe_keys); }

typedef struct {
    fluid_t *f;
    probes_t *pr;
    int n;          /* probes of the case (the reference, if any, is point n) */
    int ref;        /* a reference point is given */
    int vel;        /* velocity columns */
    double rho;     /* kinematic pressure to Pa */
    double *val;    /* pressures of the n (+1) points */
    double *uval;   /* velocities */
    char names[PROBES_MAX * 4][24];
    const char *col[PROBES_MAX * 4];
} probes_part_t;

static void part_diagnostics(void *ctx, double *c)
{
    probes_part_t *pp = ctx;
    const int dim = pp->f->g->dim, per = 1 + (pp->vel ? dim : 0);
    probes_eval_cell(pp->pr, pp->f->p, pp->val);
    const double p0 = pp->ref ? pp->val[pp->n] : 0.0;
    if (pp->vel) probes_eval_velocity(pp->pr, pp->f->u, pp->uval);
    for (int i = 0; i < pp->n; i++) {
        c[i * per] = pp->rho * (pp->val[i] - p0);
        if (pp->vel)
            for (int d = 0; d < dim; d++) c[i * per + 1 + d] = pp->uval[i * dim + d];
    }
}

static void part_destroy(void *ctx)
{
    probes_part_t *pp = ctx;
    probes_free(pp->pr);
    free(pp->val);
    free(pp->uval);
    free(pp);
}

/* ---- the pore network: the pressure of the pore holding each point ---- */

typedef struct {
    pn_model_t *m;
    int n, ref;
    double pts[3 * (PROBES_MAX + 1)];
    char names[PROBES_MAX][24];
    const char *col[PROBES_MAX];
} pn_probes_t;

static double pn_probe_value(const pn_probes_t *pp, int i)
{
    if (!pp->m->built) return 0.0; /* before the first solve the fluid is at rest: hydrostatic */
    const int p = pn_model_pore_at(pp->m, pp->pts + 3 * i);
    return p >= 0 ? pp->m->p[p] : p == PN_CLEAR_AT ? 0.0 : NAN;
}

static void pn_part_diagnostics(void *ctx, double *c)
{
    pn_probes_t *pp = ctx;
    const double p0 = pp->ref ? pn_probe_value(pp, pp->n) : 0.0;
    for (int i = 0; i < pp->n; i++) c[i] = pn_probe_value(pp, i) - p0;
}

static void add_porenet_probes(sim_t *s, cfg_t *cfg, pn_model_t *m, const double *pts, const int *key_of, int n)
{
    if (cfg_bool(cfg, "probes", "velocity"))
        cfg_fail(cfg, "probes", "velocity", "the pore network has one pressure per pore and no velocity field");
    pn_probes_t *pp = xcalloc(1, sizeof *pp);
    pp->m = m;
    pp->n = n;
    pp->ref = cfg_has(cfg, "probes", "reference");
    memcpy(pp->pts, pts, 3 * (size_t)(n + pp->ref) * sizeof *pts);
    for (int i = 0; i < n + pp->ref; i++) {
        const double *q = pts + 3 * i;
        int in = 1;
        for (int a = 0; a < 3; a++) in &= q[a] >= m->dom.lo[a] && q[a] <= m->dom.hi[a];
        char key[32];
        if (i < n) snprintf(key, sizeof key, "point%d", key_of[i]);
        else snprintf(key, sizeof key, "reference");
        if (!in)
            cfg_fail(cfg, "probes", key, "the point (%g, %g, %g) is outside the domain, x in [%g, %g], y in [%g, %g], "
                     "z in [%g, %g]", q[0], q[1], q[2], m->dom.lo[0], m->dom.hi[0], m->dom.lo[1], m->dom.hi[1],
                     m->dom.lo[2], m->dom.hi[2]);
        if (i < n) {
            snprintf(pp->names[i], sizeof pp->names[0], "p_probe%d", key_of[i]);
            pp->col[i] = pp->names[i];
        }
        msg("probes: %s (%g, %g, %g), the pressure of the pore holding it\n", i < n ? pp->names[i] : "reference",
            q[0], q[1], q[2]);
    }
    sim_part_t part = {
        .name = "probes",
        .ctx = pp,
        .ncol = n,
        .col_names = pp->col,
        .diagnostics = pn_part_diagnostics,
        .destroy = free,
    };
    sim_add_part(s, &part);
}

void sim_add_probes(sim_t *s, cfg_t *cfg)
{
    pn_model_t *pm = s->fluid ? NULL : sim_porenet_model(s);
    if (!s->fluid && !pm) die("probes: the scene has no resolved fluid and no pore network");
    double pts[3 * (PROBES_MAX + 1)];
    int key_of[PROBES_MAX + 1], n = 0;
    for (int k = 1; k <= PROBES_MAX; k++) {
        char key[32];
        snprintf(key, sizeof key, "point%d", k);
        if (!cfg_has(cfg, "probes", key)) continue;
        cfg_vec3(cfg, "probes", key, pts + 3 * n);
        key_of[n++] = k;
    }
    if (n == 0) cfg_fail(cfg, "probes", "point1", "the [probes] section names no point (point1 ... point9)");
    if (pm) {
        if (cfg_has(cfg, "probes", "reference")) cfg_vec3(cfg, "probes", "reference", pts + 3 * n);
        add_porenet_probes(s, cfg, pm, pts, key_of, n);
        return;
    }
    const grid_t *g = s->fluid->g;
    probes_part_t *pp = xcalloc(1, sizeof *pp);
    pp->f = s->fluid;
    pp->n = n;
    pp->ref = cfg_has(cfg, "probes", "reference");
    if (pp->ref) cfg_vec3(cfg, "probes", "reference", pts + 3 * n);
    pp->vel = cfg_bool(cfg, "probes", "velocity");
    pp->rho = cfg_double(cfg, "fluid", "rho");
    const int npt = n + pp->ref;
    int bad = -1;
    pp->pr = probes_create(g, npt, pts, &bad);
    if (!pp->pr) {
        char key[32];
        if (bad < n) snprintf(key, sizeof key, "point%d", key_of[bad]);
        else snprintf(key, sizeof key, "reference");
        const double *q = pts + 3 * bad;
        char zr[64] = "";
        if (g->dim == 3) snprintf(zr, sizeof zr, ", z in [%g, %g]", g->x0[2], g->x0[2] + g->L[2]);
        cfg_fail(cfg, "probes", key, "the point (%g, %g, %g) is outside the domain, x in [%g, %g], y in [%g, %g]%s",
                 q[0], q[1], q[2], g->x0[0], g->x0[0] + g->L[0], g->x0[1], g->x0[1] + g->L[1], zr);
    }
    pp->val = xcalloc((size_t)npt, sizeof *pp->val);
    pp->uval = xcalloc((size_t)npt * 3, sizeof *pp->uval);
    static const char *comp[3] = {"u", "v", "w"};
    int nc = 0;
    for (int i = 0; i < n; i++) {
        snprintf(pp->names[nc], sizeof pp->names[0], "p_probe%d", key_of[i]);
        pp->col[nc] = pp->names[nc];
        nc++;
        if (pp->vel)
            for (int d = 0; d < g->dim; d++) {
                snprintf(pp->names[nc], sizeof pp->names[0], "%s_probe%d", comp[d], key_of[i]);
                pp->col[nc] = pp->names[nc];
                nc++;
            }
    }
    for (int i = 0; i < npt; i++)
        msg("probes: %s (%g, %g, %g)\n", i < n ? pp->names[i * (1 + (pp->vel ? g->dim : 0))] : "reference",
            pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    sim_part_t part = {
        .name = "probes",
        .ctx = pp,
        .ncol = nc,
        .col_names = pp->col,
        .diagnostics = part_diagnostics,
        .destroy = part_destroy,
    };
    sim_add_part(s, &part);
}
