/* sim_scene.c — the parts of a scene for its fluid model ([coupling] fluid,
 * fluid_model.h), and the note of the keys a run did not use.
 *
 *   resolved     fluid; with particles: DEM (driven), immersed spheres of the
 *                particles (after those of [ibm]), coupling; without: [ibm] if given;
 *                then the probes of [probes]
 *   porenet      DEM (if particles), pore network, the probes of [probes] (the
 *                pressure of the pore holding each point)
 *   drag,
 *   lubrication,
 *   none         DEM (the drag, the buoyancy and the lubrication act inside its steps);
 *                [probes] is not read (the log notes its keys as unused)
 * plus, without the resolved fluid, the restitution measurements if asked. */
#include <stdlib.h>
#include <string.h>

#include "coupling.h"
#include "fluid_model.h"
#include "sim.h"
#include "util.h"

void sim_build_scene(sim_t *s, cfg_t *cfg)
{
    const fluid_model_t model = fluid_model_of(cfg);
    s->fluid_model = (int)model;
    const int particles = cfg_has_section(cfg, "particles");
    if (model == FLUID_MODEL_RESOLVED) {
        sim_add_fluid(s, cfg);
        if (particles) {
            /* resolved coupling: the particles are immersed spheres of the fluid */
            sim_add_dem(s, cfg);
            sim_dem_set_driven(s);
            int n = 0;
            ibm_sphere_t *sp = coupling_spheres_of_particles(sim_dem_engine_unprepared(s), &n);
            struct ibm *ibm = sim_add_ibm_with(s, cfg, sp, n);
            free(sp);
            sim_add_coupling(s, cfg, ibm);
            if (cfg_has_section(cfg, "avalanche")) sim_add_avalanche(s, cfg, ibm);
        } else if (cfg_has_section(cfg, "ibm")) {
            sim_add_ibm(s, cfg);
        }
        if (cfg_has_section(cfg, "probes")) sim_add_probes(s, cfg);
        return;
    }
    /* without the resolved fluid, [ibm] is a section of another model: an
     * error only when the case did not name its model (it has no [fluid]) */
    if (cfg_has_section(cfg, "ibm") && cfg_enum(cfg, "coupling", "fluid") == 0)
        cfg_fail(cfg, "ibm", "sphere1", "an immersed boundary needs a fluid: the case has no [fluid] section");
    if (particles) sim_add_dem(s, cfg);
    if (model == FLUID_MODEL_PORENET) sim_add_porenet(s, cfg);
    if (model == FLUID_MODEL_PORENET && cfg_has_section(cfg, "oedometer")) sim_add_oedometer(s, cfg);
    if (model == FLUID_MODEL_PORENET && cfg_has_section(cfg, "probes")) sim_add_probes(s, cfg);
    if (particles && cfg_enum(cfg, "coupling", "restitution") != 0) sim_add_coupling(s, cfg, NULL);
    if (particles && cfg_has_section(cfg, "avalanche")) sim_add_avalanche(s, cfg, NULL);
    if (s->npart == 0) {
        if (mpi_rank() == 0) {
            char secs[128] = "";
            static const char *other[] = {"fluid", "ibm", "porenet", "drag"};
            int ns = 0;
            for (int k = 0; k < 4; k++)
                if (cfg_has_section(cfg, other[k]))
                    snprintf(secs + strlen(secs), sizeof secs - strlen(secs), "%s[%s]", ns++ ? " and " : "", other[k]);
            if (ns)
                fprintf(stderr,
                        "%s: nothing to simulate with coupling.fluid = %s: the case has no [particles] (its %s "
                        "belong%s to another fluid model)\n",
                        cfg_path(cfg), cfg_string(cfg, "coupling", "fluid"), secs, ns > 1 ? "" : "s");
            else
                fprintf(stderr,
                        "%s: nothing to simulate: the case has no [fluid] or [particles] section (with at least one "
                        "key)\n",
                        cfg_path(cfg));
        }
        MPI_Finalize();
        exit(2);
    }
}

/* ---- the keys a run did not use --------------------------------------------------- */

typedef struct {
    char section[64];
    char line[900];
    int nline;
} unused_t;

static void flush_unused(unused_t *u)
{
    if (u->nline) msg("  [%s] %s\n", u->section, u->line);
    u->nline = 0;
    u->line[0] = 0;
}

static void add_unused(const char *section, const char *key, int line, void *ctx)
{
    unused_t *u = ctx;
    (void)line;
    if (strcmp(section, u->section)) {
        flush_unused(u);
        snprintf(u->section, sizeof u->section, "%s", section);
    }
    size_t len = strlen(u->line);
    snprintf(u->line + len, sizeof u->line - len, "%s%s", u->nline ? ", " : "", key);
    u->nline++;
}

static void count_unused(const char *section, const char *key, int line, void *ctx)
{
    (void)section, (void)key, (void)line;
    (*(int *)ctx)++;
}

void sim_note_unused(const sim_t *s)
{
    static const char *what[] = {"none (the DEM alone)", "lubrication (the DEM with lubrication, [lubrication] model = ",
                                 "drag (the DEM with a drag closure, buoyancy and [lubrication])",
                                 "porenet (the pore network)", "resolved (the resolved fluid)"};
    int m = s->fluid_model;
    /* (the lubrication model was read by the DEM in every model but none) */
    if (m == FLUID_MODEL_LUBRICATION && cfg_enum(s->cfg, "lubrication", "model") == 0) m = FLUID_MODEL_NONE;
    const int lub = m == FLUID_MODEL_LUBRICATION;
    msg("fluid model: %s%s%s; coupling.fluid = %s\n", what[m], lub ? cfg_string(s->cfg, "lubrication", "model") : "",
        lub ? ")" : "", cfg_string(s->cfg, "coupling", "fluid"));
    int n = 0;
    cfg_foreach_unused(s->cfg, count_unused, &n);
    if (n == 0) return;
    msg("note: %d key%s of the case not used by this run%s:\n", n, n > 1 ? "s" : "",
        s->restart_path[0] ? " (restarted)" : "");
    unused_t u = {"", "", 0};
    cfg_foreach_unused(s->cfg, add_unused, &u);
    flush_unused(&u);
}
