/* ibm_internal.h — private state of the immersed boundary, shared by the
 * files of src/ibm/ only (the interface is include/ibm.h). */
#ifndef IBMDEM_IBM_INTERNAL_H
#define IBMDEM_IBM_INTERNAL_H

#include <stdint.h>

#include "ibm.h"

/* A run of consecutive nodes of one velocity component inside the band
 * or the interior of sphere p, along the fastest storage direction (z in
 * 3-D, y in 2-D): node q = 0..len−1 is at storage index m0 + q·stride, at
 * offset r0 + q·h_run e_run from the sphere's centre (periodic image
 * applied), with solid fraction alpha[a0 + q], and is the forced node
 * u0 + q of the merged lists below.  A sphere + band is convex, so a grid
 * line meets it in one segment (two if a periodic face cuts it).  The runs
 * of all spheres are kept in storage order (by grid line, then m0, then
 * sphere), so that every pass over them streams through the velocity field
 * and the α array instead of jumping from sphere to sphere. */
typedef struct {
    double r0[3];
    int32_t m0;     /* G_IDX of the first node */
    int32_t a0;     /* index of its α in the alpha array */
    int32_t u0;     /* index of its first node among the forced nodes */
    int32_t line;   /* grid line in its plane (component, x index): the y index in 3-D, 0 in 2-D */
    int32_t p;      /* sphere */
    int16_t len;
    uint8_t c;      /* velocity component */
} ibm_run_t;

/* A run of forced nodes: the union of the spheres' runs on one grid line
 * that overlap or touch, each node once (node q = 0..len−1 at storage
 * index m0 + q·stride is forced node n0 + q). */
typedef struct {
    int32_t m0, n0, len;
    uint8_t c;
} ibm_node_run_t;

typedef struct {
    int n;
    double *t;      /* n times */
    double *v;      /* n × 6: u, v, w, ωx, ωy, ωz */
} ibm_history_t;

/* Per-sphere sums reduced over the ranks. */
enum { IBM_FIMP = 0, IBM_TIMP = 3, IBM_MOM = 6, IBM_ANG = 9, IBM_NSUM = 12 };

typedef struct {
    /* runs of all spheres in storage order */
    ibm_run_t *runs;
    long nruns, cap_runs;
    double *alpha;
    long nalpha, cap_alpha, nshared; /* nshared: entries at nodes that another sphere's band reaches */
    int rdir;          /* run direction (2 in 3-D, 1 in 2-D), its stride and spacing */
    long rstride;
    double rstep;
    /* the forced nodes (each node once, whatever the number of spheres
     * whose band reaches it), by runs along the grid lines; per node:
     * Σ_p α_p, the target velocity Σ_p (α_p/Σα) U_p(r) of the forcing, and
     * the forcing impulse accumulated since the target was set */
    ibm_node_run_t *nruns_f;
    long n_nruns, cap_nruns;
    double *node_asum, *node_target, *node_imp;
    long nnodes, cap_nodes;
    /* scratch of the build, one plane at a time (alpha.c): the runs as
     * generated, the first of each grid line's runs among the sorted ones,
     * the forced node of each node entry (entry_node) and the number of spheres
     * at each node (cnt) */
    ibm_run_t *tmp;
    long ntmp, cap_tmp;
    int32_t *entry_node, *line_head, *cnt;
    long cap_entry_node, cap_cnt;
    int built;         /* node lists exist */
    int targets_valid; /* node_target was set from these node lists and the velocities in target_vel */
    double *target_vel; /* n × 6: u, ω of each sphere towards which node_target forces */
    int frozen;        /* this step: no sphere moves within it (forcing.c) */
    int stage_first;   /* this stage's forcing stores the impulses, not adds them (set_targets) */
    long *plane_nrun;  /* dim × (nxl + 1): first node run of each (component, local x plane) */
    /* control volume of each unknown by local x index (−1..nxl), times 2π
     * in axisymmetric geometry: the integrals are over the whole volume */
    double *vol[3];
    double *hcell[3];  /* cell size h of the unknowns by local x index (see alpha.c) */
    /* per-sphere sums: forcing impulse ∫f dV Δt_k and its moment, fluid
     * momentum ∫α u dV and angular momentum ∫α r × u dV */
    double *sum;       /* n × IBM_NSUM, this rank, then reduced */
    double *mom_prev;  /* n × 6: momentum and angular momentum at the end of the last stage (reduced) */
    double *imp_step;  /* n × 6: Σ over the stages of the hydrodynamic impulse (force and torque × Δt_k) */
    double t_step;     /* Σ Δt_k of the stages so far in this step */
    double t_stage0;   /* fluid time at the start of the step */
    int nhist;
    ibm_history_t *hist;
    /* radius_correction = gaps: the neighbours of each sphere (the other
     * spheres and the periodic images of all, itself included) whose surface
     * may come within IBM_GAP_CUTOFF_D diameters of its band: nb[nb_head[p]
     * .. nb_head[p + 1]), each the offset of the neighbour's centre from
     * sphere p's, its radius and the distance from p's centre to its
     * surface (x, y, z, R, |x| − R: IBM_NB_STRIDE doubles), in increasing
     * order of that distance; built with the node lists */
    int32_t *nb_head;
    double *nb;
    long cap_nb;
} ibm_priv_t;

#define IBM_NB_STRIDE 5 /* doubles per entry of ibm_priv_t.nb */

static inline ibm_priv_t *ibm_priv(const ibm_t *ibm) { return (ibm_priv_t *)ibm->priv; }

/* alpha_gaps.c (radius_correction = gaps) */
/* The neighbour lists nb_head, nb at the centres xa (a cell list, O(N)). */
void ibm_gap_neighbours(ibm_t *ibm);
/* The local thickening (length) of sphere p's forced radius at offset r
 * from its centre, cell size h. */
double ibm_gap_extra(const ibm_t *ibm, int p, const double r[3], double h);

/* alpha.c */
/* First global index whose node coordinate is >= x along a non-periodic x
 * (c: component, -1 for cell centres). */
int ibm_lower_index(const grid_t *g, int c, double x);
/* The node lists at the current centres xa, with, in the same pass, the
 * targets of the forcing (targets != 0) and the momentum integrals into
 * mom (not NULL; see ibm_sums_of). */
void ibm_build_nodes(ibm_t *ibm, double *mom, int targets);
/* The band's half-width in cells with the case's band_width (alpha.c). */
static inline double ibm_band(const ibm_t *ibm) { return ibm_band_halfwidth() * ibm->prm.band_width; }
/* Local x index of storage index m. */
static inline int ibm_node_i(const grid_t *g, long m) { return (int)(m / g->sx) - 1; }
/* Rigid-body velocity component c at offset r of a sphere moving with
 * v = (u, ω). */
static inline double ibm_rigid_velocity(const double v[6], int c, const double r[3])
{
    const double *w = v + 3; /* v: u, ω */
    switch (c) {
    case 0: return v[0] + w[1] * r[2] - w[2] * r[1];
    case 1: return v[1] + w[2] * r[0] - w[0] * r[2];
    default: return v[2] + w[0] * r[1] - w[1] * r[0];
    }
}
/* forcing.c */
/* ∫ α_p u dV and ∫ α_p r × u dV of every sphere into sum_all (n × IBM_NSUM, IBM_MOM..IBM_ANG+2). */
void ibm_momentum(ibm_t *ibm, double *sum_all);
/* The per-sphere sums over the runs r0 .. r1−1 added to sum_all (n ×
 * IBM_NSUM): the shares of the forcing impulses (impulses) and the momentum
 * integrals (momentum); ibm_sums_zero() clears them first. */
void ibm_sums_zero(ibm_t *ibm, double *sum_all, int impulses, int momentum);
void ibm_sums_of(ibm_t *ibm, double *sum_all, long r0, long r1, int impulses, int momentum);
/* The targets Ū of the nodes n0 .. n1−1 from the runs r0 .. r1−1 that
 * cover them, from the spheres' velocities recorded by ibm_targets_note(). */
void ibm_targets_note(ibm_t *ibm);
void ibm_targets_of(ibm_t *ibm, long r0, long r1, long n0, long n1);
void ibm_stage_begin(fluid_t *f, int stage, double dt_stage, void *ctx);
void ibm_force_plane(fluid_t *f, double *const ustar[3], int stage, double dt_stage, int i, void *ctx);
void ibm_stage_force(fluid_t *f, int stage, double dt_stage, void *ctx);
void ibm_stage_end(fluid_t *f, int stage, double dt_stage, void *ctx);

#endif
