/* fluid_model.c — the fluid model of a scene ([coupling] fluid, fluid_model.h). */
#include "fluid_model.h"

#include <string.h>

#include "fluid.h"

static const cfg_key_t model_keys[] = {
    {"coupling", "fluid", CFG_ENUM, "auto", 1, 0, "auto|resolved|porenet|drag|lubrication|none|off",
     "the fluid model: resolved ([fluid]: particles are immersed spheres, DEM sub-cycled in each fluid step), "
     "porenet (the pore network of [porenet]), drag (DEM + drag closure + buoyancy of [drag], with [lubrication]), "
     "lubrication (DEM + Brenner lubrication), none (the DEM alone), off (dry: the DEM with [lubrication] as set); "
     "auto: the model whose section the case has (none of them: off); sections of other models are not used"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL},
};

void fluid_model_register_keys(void) { cfg_schema_add(model_keys); }

const char *fluid_model_name(fluid_model_t m)
{
    static const char *name[] = {"none", "lubrication", "drag", "porenet", "resolved"};
    return name[m];
}

enum { KEY_AUTO = 0, KEY_RESOLVED, KEY_PORENET, KEY_DRAG, KEY_LUBRICATION, KEY_NONE, KEY_OFF };

fluid_model_t fluid_model_of(cfg_t *cfg)
{
    const int key = cfg_enum(cfg, "coupling", "fluid");
    switch (key) {
    case KEY_RESOLVED:
        if (!cfg_has_section(cfg, "fluid")) cfg_fail(cfg, "coupling", "fluid", "resolved needs a [fluid] section");
        return FLUID_MODEL_RESOLVED;
    case KEY_PORENET:
        if (!cfg_has_section(cfg, "porenet")) cfg_fail(cfg, "coupling", "fluid", "porenet needs a [porenet] section");
        return FLUID_MODEL_PORENET;
    case KEY_DRAG: return FLUID_MODEL_DRAG;
    case KEY_LUBRICATION:
        if (cfg_enum(cfg, "lubrication", "model") == 0)
            cfg_fail(cfg, "coupling", "fluid", "lubrication needs a [lubrication] model (brenner or correction)");
        return FLUID_MODEL_LUBRICATION;
    case KEY_NONE: return FLUID_MODEL_NONE;
    case KEY_OFF: return FLUID_MODEL_LUBRICATION;
    }
    /* auto: the one model whose section the case has */
    static const char *sec[3] = {"fluid", "porenet", "drag"};
    static const fluid_model_t model[3] = {FLUID_MODEL_RESOLVED, FLUID_MODEL_PORENET, FLUID_MODEL_DRAG};
    int found = -1;
    for (int k = 0; k < 3; k++) {
        if (!cfg_has_section(cfg, sec[k])) continue;
        if (found >= 0)
            cfg_fail(cfg, "coupling", "fluid",
                     "the case has a [%s] and a [%s] section: name its fluid model (resolved, porenet, drag, "
                     "lubrication or none)",
                     sec[found], sec[k]);
        found = k;
    }
    return found >= 0 ? model[found] : FLUID_MODEL_LUBRICATION;
}

int fluid_model_lubrication(cfg_t *cfg) { return fluid_model_of(cfg) != FLUID_MODEL_NONE; }

double fluid_model_viscosity(cfg_t *cfg)
{
    const fluid_model_t m = fluid_model_of(cfg);
    if (m == FLUID_MODEL_DRAG && cfg_double(cfg, "drag", "viscosity") > 0) return cfg_double(cfg, "drag", "viscosity");
    if (m == FLUID_MODEL_PORENET) return cfg_double(cfg, "porenet", "viscosity");
    if (cfg_has_section(cfg, "fluid")) return cfg_double(cfg, "fluid", "rho") * fluid_nu_from_config(cfg);
    return -1;
}
