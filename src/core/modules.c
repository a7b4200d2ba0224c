/* modules.c — one place that knows every module's schema of keys. */
#include "modules.h"

#include "dem.h"
#include "fluid_model.h"
#include "fluid.h"
#include "ibm.h"
#include "grid.h"
#include "poisson.h"
#include "porenet.h"
#include "sim.h"

void modules_register_keys(void)
{
    grid_register_keys();
    poisson_register_keys();
    fluid_register_keys();
    porenet_register_keys();
    ibm_register_keys();
    sim_register_keys();
    dem_register_keys();
    dem_lubrication_register_keys();
    dem_drag_register_keys();
    sim_coupling_register_keys();
    fluid_model_register_keys();
    sim_oedometer_register_keys();
    sim_avalanche_register_keys();
    sim_probes_register_keys();
}
