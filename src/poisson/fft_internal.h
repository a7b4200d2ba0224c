/* fft_internal.h — the FFT solver's data (fft_t) and the functions its files
 * share: fft.c (set-up, solve, the solve by planes), fft_plan.c (transform
 * kinds, FFTW plans, the plane transforms of the fast path), fft_butterfly.c
 * (the cosine coefficients from the 2-D DFT), fft_tridiag.c (the tridiagonal
 * solves in x), fft_wisdom.c (reproducible measured plans).  The method is
 * described at the top of fft.c. */
#ifndef IBMDEM_FFT_INTERNAL_H
#define IBMDEM_FFT_INTERNAL_H

#include <fftw3.h>
#include <mpi.h>

#include "poisson.h"
#include "r2r.h"

/* Modes per block of the tridiagonal sweep: the block's data, c' and the
 * Sherman–Morrison vector are n_x × MODE_BLOCK doubles each (in cache). */
#define MODE_BLOCK 512

typedef struct {
    int m;                     /* transform length (unknowns) */
    int periodic, neumann;     /* the BC pair is periodic / Neumann–Neumann */
    fftw_r2r_kind fwd, inv;    /* real kinds (periodic: R2HC/HC2R) */
    double norm;               /* forward+inverse scale factor of the r2r kinds */
    double *eig;               /* eigenvalues of c δ² (≤ 0) by transform index, m of them */
} tf_dir_t;

/* One batched transform of the pipeline (an FFTW guru plan). */
typedef enum { TK_R2R, TK_R2C, TK_C2R, TK_C2C } tkind_t;
typedef enum { SIDE_FIELD, SIDE_WORK } side_t;
typedef struct {
    tkind_t kind;
    int sign;                  /* TK_C2C: FFTW_FORWARD or FFTW_BACKWARD */
    fftw_r2r_kind rk;          /* TK_R2R (rank 1) */
    int rank;
    fftw_iodim dims[2];        /* transformed dimensions (strides in units of each side's type) */
    int nhow;
    fftw_iodim how[2];         /* loops: x planes, then rows or columns */
    side_t in, out;
    fftw_plan plan[2];         /* per alignment class of the field pointer */
    r2r_plan_t *cr;            /* TK_R2R: the kind from complex DFTs (r2r.h), used instead of plan */
} step_t;

typedef struct {
    poisson_t *p;
    int dim3;                  /* a z transform exists */
    int nx, ny, nz;            /* unknowns in x (global), y, z */
    int nxu;                   /* local unknown x planes */
    int periodic_x;
    tf_dir_t dy, dz;
    double scale;              /* 1 / (forward+inverse factor) */
    unsigned plan_flags;       /* planner of the set-up plans */
    unsigned lazy_flags;       /* planner of a plan made at the first solve (fft_step_run) */

    /* transformed data of one x plane: TR rows (y modes) of TC doubles (z
     * modes; re/im interleaved when z, or y in 2-D, is periodic); in the
     * work array a row starts every RS doubles and a plane every PS */
    int TR, TC;
    long RS, PS;
    step_t fwd[2], inv[2];     /* forward: [0] then [1]; inverse: [0] then [1] */
    int nsteps;
    /* fast path: a 2-D DFT per x plane, with Makhoul reordering of the
     * Neumann directions */
    int fast, ynn, znn, reord; /* reord = ynn || znn */
    int fused;                 /* butterflies applied inside the tridiagonal sweeps (one rank) */
    double *wy, *wz;           /* twiddles e^{−iπk/2N} (re, im) */
    /* fast path: the 2-D transforms run plane by plane on a (reordered)
     * copy of the plane (pbuf, in cache) */
    double *pbuf;
    fftw_plan pfwd, pinv;
    /* nz even: the plane's r2c as a complex DFT of length nz/2 of each row
     * (even and odd values as real and imaginary parts), a split pass, and
     * the complex DFT of the columns (plane_r2c); c2r in reverse */
    int half;
    fftw_plan prow_f, prow_b, pcol_f, pcol_b;
    double *tw;                /* W^k = e^{−2πik/nz}, k = 0 … nz/2 (re, im) */
    unsigned char *fwd_ready;  /* plane i already forward-transformed (poisson_forward_plane) */

    /* decomposition of the rows among ranks (P > 1) */
    int P, me;
    int *j0, *nyl, *nxu_r, *scount, *sdispl, *rcount, *rdispl;
    double *work;              /* transformed data in the slab layout */
    double *recv;              /* transposed data (P > 1) */

    /* view of the data for the tridiagonal solves: element (i, row, col) at
     * tbuf[toff[i] + row * trs[i] + col], eigenvalue erow[row] + ecol[col] */
    double *tbuf;
    long *toff, *trs;
    int trows, tcols;
    double *erow, *ecol;
    int nzero, zcol[4];        /* columns of row 0 with eigenvalue 0 (singular modes) */
    double *wx;                /* compatibility weights in x (singular problems) */

    double *cp, *zs, *gam;     /* scratch of one block */
    int *rowlist;              /* rows of one block */
    double *zero_sol;          /* solutions of the singular modes (nzero × nx) */
} fft_t;


/* transform kinds and plans (fft_plan.c) */
void fft_plane_transform(fft_t *t, double *f, int inverse, int i);
void fft_plane_transforms(fft_t *t, double *f, int inverse);
void fft_plans_destroy(fft_t *t);
void fft_plans_make(fft_t *t, int a);
void fft_setup_steps(fft_t *t);
void fft_step_run(fft_t *t, step_t *s, double *f);
void fft_direction_setup(tf_dir_t *t, ebc_t lo, ebc_t hi, int ncell, double c);

/* the fast path's butterflies (fft_butterfly.c) */
void fft_bf_apply(const fft_t *t, double *p, double *q, int n, int c0, int k1, int inverse);
void fft_fast_butterfly(fft_t *t, int inverse);

/* the tridiagonal solves in x (fft_tridiag.c) */
void fft_tridiagonal_solves(fft_t *t, double lambda);

/* FFTW wisdom (fft_wisdom.c) */
void fft_wisdom_merge(MPI_Comm comm);
void fft_wisdom_start(const char *path, MPI_Comm comm);
void fft_wisdom_write(MPI_Comm comm);

#endif
