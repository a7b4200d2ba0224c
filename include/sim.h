/* sim.h — the run driver: reads [time] and [output], builds the parts of the
 * scene the case file describes, runs the time loop and writes the outputs.
 *
 * A run is a set of PARTS (sim_part_t), each a physical model taking part in
 * the time loop through a few callbacks.  sim.c knows nothing of the physics:
 * it asks each part for its stable time step, advances each part, collects
 * its diagnostics and checks, and tells it when to write snapshots and
 * checkpoints.  The fluid part is src/core/sim_fluid.c; a scene without a
 * [fluid] section has no fluid part.  A new model (particles/DEM, immersed
 * boundary coupling, pore network) adds a file src/core/sim_<name>.c with a
 * function that fills a sim_part_t, and one line in sim_create() (sim.c,
 * "parts of the scene").  Coupled models (e.g. the DEM sub-cycled inside the
 * fluid step) install their hooks when their part is created.
 *
 * The loop (docs/theory.md §1):
 *   dt = min over parts of stable_dt      (fluid_stable_dt)
 *   every part: advance(dt)              (fluid_step)
 *   diagnostics; stop with a checkpoint if a part reports divergence
 *   outputs due at this step (series, fields, checkpoint), progress line;
 *   stop with a checkpoint if a write failed (io_check_errors)
 * What the outputs promise (durability, restarts, the output folder) is in
 * docs/user-guide.md, "What the outputs promise".
 */
#ifndef IBMDEM_SIM_H
#define IBMDEM_SIM_H

#include <hdf5.h>

#include "config.h"
#include "io.h"
#include "porenet.h"

#define SIM_MAX_PARTS 8
#define SIM_MAX_COLS 160

typedef struct sim sim_t;

typedef struct sim_part {
    const char *name; /* checkpoint group, summary.json prefix */
    void *ctx;
    /* Largest stable time step (INFINITY if the part sets no limit). */
    double (*stable_dt)(void *ctx);
    /* Optional: given the step dt every part's limit allows, the step to take
     * (no longer than dt), e.g. one that ends where a collision starts. */
    double (*align_dt)(void *ctx, double dt);
    /* Advance by dt from the current state. */
    void (*advance)(void *ctx, double dt);
    /* Columns this part adds to the time series, and their values after a
     * step (called every step: the divergence checks use them). */
    int ncol;
    const char *const *col_names;
    void (*diagnostics)(void *ctx, double *cols);
    /* After a step: non-zero with a reason if the state is unusable (non-finite
     * values, a stability limit exceeded, a blow-up). */
    int (*diverged)(void *ctx, char *why, size_t nwhy);
    /* Keep / bring back the state at the start of the step, exactly (so a
     * diverged run checkpoints its last good state, from which a restart
     * continues as the uninterrupted run did).  A part with a checkpoint
     * (checkpoint_write) must have them: without, a diverged run checkpoints
     * the state after the failed step. */
    void (*keep_previous)(void *ctx);
    void (*restore_previous)(void *ctx);
    /* Relative rate of change over the last step, per unit time (for
     * [time] steady_tol); needs keep_previous.  NULL: always steady. */
    double (*change_rate)(void *ctx, double dt);
    /* Write a snapshot of the part's fields (its own files in the output folder). */
    void (*write_fields)(void *ctx, double time, long step);
    /* Write / read the exact state of the part in an HDF5 group of a checkpoint. */
    void (*checkpoint_write)(void *ctx, hid_t group);
    void (*checkpoint_read)(void *ctx, hid_t group, const char *path);
    /* Final results for summary.json (keys are prefixed with the part's name). */
    void (*summary)(void *ctx, io_summary_t *s, const char *prefix);
    /* Non-zero when the part has what the run was for (e.g. a measured
     * bounce): the run stops as at t_end.  NULL: never. */
    int (*done)(void *ctx);
    /* Non-zero with a reason when the part cannot go on from the state it is
     * in though nothing diverged (e.g. a contact it has no law for): the run
     * stops with its final outputs, the reason and exit status 1.  NULL: never. */
    int (*halt)(void *ctx, char *why, size_t nwhy);
    void (*destroy)(void *ctx);
} sim_part_t;

/* Run-control values read from [time] and [output]. */
typedef struct {
    double t_end;          /* stop at this simulated time */
    long max_steps;        /* stop after this step number (0: no limit) */
    double wall_limit;     /* stop (with a checkpoint) after this many seconds (0: none) */
    double steady_tol;     /* stop when every part's relative rate of change < this (0: off) */
    int steady_integrals;  /* 1: the rates are those of integrals (flux, forces), not of fields */
    double cfl_abort;      /* hard CFL limit: above it the run has diverged */
    double ke_growth_abort; /* kinetic energy growing by more than this factor in one step: diverged */
    int rollback;          /* keep the previous state (checkpoint on divergence, steady test) */
    int step_retries;      /* a diverging step is taken again with half its dt up to this many times */
    char dir[IO_PATH_MAX]; /* output folder */
    char name[256];        /* case name */
    double fields_every;   /* simulated time between field snapshots (0: first and last only) */
    long series_every;     /* steps between rows of the time series */
    long checkpoint_every; /* steps between checkpoints (0: at the end only) */
    int checkpoint_keep;   /* checkpoints kept in the folder (0: all) */
    int overwrite;         /* a new run deletes the outputs of an earlier run in the folder (else refused) */
    int progress;          /* progress line: 0 auto, 1 on, 2 off (io_progress_start) */
} sim_params_t;

/* A part that adds cell fields to the fluid's snapshots (e.g. the solid
 * fraction of the immersed boundary): called between io_snapshot_begin and
 * io_snapshot_end of every snapshot. */
typedef void (*sim_field_writer_t)(void *ctx, io_snapshots_t *snap);

typedef enum {
    SIM_RUNNING = 0,
    SIM_T_END,
    SIM_MAX_STEPS,
    SIM_WALL_LIMIT,
    SIM_STEADY,
    SIM_DIVERGED,
    SIM_DONE,
    SIM_HALTED,
    SIM_IO_ERROR
} sim_status_t;

struct sim {
    cfg_t *cfg;
    MPI_Comm comm;
    sim_params_t prm;
    sim_part_t part[SIM_MAX_PARTS];
    int npart;
    struct fluid *fluid;     /* the scene's fluid (sim_add_fluid), NULL without [fluid] */
    sim_field_writer_t field_writer[SIM_MAX_PARTS]; /* extra fields of the fluid snapshots */
    void *field_writer_ctx[SIM_MAX_PARTS];
    int nfield_writers;
    const char *output_names[SIM_MAX_PARTS + 1]; /* files of the parts beyond the usual ones (NULL-terminated) */
    int noutput_names;
    /* state */
    double time, dt;
    long step;
    double time_prev;        /* time, step and dt at the start of the last step */
    long step_prev;
    double dt_prev;
    double dt_cap;           /* a step taken again after it diverged: at most this dt (0: no cap) */
    int retries;             /* times the current step has been taken again */
    int retry_ok;            /* the part that diverged says a smaller step may cure it (set in its diverged()) */
    long rejected_steps;     /* steps taken again with a smaller dt, since the start (checkpointed) */
    double wall0, wall_step; /* start of the run; wall time of the last step */
    double part_wall[SIM_MAX_PARTS]; /* wall time in each part's advance, this run (summary.json "cost") */
    double output_wall;      /* wall time in the outputs (series, snapshots, checkpoints), this run */
    long step0;              /* step at the start of this run (restart) */
    sim_status_t status;
    char why[512];           /* why the run diverged or halted */
    char io_why[IO_PATH_MAX + 512]; /* the write that failed */
    char *command;           /* the command line of the run, quoted, without --restart (sim_set_command) */
    /* outputs */
    io_outdir_t out;
    io_series_t *series;
    io_summary_t *summary;
    io_progress_t progress;
    double next_fields;      /* simulated time of the next snapshot */
    long last_fields_step, last_series_step, last_checkpoint_step;
    long prev_series_step;   /* the series row before the last one */
    io_series_resume_t series_resume; /* restart: what the checkpoint says of series.csv */
    double next_report;      /* progress fraction of the next report line */
    char last_checkpoint[IO_PATH_MAX + 64];
    char restart_path[IO_PATH_MAX];
    char *input;             /* resolved input (text) */
    uint64_t fingerprint;
    int check_only;
    int fluid_model;         /* fluid_model_t of the scene ([coupling] fluid) */
};

void sim_register_keys(void);

/* Read [time] and [output], build every part of the scene and its initial
 * state; with restart != NULL, continue from that checkpoint.  check_only:
 * validate and build without creating any output (ibmdem check). */
sim_t *sim_create(cfg_t *cfg, const char *restart, int check_only);
/* The parts of the scene for its fluid model (sim_scene.c, called from sim_create). */
void sim_build_scene(sim_t *s, cfg_t *cfg);
/* Note in the log the keys of the case the run has not read (after its first step). */
void sim_note_unused(const sim_t *s);
/* Add a part (called from sim_create). */
void sim_add_part(sim_t *s, const sim_part_t *part);
/* The command line that started the run (argv of main), for the advice
 * printed when it stops early (restart commands that work as printed). */
void sim_set_command(sim_t *s, int argc, char **argv);
/* Run to the end; returns the exit status: 0 when the run finished (t_end,
 * max_steps, steady state or wall_limit), 1 when a part halted it or a write
 * failed, 3 when it diverged. */
int sim_run(sim_t *s);
/* A word for a POSIX shell: as it is, or single-quoted. */
void shell_quote(const char *word, char *buf, size_t n);
/* The command that continues the run from checkpoint `ckpt` (sim_advice.c). */
void sim_restart_command(const sim_t *s, const char *ckpt, char *buf, size_t n);
/* "--set KEY=VALUE": a smaller step for the part that diverged (s->why). */
void sim_smaller_step_hint(const sim_t *s, char *buf, size_t n);
void sim_free(sim_t *s);

/* The keys a restart may change without breaking exactness (the fingerprint
 * skips them): run control, outputs, and the FFTW wisdom file (a restart
 * plans from the checkpoint's copy of the wisdom). */
extern const char *const sim_run_control_keys[];

/* A file a part writes into the output folder under a name of the case
 * file's (e.g. [packing] output): an output of the run, like the usual ones
 * (a new run refuses a folder that has it, output.overwrite deletes it). */
void sim_add_output_name(sim_t *s, const char *name);

/* Add cell fields to the fluid's snapshots (see sim_field_writer_t). */
void sim_add_field_writer(sim_t *s, sim_field_writer_t fn, void *ctx);

/* The fluid part (sim_fluid.c): built for the resolved fluid model. */
void sim_add_fluid(sim_t *s, cfg_t *cfg);
/* The DEM part (sim_dem.c): built when the case has a [particles] section. */
void sim_add_dem(sim_t *s, cfg_t *cfg);
/* The DEM engine of the run (its packing prepared), NULL without particles. */
struct dem *sim_dem_engine(sim_t *s);
/* The same before the packing preparation (while building the scene). */
struct dem *sim_dem_engine_unprepared(sim_t *s);
/* The pore-network fluid (sim_porenet.c): built for the porenet fluid model. */
void sim_add_porenet(sim_t *s, cfg_t *cfg);
/* Its model (NULL without it), and a function called once before its first solve. */
pn_model_t *sim_porenet_model(sim_t *s);
void sim_porenet_before_start(sim_t *s, void (*fn)(void *ctx), void *ctx);
/* The oedometer protocol of a pore-network + DEM scene ([oedometer], sim_oedometer.c:
 * Terzaghi's consolidation), added after the network. */
void sim_add_oedometer(sim_t *s, cfg_t *cfg);
void sim_oedometer_register_keys(void);
/* The immersed-boundary part (sim_ibm.c): built when the case has an [ibm]
 * section; needs the fluid (its stage hooks do the work). */
void sim_add_ibm(sim_t *s, cfg_t *cfg);
/* The same with extra spheres after those of [ibm] (the DEM particles of a
 * coupled scene); returns the immersed boundary. */
struct ibm *sim_add_ibm_with(sim_t *s, cfg_t *cfg, const void *extra_spheres, int nextra);
/* A DEM advanced by another part (the coupling): its own advance does nothing. */
void sim_dem_set_driven(sim_t *s);
/* The coupling part (sim_coupling.c): resolved IBM–DEM exchange (ibm != NULL)
 * and the restitution measurements. */
void sim_add_coupling(sim_t *s, cfg_t *cfg, struct ibm *ibm);
/* The measurements of a flow down an inclined plane ([avalanche], sim_avalanche.c), after
 * every other part; ibm: the immersed spheres of the particles (NULL without a resolved fluid). */
void sim_avalanche_register_keys(void);
void sim_add_avalanche(sim_t *s, cfg_t *cfg, struct ibm *ibm);
void sim_coupling_register_keys(void);
/* Pressure probes ([probes], sim_probes.c): columns of series.csv, added
 * after the other parts of a scene with the resolved fluid. */
void sim_add_probes(sim_t *s, cfg_t *cfg);
void sim_probes_register_keys(void);
/* The scene's fluid model is the resolved fluid ([coupling] fluid, fluid_model.h). */
int sim_fluid_enabled(cfg_t *cfg);

#endif
