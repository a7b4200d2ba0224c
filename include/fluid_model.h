/* fluid_model.h — the fluid model of a scene, named in one place: the key
 * [coupling] fluid (docs/user-guide.md "Fluid models").
 *
 *   none         no fluid: the DEM alone ([lubrication] is not used)
 *   lubrication  the DEM with Brenner lubrication ([lubrication] model = brenner),
 *                no other fluid force; `off` is the same with [lubrication]
 *                as set (the DEM alone when its model is none)
 *   drag         the DEM with a drag closure, buoyancy and [lubrication] as set
 *                ([drag], src/dem/drag.c)
 *   porenet      the pore network coupled with the DEM, or alone on a fixed packing ([porenet])
 *   resolved     the resolved fluid ([fluid]) with immersed spheres and DEM particles
 *
 * The default, auto, takes the model whose section the case has ([fluid]:
 * resolved, [porenet]: porenet, [drag]: drag; none of them: off) and asks
 * the case to name it when it has more than one.  The other sections stay
 * valid; the run notes in its log the keys it did not use. */
#ifndef IBMDEM_FLUID_MODEL_H
#define IBMDEM_FLUID_MODEL_H

#include "config.h"

typedef enum {
    FLUID_MODEL_NONE = 0,
    FLUID_MODEL_LUBRICATION, /* off: the same with [lubrication] as set */
    FLUID_MODEL_DRAG,
    FLUID_MODEL_PORENET,
    FLUID_MODEL_RESOLVED
} fluid_model_t;

void fluid_model_register_keys(void);
/* The scene's fluid model (stops with file:line: coupling.fluid: reason when
 * the case does not give what the model needs). */
fluid_model_t fluid_model_of(cfg_t *cfg);
const char *fluid_model_name(fluid_model_t m);
/* The DEM's Brenner lubrication of [lubrication] applies (every model but none). */
int fluid_model_lubrication(cfg_t *cfg);
/* Dynamic viscosity of the scene's fluid (Pa s) for a part that has none of
 * its own (the lubrication): [drag] viscosity, [porenet] viscosity, or ρν of
 * [fluid]; -1 when the case gives none. */
double fluid_model_viscosity(cfg_t *cfg);

#endif
