/* testutil.h — shared by the cmocka test programs.
 *
 * Every test program runs under mpirun with the rank counts listed on a line
 * "RANKS: 1 2" in its source (tests/run.sh reads it).  Only rank 0 writes
 * cmocka's report; assertions must be on globally reduced quantities so that
 * every rank takes the same branch (no rank may wait in a collective for one
 * that failed). */
#ifndef IBMDEM_TESTUTIL_H
#define IBMDEM_TESTUTIL_H

#include <math.h>
#include <mpi.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <cmocka.h>

static inline void test_mpi_init(int *argc, char ***argv)
{
    MPI_Init(argc, argv);
    int r;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    /* rank 0 reports; assertions are on global values, so it sees every failure */
    if (r != 0 && (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))) perror("freopen");
}

/* Run a cmocka group and finalise MPI; the exit code is the failure count
 * seen by any rank. */
#define TEST_MPI_RUN(name, tests)                                                   \
    do {                                                                            \
        int fails_ = _cmocka_run_group_tests(name, tests, sizeof(tests) / sizeof((tests)[0]), NULL, NULL); \
        int all_;                                                                   \
        MPI_Allreduce(&fails_, &all_, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);         \
        MPI_Finalize();                                                             \
        return all_;                                                                \
    } while (0)

/* Observed order of convergence between two resolutions. */
static inline double conv_order(double e_coarse, double e_fine, double h_ratio)
{
    return log(e_coarse / e_fine) / log(h_ratio);
}

#endif
