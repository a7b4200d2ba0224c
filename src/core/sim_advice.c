/* sim_advice.c — what a run that stops early tells its user: the command
 * that continues it (its own command line, quoted for a shell, with
 * --restart) and the key that makes the step of the part that diverged
 * smaller. */
#include <stdlib.h>
#include <string.h>

#include "fluid.h"
#include "sim.h"
#include "util.h"

/* Shell word: as it is when it is made of safe characters, else in single
 * quotes (a quote inside written '\''). */
void shell_quote(const char *w, char *buf, size_t n)
{
    int safe = *w != 0;
    for (const char *c = w; *c && safe; c++)
        safe = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
               strchr("_@%+=:,./-", *c) != NULL;
    if (safe) {
        snprintf(buf, n, "%s", w);
        return;
    }
    size_t k = 0;
    if (k + 1 < n) buf[k++] = '\'';
    for (const char *c = w; *c && k + 5 < n; c++) {
        if (*c == '\'') {
            memcpy(buf + k, "'\\''", 4);
            k += 4;
        } else {
            buf[k++] = *c;
        }
    }
    if (k + 1 < n) buf[k++] = '\'';
    buf[k < n ? k : n - 1] = 0;
}

void sim_set_command(sim_t *s, int argc, char **argv)
{
    size_t cap = 64;
    for (int a = 0; a < argc; a++) cap += 4 * strlen(argv[a]) + 4;
    char *cmd = malloc(cap), *w = malloc(cap);
    size_t len = 0;
    if (mpi_size() > 1) len += (size_t)snprintf(cmd, cap, "mpirun -np %d ", mpi_size());
    for (int a = 0; a < argc; a++) {
        if (!strcmp(argv[a], "--restart")) { /* the restart is said apart */
            a++;
            continue;
        }
        shell_quote(argv[a], w, cap);
        len += (size_t)snprintf(cmd + len, cap - len, "%s%s", a ? " " : "", w);
    }
    free(w);
    free(s->command);
    s->command = cmd;
}

/* The command that continues from checkpoint `ckpt`: the run's own command
 * line (its --set and --out included) with --restart. */
void sim_restart_command(const sim_t *s, const char *ckpt, char *buf, size_t n)
{
    char q[IO_PATH_MAX + 256];
    shell_quote(ckpt, q, sizeof q);
    snprintf(buf, n, "%s --restart %s", s->command ? s->command : "ibmdem run CASE.ini", q);
}

/* A key and value that make the time step of the part that diverged smaller. */
void sim_smaller_step_hint(const sim_t *s, char *buf, size_t n)
{
    const char *who = s->why;
    cfg_t *c = s->cfg;
    if ((!strncmp(who, "dem", 3) || !strncmp(who, "coupling", 8)) && cfg_has_section(c, "particles")) {
        if (cfg_double(c, "dem", "dt") > 0)
            snprintf(buf, n, "--set dem.dt=%.6g", 0.5 * cfg_double(c, "dem", "dt"));
        else
            snprintf(buf, n, "--set dem.steps_per_contact=%ld", 2L * cfg_int(c, "dem", "steps_per_contact"));
    } else if (!strncmp(who, "porenet", 7) && cfg_has_section(c, "particles")) {
        snprintf(buf, n, "--set porenet.dt_factor=%.6g", 0.5 * cfg_double(c, "porenet", "dt_factor"));
    } else if (s->fluid && s->fluid->prm.dt_fixed > 0) {
        snprintf(buf, n, "--set fluid.dt=%.6g", 0.5 * s->fluid->prm.dt_fixed);
    } else if (s->fluid) {
        snprintf(buf, n, "--set fluid.cfl=%.6g", 0.5 * s->fluid->prm.cfl);
    } else {
        snprintf(buf, n, "--set ... (a smaller step)");
    }
}
