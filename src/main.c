/* main.c — command line: ibmdem run|check CASE.ini, ibmdem --version. */
#include <fftw3.h>
#include <gsl/gsl_version.h>
#include <hdf5.h>
#include <mpi.h>
#include <stdio.h>
#include <string.h>

#include "config.h"
#include "grid.h"
#include "modules.h"
#include "poisson.h"
#include "util.h"

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

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    modules_register_keys();
    if (argc >= 2 && !strcmp(argv[1], "--version")) {
        print_version();
        MPI_Finalize();
        return 0;
    }
    if (argc >= 3 && !strcmp(argv[1], "check")) {
        cfg_t *cfg = cfg_load(argv[2], 0, NULL);
        if (!cfg) die("%s: invalid input", argv[2]);
        grid_t *g = grid_create_from_config(cfg, MPI_COMM_WORLD);
        poisson_opts_t po;
        poisson_opts_from_config(cfg, &po);
        if (mpi_rank() == 0) cfg_write_resolved(cfg, stdout);
        grid_free(g);
        cfg_free(cfg);
        MPI_Finalize();
        return 0;
    }
    msg("usage: ibmdem run CASE.ini [--set section.key=value]... [--out DIR] [--restart FILE]\n"
        "       ibmdem check CASE.ini [--set ...]\n"
        "       ibmdem --version\n");
    MPI_Finalize();
    return 1;
}
