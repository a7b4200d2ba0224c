/* main.c — the command line:
 *   ibmdem run CASE.ini [--set section.key=value]... [--out DIR] [--restart FILE]
 *   ibmdem check CASE.ini [--set section.key=value]...
 *   ibmdem keys          every case-file key as a Markdown table
 *   ibmdem --version
 * Exit status: 0 success, 1 run-time error, 2 bad input or usage, 3 the run
 * diverged (a checkpoint of its last good state was written). */
#include <fftw3.h>
#include <gsl/gsl_version.h>
#include <hdf5.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "modules.h"
#include "sim.h"
#include "util.h"

static const char *usage =
    "usage: ibmdem run CASE.ini [--set section.key=value]... [--out DIR] [--restart FILE]\n"
    "       ibmdem check CASE.ini [--set section.key=value]...\n"
    "       ibmdem keys\n"
    "       ibmdem --version\n"
    "Runs the same under mpirun -np N (nx must divide by N).  See docs/user-guide.md.\n";

static void print_version(void)
{
    unsigned maj, min, rel;
    H5get_libversion(&maj, &min, &rel);
    char mpiv[MPI_MAX_LIBRARY_VERSION_STRING];
    int len;
    MPI_Get_library_version(mpiv, &len);
    char *nl = strchr(mpiv, '\n');
    if (nl) *nl = 0;
    msg("ibmdem %s\n  FFTW %s\n  HDF5 %u.%u.%u\n  MPI  %s\n  GSL  %s\n", IBMDEM_VERSION, fftw_version, maj, min, rel,
        mpiv, GSL_VERSION);
}

/* Markdown cell text: '|' would end the cell. */
static void md(const char *s)
{
    for (; s && *s; s++) {
        if (*s == '|')
            fputs("\\|", stdout);
        else
            fputc(*s, stdout);
    }
}

static void print_keys(void)
{
    static const char *type_name[] = {"real", "integer", "boolean", "string", "choice", "3 reals"};
    printf("| section | key | type | default | range / choices | description |\n");
    printf("|---|---|---|---|---|---|\n");
    for (int i = 0; cfg_schema_at(i); i++) {
        const cfg_key_t *k = cfg_schema_at(i);
        printf("| `%s` | `%s` | %s | ", k->section, k->key, type_name[k->type]);
        if (k->def) {
            printf("`");
            md(k->def);
            printf("`");
        } else {
            static const char *need[] = {"**required**", "optional", "if needed"};
            printf("%s", need[k->need]);
        }
        printf(" | ");
        if (k->type == CFG_ENUM && k->choices) {
            for (const char *c = k->choices; *c; c++) {
                if (*c == '|')
                    printf(", ");
                else
                    fputc(*c, stdout);
            }
        } else if (k->min <= k->max && k->type != CFG_BOOL && k->type != CFG_STRING) {
            int lo = k->min > -1e299, hi = k->max < 1e299 && !(k->type == CFG_INT && k->max >= 2147483647);
            if (lo && hi)
                printf("[%.7g, %.7g]", k->min, k->max);
            else if (lo)
                printf("≥ %.7g", k->min);
            else if (hi)
                printf("≤ %.7g", k->max);
        }
        printf(" | ");
        md(k->help);
        printf(" |\n");
    }
}

static int usage_error(const char *fmt, const char *arg)
{
    if (mpi_rank() == 0) {
        fprintf(stderr, "ibmdem: ");
        fprintf(stderr, fmt, arg);
        fprintf(stderr, "\n%s", usage);
    }
    MPI_Finalize();
    return 2;
}

int main(int argc, char **argv)
{
#ifdef OPEN_MPI
    /* Open MPI's MPI-IO (OMPIO, under parallel HDF5) asks its shared-file-
     * pointer components about every file it opens; the "lockedfile" one
     * copies the file name into a 256-byte buffer, which a path of 245
     * characters or more overflows (Open MPI 4.1: the process aborts).
     * ibmdem never uses shared file pointers: that component is left out,
     * unless the user chose the components (then paths must stay shorter). */
    setenv("OMPI_MCA_sharedfp", "^lockedfile", 0);
#endif
    MPI_Init(&argc, &argv);
    modules_register_keys();
    const char *cmd = argc >= 2 ? argv[1] : "";
    if (!strcmp(cmd, "--version")) {
        print_version();
        MPI_Finalize();
        return 0;
    }
    if (!strcmp(cmd, "keys")) {
        if (mpi_rank() == 0) print_keys();
        MPI_Finalize();
        return 0;
    }
    if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        msg("%s", usage);
        MPI_Finalize();
        return 0;
    }
    int run = !strcmp(cmd, "run");
    if (!run && strcmp(cmd, "check") != 0) return usage_error("unknown command '%s'", cmd);

    /* CASE.ini and the options, in any order */
    const char *path = NULL, *restart = NULL, *out = NULL;
    char **sets = calloc((size_t)argc + 1, sizeof *sets);
    int nset = 0;
    for (int a = 2; a < argc; a++) {
        const char *o = argv[a];
        int has_next = a + 1 < argc;
        if (!strcmp(o, "--set")) {
            if (!has_next) return usage_error("%s needs section.key=value", o);
            sets[nset++] = argv[++a];
        } else if (run && !strcmp(o, "--out")) {
            if (!has_next) return usage_error("%s needs a folder", o);
            out = argv[++a];
        } else if (run && !strcmp(o, "--restart")) {
            if (!has_next) return usage_error("%s needs a checkpoint file", o);
            restart = argv[++a];
        } else if (o[0] == '-') {
            return usage_error("unknown option '%s'", o);
        } else if (path) {
            return usage_error("one case file only (extra argument '%s')", o);
        } else {
            path = o;
        }
    }
    if (!path) return usage_error("%s: missing CASE.ini", cmd);
    if (restart && strlen(restart) >= IO_PATH_MAX) {
        char lim[32];
        snprintf(lim, sizeof lim, "%d", IO_PATH_MAX - 1);
        return usage_error("--restart: a path longer than %s bytes", lim);
    }
    char *outset = NULL;
    if (out) {
        outset = malloc(strlen(out) + 16);
        sprintf(outset, "output.dir=%s", out);
        sets[nset++] = outset; /* last: wins over the file and other --set */
    }

    cfg_t *cfg = cfg_load(path, nset, sets);
    free(outset);
    if (!cfg) {
        /* the messages are printed; every rank parsed the same input */
        MPI_Finalize();
        return 2;
    }
    sim_t *s = sim_create(cfg, restart, !run);
    int status = 0;
    if (run) {
        sim_set_command(s, argc, argv);
        status = sim_run(s);
    } else if (mpi_rank() == 0) {
        cfg_write_resolved(cfg, stdout);
        printf("; check: valid on %d rank%s\n", mpi_size(), mpi_size() > 1 ? "s" : "");
    }
    sim_free(s);
    cfg_free(cfg);
    free(sets);
    mpi_finish(status);
}
