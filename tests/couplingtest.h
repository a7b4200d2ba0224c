/* couplingtest.h — helpers of the coupling's unit tests (test_coupling_*.c):
 * a DEM built from a case-file text, and the immersed boundary reduced to
 * its spheres (the coupling reads only their velocities, force and torque). */
#ifndef IBMDEM_COUPLINGTEST_H
#define IBMDEM_COUPLINGTEST_H

#include <stdlib.h>

#include "dem.h"
#include "ibm.h"
#include "testutil.h"
#include "util.h"

static inline dem_t *test_dem_from_text(const char *text)
{
    cfg_t *cfg = cfg_load_string("test.ini", text, 0, NULL);
    assert_non_null(cfg);
    return dem_create_from_config(cfg, MPI_COMM_WORLD);
}

/* n spheres at rest, no force: only ibm->n and ibm->s are set */
static inline ibm_t *test_fake_ibm(int n)
{
    ibm_t *ibm = xcalloc(1, sizeof *ibm);
    ibm->n = n;
    ibm->s = xcalloc((size_t)n, sizeof *ibm->s);
    return ibm;
}

static inline void test_free_ibm(ibm_t *ibm)
{
    free(ibm->s);
    free(ibm);
}

#endif
