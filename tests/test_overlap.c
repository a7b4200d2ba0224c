/* test_overlap.c — the overlap search of the input checks (overlap.h)
 * against brute force, and the number reader of the case file.
 * RANKS: 1
 */
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "overlap.h"
#include "testutil.h"

/* The first overlapping pair (smallest i, then j) by looking at every pair. */
static int brute(const overlap_box_t *b, int n, const double *x, const double *r, const unsigned char *act,
                 double frac, int *pi, int *pj)
{
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++) {
            if (act && !act[i] && !act[j]) continue;
            double d2 = 0;
            for (int a = 0; a < b->dim; a++) {
                double e = x[3 * j + a] - x[3 * i + a];
                if (b->periodic[a]) e -= b->L[a] * round(e / b->L[a]);
                d2 += e * e;
            }
            if (r[i] + r[j] - sqrt(d2) > frac * 2 * fmin(r[i], r[j])) {
                *pi = i;
                *pj = j;
                return 1;
            }
        }
    return 0;
}

/* Random boxes, periodic or not in each direction, 2-D and 3-D, sparse and
 * dense, polydisperse (one sphere per scene may be much larger), a mask of
 * active spheres or none: the cell search finds exactly the pair brute force
 * finds, across the periodic faces too, with fewer than three cells along a
 * direction and with many. */
static void test_against_brute_force(void **state)
{
    (void)state;
    srand(12345);
    int agree = 0, found = 0, scenes = 600;
    for (int s = 0; s < scenes; s++) {
        overlap_box_t b = {.dim = s % 3 == 0 ? 2 : 3};
        for (int a = 0; a < 3; a++) {
            b.lo[a] = -1.0 + (double)rand() / RAND_MAX;
            b.L[a] = 1.0 + 4.0 * rand() / RAND_MAX;
            b.periodic[a] = rand() % 2;
        }
        const int n = 2 + rand() % 200;
        const double rmean = 0.005 + 0.06 * rand() / RAND_MAX;
        double *x = malloc(3 * sizeof(double) * n), *r = malloc(sizeof(double) * n);
        unsigned char *act = malloc(n);
        for (int i = 0; i < n; i++) {
            for (int a = 0; a < 3; a++) x[3 * i + a] = b.lo[a] + b.L[a] * rand() / RAND_MAX;
            r[i] = rmean * (0.5 + (double)rand() / RAND_MAX);
            act[i] = rand() % 3 != 0;
        }
        if (s % 5 == 0) r[rand() % n] = 0.4 * b.L[0]; /* one large sphere: few cells */
        if (s % 7 == 0) memcpy(&x[3 * (n - 1)], &x[0], 3 * sizeof(double)); /* two at the same centre */
        const double frac = (s % 4) * 0.05;
        const unsigned char *mask = s % 2 ? act : NULL;
        int i1 = -1, j1 = -1, i2 = -1, j2 = -1;
        double depth;
        const int f1 = overlap_find(&b, n, x, r, mask, frac, &i1, &j1, &depth);
        const int f2 = brute(&b, n, x, r, mask, frac, &i2, &j2);
        agree += f1 == f2 && (!f1 || (i1 == i2 && j1 == j2));
        found += f2;
        free(x);
        free(r);
        free(act);
    }
    print_message("  %d of %d scenes: the same first pair as brute force (%d scenes with an overlap)\n", agree, scenes,
                  found);
    assert_int_equal(agree, scenes);
    assert_true(found > scenes / 4 && found < scenes); /* both outcomes are exercised */
}

/* Numbers of the case file: decimal only, finite. */
static void test_numbers(void **state)
{
    (void)state;
    static const char *good[] = {"1", "-2.5", "+3", ".5", "5.", "1e3", "1E-3", " 7 ", "1.7e+308", "1e-400"};
    static const char *bad[] = {"0x10", "0X1p3", "inf", "-inf", "nan", "Infinity", "1e999", "1e", "e5", ".", "-",
                                "1 2", "1,5", "", "+-1", "1..2", "0x", "1e+"};
    double v;
    for (size_t k = 0; k < sizeof good / sizeof *good; k++) assert_true(cfg_parse_real(good[k], &v));
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        if (cfg_parse_real(bad[k], &v)) print_message("  '%s' was read as %g\n", bad[k], v);
        assert_false(cfg_parse_real(bad[k], &v));
    }
    assert_true(cfg_parse_real("1e-400", &v) && v == 0.0); /* below the smallest double: 0 */
}

/* UTF-8: the valid forms, and what is not (overlong, surrogates, past U+10FFFF, cut). */
static void test_utf8(void **state)
{
    (void)state;
    assert_int_equal(cfg_utf8_char("a", 1), 1);
    assert_int_equal(cfg_utf8_char("\xc3\xa9", 2), 2);
    assert_int_equal(cfg_utf8_char("\xe2\x82\xac", 3), 3);
    assert_int_equal(cfg_utf8_char("\xf0\x9f\x99\x82", 4), 4);
    assert_int_equal(cfg_utf8_char("\xe9", 1), 0);
    assert_int_equal(cfg_utf8_char("\xc3", 1), 0);
    assert_int_equal(cfg_utf8_char("\xc0\xaf", 2), 0);
    assert_int_equal(cfg_utf8_char("\xed\xa0\x80", 3), 0);
    assert_int_equal(cfg_utf8_char("\xf4\x90\x80\x80", 4), 0);
    assert_int_equal(cfg_utf8_char("\xff", 1), 0);
    assert_int_equal(cfg_utf8_char("\x80", 1), 0);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_brute_force),
        cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_utf8),
    };
    TEST_MPI_RUN("overlap", tests);
}
