/* sim_internal.h — what the run driver's files share: sim.c (the time loop,
 * stop conditions, outputs), sim_params.c (the [time] and [output] keys),
 * sim_checkpoint.c (checkpoints and restart). */
#ifndef IBMDEM_SIM_INTERNAL_H
#define IBMDEM_SIM_INTERNAL_H

#include "config.h"
#include "sim.h"

/* Read [time] and [output] into s->prm (stops with file:line: key: reason). */
void sim_read_params(sim_t *s, cfg_t *cfg);
/* Write a checkpoint of every part at the current step; 0 on success. */
int sim_write_checkpoint(sim_t *s);
/* Restart from the checkpoint at path (every part's state, the time, the step). */
void sim_read_checkpoint(sim_t *s, const char *path);
/* Write the FFTW wisdom the run used to the output folder. */
void sim_write_fftw_wisdom(const sim_t *s);

#endif
