/* fft.c — TEMPORARY placeholder, replaced by the FFT solver. */
#include "poisson.h"
#include "util.h"
static void *c(poisson_t *p) { (void)p; return NULL; }
static int s(poisson_t *p, void *i, double l, const double *b, double *x) { die("fft solver not implemented yet"); }
static void d(void *i) { (void)i; }
const poisson_backend_t poisson_backend_fft = {c, s, d};
