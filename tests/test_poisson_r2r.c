/* test_poisson_r2r.c — the r2r kinds of the Poisson solver computed from
 * complex DFTs (src/poisson/r2r.c) against FFTW's own r2r plans: every kind
 * the solver uses, even and odd lengths (those a family does not cover must
 * be refused), several lines in two loops with non-unit strides, out of
 * place and in place.
 * RANKS: 1
 *
 * Tolerance: both compute the same unnormalised transform with O(log n)
 * rounding stages, so they agree to a few ε·log₂n relative to max|Y|
 * (measured ≤ 4.4e-16 for n ≤ 880); 1e-13 leaves a wide margin, while a wrong
 * twiddle, sign, order or pairing of lines gives O(1). */
#include <stdlib.h>
#include <string.h>

#include "../src/poisson/r2r.h"
#include "testutil.h"

#define TOL 1e-13

static const fftw_r2r_kind kinds[] = {FFTW_REDFT10, FFTW_REDFT01, FFTW_RODFT10, FFTW_RODFT01,
                                      FFTW_REDFT11, FFTW_RODFT11, FFTW_RODFT00};
static const char *kind_name[] = {"REDFT10", "REDFT01", "RODFT10", "RODFT01", "REDFT11", "RODFT11", "RODFT00"};

/* Relative max difference between r2r.c and FFTW on h0 × h1 lines of n
 * points (element strides is, os; line strides from them), or −1 if r2r.c
 * refuses the kind and length. */
static double compare(int q, int n, int h0, int h1, int in_place)
{
    const long is = 2, os = in_place ? 2 : 3;
    const long id1 = (long)n * is + 1, id0 = h1 * id1 + 3;
    const long od1 = in_place ? id1 : (long)n * os + 2, od0 = in_place ? id0 : h1 * od1 + 5;
    long nin = h0 * id0 + 8, nout = h0 * od0 + 8;
    double *x = fftw_alloc_real(nin), *y = fftw_alloc_real(nout), *ref = fftw_alloc_real(nout),
           *tmp = fftw_alloc_real(nin);
    for (long m = 0; m < nin; m++) x[m] = sin(0.37 * m + 0.1) + 0.25 * cos(1.3 * m);
    for (long m = 0; m < nout; m++) y[m] = ref[m] = 0.0;
    r2r_plan_t *p = r2r_plan_make(kinds[q], n, FFTW_ESTIMATE);
    if (!p) {
        fftw_free(x), fftw_free(y), fftw_free(ref), fftw_free(tmp);
        return -1.0;
    }
    fftw_iodim d = {n, (int)is, (int)os}, h[2] = {{h0, (int)id0, (int)od0}, {h1, (int)id1, (int)od1}};
    memcpy(tmp, x, nin * sizeof(double));
    fftw_plan f = fftw_plan_guru_r2r(1, &d, 2, h, tmp, in_place ? tmp : ref, &kinds[q], FFTW_ESTIMATE);
    memcpy(tmp, x, nin * sizeof(double));
    fftw_execute(f);
    if (in_place) memcpy(ref, tmp, nin * sizeof(double));
    if (in_place) {
        memcpy(y, x, nin * sizeof(double));
        r2r_plan_exec(p, y, is, y, os, h0, id0, od0, h1, id1, od1);
    } else
        r2r_plan_exec(p, x, is, y, os, h0, id0, od0, h1, id1, od1);
    double err = 0.0, big = 0.0;
    for (int a = 0; a < h0; a++)
        for (int b = 0; b < h1; b++)
            for (int k = 0; k < n; k++) {
                long m = a * od0 + b * od1 + k * os;
                err = fmax(err, fabs(y[m] - ref[m]));
                big = fmax(big, fabs(ref[m]));
            }
    fftw_destroy_plan(f);
    r2r_plan_destroy(p);
    fftw_free(x), fftw_free(y), fftw_free(ref), fftw_free(tmp);
    return err / big;
}

static void test_against_fftw(void **state)
{
    (void)state;
    const int lengths[] = {2, 3, 7, 8, 9, 16, 130, 879, 880};
    int nk = sizeof kinds / sizeof kinds[0], nn = sizeof lengths / sizeof lengths[0];
    for (int q = 0; q < nk; q++) {
        double worst = 0.0;
        int covered = 0;
        for (int l = 0; l < nn; l++) {
            int n = lengths[l];
            for (int ip = 0; ip < 2; ip++) {
                /* 5 × 3 lines: odd in total, so one complex DFT carries a single line */
                double e = compare(q, n, 5, 3, ip);
                int refused = e < 0.0;
                /* DCT-IV/DST-IV need an even n; the other kinds take every n ≥ 2 */
                int expect = (kinds[q] == FFTW_REDFT11 || kinds[q] == FFTW_RODFT11) && n % 2;
                assert_int_equal(refused, expect);
                if (refused) continue;
                covered++;
                worst = fmax(worst, e);
                if (e > TOL) print_error("  %s n = %d %s: relative difference %.2e\n", kind_name[q], n,
                                         ip ? "in place" : "out of place", e);
                assert_true(e <= TOL);
            }
        }
        print_message("  %s: %d cases, worst relative difference from FFTW's r2r %.2e\n", kind_name[q], covered,
                      worst);
    }
    assert_null(r2r_plan_make(FFTW_REDFT00, 16, FFTW_ESTIMATE)); /* not covered: FFTW's own */
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_fftw),
    };
    TEST_MPI_RUN("poisson_r2r", tests);
}
