/* r2r.h — FFTW's real-to-real kinds of the Poisson solver computed from
 * complex DFTs (private to src/poisson).
 *
 * FFTW computes its r2r kinds (and its r2c when the default, estimating
 * planner chooses) with scalar codelets; its complex DFTs run with SIMD
 * codelets.  These plans give the same numbers as fftw_plan_guru_r2r of one
 * dimension (same kind, same unnormalised scaling, to round-off) for the
 * kinds the solver uses, through one complex DFT per one or two lines and
 * O(n) passes before and after (r2r.c).  A kind or length they do not cover
 * returns NULL, and the caller keeps FFTW's r2r. */
#ifndef IBMDEM_POISSON_R2R_H
#define IBMDEM_POISSON_R2R_H

#include <fftw3.h>

typedef struct r2r_plan r2r_plan_t;

/* A plan for `kind` along n points with the FFTW planner flags `flags`
 * (its complex plans are made with them, so a measuring planner measures
 * them and wisdom records them); NULL if not covered. */
r2r_plan_t *r2r_plan_make(fftw_r2r_kind kind, int n, unsigned flags);

/* The transform of the lines (a, b), 0 ≤ a < h0, 0 ≤ b < h1: input line at
 * in + a·id0 + b·id1 with element stride is, output likewise (od0, od1,
 * os), as fftw_plan_guru_r2r with one dimension {n, is, os} and the loops
 * {h0, id0, od0}, {h1, id1, od1}.  in and out may be the same array (each
 * line is read before it is written); other lines must not overlap. */
void r2r_plan_exec(r2r_plan_t *p, const double *in, long is, double *out, long os, int h0, long id0, long od0,
                   int h1, long id1, long od1);

void r2r_plan_destroy(r2r_plan_t *p);

#endif
