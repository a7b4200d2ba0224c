/* sim_params.c — the run driver's keys ([time], [output]) and their reading
 * into sim_params_t (sim.c). */
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "coupling.h"
#include "poisson.h"
#include "sim.h"
#include "sim_internal.h"
#include "util.h"

static const cfg_key_t sim_keys[] = {
    {"time", "t_end", CFG_DOUBLE, NULL, 0, 1e300, NULL, "simulated time at which the run stops"},
    {"time", "max_steps", CFG_INT, "0", 0, 2147483647, NULL,
     "stop after this step number (counted from the start of the run, restarts included); 0: no limit"},
    {"time", "wall_limit", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "stop with a checkpoint after this many seconds of wall time; 0: no limit"},
    {"time", "steady_tol", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "stop when the relative rate of change per unit time (steady_measure) falls below this; 0: off"},
    {"time", "steady_measure", CFG_ENUM, "field", 1, 0, "field|integrals",
     "steady_tol measures field: max|u(n+1) - u(n)| / (dt max|u|) over the velocity field (and the particles' "
     "velocities); integrals: the quantities a steady flow is run for — the superficial velocity along each "
     "periodic direction (and a held flow rate's body force) and the force on each immersed sphere, "
     "max|q(n+1) - q(n)| / (dt max|q|) (the field where the domain has no periodic direction)"},
    {"time", "cfl_abort", CFG_DOUBLE, "1.5", 1e-3, 100, NULL,
     "hard CFL limit: a step above it (or above twice the CFL target of an adaptive step) means divergence"},
    {"time", "ke_growth_abort", CFG_DOUBLE, "100", 1.000001, 1e300, NULL,
     "kinetic energy growing by more than this factor in one step means divergence"},
    {"time", "step_retries", CFG_INT, "4", 0, 100, NULL,
     "a step of an adaptive fluid step that diverges (CFL or kinetic-energy limit, non-finite values) is taken "
     "again from its start with half its time step, up to this many times, before the run stops as diverged "
     "(needs rollback; each retry is logged, their count is summary.json's rejected_steps); 0: stop at the first "
     "divergence"},
    {"time", "rollback", CFG_BOOL, "true", 1, 0, NULL,
     "keep the state at the start of each step, so a diverging run checkpoints its last good state "
     "(costs one copy of the velocity and pressure, of the spheres, of the DEM's particles, springs and lists, "
     "and of the pore network's state)"},
    {"output", "dir", CFG_STRING, "out/NAME", 1, 0, NULL, "output folder (created); --out DIR sets it too"},
    {"output", "name", CFG_STRING, "case file name", 1, 0, NULL, "case name written in summary.json"},
    {"output", "fields_every", CFG_DOUBLE, "0", 0, 1e300, NULL,
     "simulated time between field snapshots (fields_NNNNN.h5 + fields.xmf); 0: initial and final only"},
    {"output", "series_every", CFG_INT, "1", 1, 2147483647, NULL, "steps between rows of series.csv"},
    {"output", "checkpoint_every", CFG_INT, "0", 0, 2147483647, NULL,
     "steps between checkpoints (checkpoint_SSSSSSSS.h5); 0: at the end only"},
    {"output", "checkpoint_keep", CFG_INT, "2", 0, 1000000, NULL, "newest checkpoints kept in the folder; 0: all"},
    {"output", "overwrite", CFG_BOOL, "false", 1, 0, NULL,
     "a new run into a folder that holds the outputs of an earlier run: false: refused; true: those files are "
     "deleted first (a restart continues in place whatever this is)"},
    {"output", "progress", CFG_ENUM, "auto", 1, 0, "auto|on|off",
     "progress line redrawn in place: auto = when stdout is a terminal and the run was not started by mpirun "
     "(whose processes always see a pseudo-terminal), on, off"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void sim_register_keys(void) { cfg_schema_add(sim_keys); }

const char *const sim_run_control_keys[] = {"time.t_end",     "time.max_steps", "time.wall_limit", "time.steady_tol",
                                            "time.cfl_abort", "time.ke_growth_abort", "time.rollback",
                                            "time.step_retries", "time.steady_measure",
                                            "output.*",       "poisson.fftw_wisdom", NULL};

void sim_read_params(sim_t *s, cfg_t *cfg)
{
    sim_params_t *p = &s->prm;
    p->t_end = cfg_double(cfg, "time", "t_end");
    p->max_steps = cfg_int(cfg, "time", "max_steps");
    p->wall_limit = cfg_double(cfg, "time", "wall_limit");
    p->steady_tol = cfg_double(cfg, "time", "steady_tol");
    p->steady_integrals = cfg_enum(cfg, "time", "steady_measure") == 1;
    p->cfl_abort = cfg_double(cfg, "time", "cfl_abort");
    p->ke_growth_abort = cfg_double(cfg, "time", "ke_growth_abort");
    p->rollback = cfg_bool(cfg, "time", "rollback");
    p->step_retries = cfg_int(cfg, "time", "step_retries");
    /* The case name defaults to the file name without its directory and .ini */
    if (cfg_has(cfg, "output", "name")) {
        if (strlen(cfg_string(cfg, "output", "name")) >= sizeof p->name)
            cfg_fail(cfg, "output", "name", "longer than %zu bytes", sizeof p->name - 1);
        snprintf(p->name, sizeof p->name, "%s", cfg_string(cfg, "output", "name"));
    } else {
        const char *base = strrchr(cfg_path(cfg), '/');
        snprintf(p->name, sizeof p->name, "%s", base ? base + 1 : cfg_path(cfg));
        char *dot = strrchr(p->name, '.');
        if (dot && dot != p->name) *dot = 0;
    }
    if (cfg_has(cfg, "output", "dir")) {
        if (strlen(cfg_string(cfg, "output", "dir")) >= sizeof p->dir)
            cfg_fail(cfg, "output", "dir", "the path is longer than %zu bytes", sizeof p->dir - 1);
        snprintf(p->dir, sizeof p->dir, "%s", cfg_string(cfg, "output", "dir"));
    } else {
        snprintf(p->dir, sizeof p->dir, "out/%s", p->name);
    }
    /* every file name inside the folder must fit in a path the system takes */
    const size_t longest = strlen("/checkpoint_00000000000.h5.tmp") + 16;
    if (strlen(p->dir) + longest >= PATH_MAX || strlen(p->dir) + longest >= IO_PATH_MAX)
        cfg_fail(cfg, "output", "dir", "a path of %zu characters: at most %zu (the system's PATH_MAX %d less the "
                 "longest file name inside it)", strlen(p->dir), (size_t)PATH_MAX - longest - 1, PATH_MAX);
    for (const char *c = p->dir; *c;) {
        size_t len = strcspn(c, "/");
        if (len > NAME_MAX)
            cfg_fail(cfg, "output", "dir", "a folder name of %zu characters: at most %d (the system's NAME_MAX)", len,
                     NAME_MAX);
        c += len + (c[len] == '/');
    }
    p->overwrite = cfg_bool(cfg, "output", "overwrite");
    p->fields_every = cfg_double(cfg, "output", "fields_every");
    p->series_every = cfg_int(cfg, "output", "series_every");
    p->checkpoint_every = cfg_int(cfg, "output", "checkpoint_every");
    p->checkpoint_keep = cfg_int(cfg, "output", "checkpoint_keep");
    p->progress = cfg_enum(cfg, "output", "progress");
    if (p->steady_tol > 0 && !p->rollback)
        cfg_fail(cfg, "time", "steady_tol", "needs time.rollback = true (the previous state is compared)");
}
