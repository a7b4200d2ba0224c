/* progress.c — one progress line (simulated time, percent, steps/s, ETA),
 * redrawn in place with \r.  Drawn only on rank 0 and only when stdout is a
 * terminal: a log or a pipe gets no carriage returns. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "io.h"
#include "util.h"

static int under_mpirun(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_RANK") || getenv("PMIX_RANK");
}

void io_progress_start(io_progress_t *p, double frac, long step, int mode)
{
    int want = mode == 1 || (mode == 0 && isatty(fileno(stdout)) && !under_mpirun());
    p->active = mpi_rank() == 0 && want;
    p->wall0 = wtime();
    p->frac0 = frac;
    p->step0 = step;
    p->last = 0;
    p->shown = 0;
}

static void format_duration(double s, char *buf, size_t n)
{
    if (!isfinite(s) || s < 0)
        snprintf(buf, n, "?");
    else if (s < 60)
        snprintf(buf, n, "%.0fs", s);
    else if (s < 3600)
        snprintf(buf, n, "%dm%02ds", (int)(s / 60), (int)fmod(s, 60));
    else
        snprintf(buf, n, "%dh%02dm", (int)(s / 3600), (int)fmod(s / 60, 60));
}

void io_progress_update(io_progress_t *p, double time, long step, double frac)
{
    if (!p->active) return;
    double now = wtime();
    if (now - p->last < 0.25 && frac < 1.0) return;
    p->last = now;
    double el = now - p->wall0;
    double rate = el > 0 ? (step - p->step0) / el : 0;
    double eta = frac > p->frac0 ? el * (1.0 - frac) / (frac - p->frac0) : NAN;
    char etas[32];
    format_duration(eta, etas, sizeof etas);
    int len = printf("\r  t = %-12.6g %5.1f %%  step %-9ld %8.1f steps/s  ETA %-8s", time, 100.0 * fmin(frac, 1.0),
                     step, rate, etas);
    fflush(stdout);
    p->shown = len;
}

void io_progress_clear(io_progress_t *p)
{
    if (!p->active || !p->shown) return;
    printf("\r%*s\r", p->shown, "");
    fflush(stdout);
    p->shown = 0;
}
