/* ibm_internal.h — private state of the immersed boundary, shared by the
 * files of src/ibm/ only (the interface is include/ibm.h). */
#ifndef IBMDEM_IBM_INTERNAL_H
#define IBMDEM_IBM_INTERNAL_H

#include <stdint.h>

#include "ibm.h"

/* One (sphere, velocity node) pair with α > 0 on this rank. */
typedef struct {
    double alpha;
    int32_t m;      /* G_IDX of the node in the component's field */
    uint8_t c;      /* velocity component */
    int8_t img[3];  /* periodic image: the node seen by this sphere is at
                     * its stored position + img[d] L[d] */
} ibm_node_t;

typedef struct {
    int n;
    double *t;      /* n times */
    double *v;      /* n × 6: u, v, w, ωx, ωy, ωz */
} ibm_history_t;

/* Per-sphere sums reduced over the ranks. */
enum { IBM_FIMP = 0, IBM_TIMP = 3, IBM_MOM = 6, IBM_ANG = 9, IBM_NSUM = 12 };

typedef struct {
    /* node lists: sphere p owns nodes[start[p] .. start[p+1]) */
    ibm_node_t *nodes;
    long nnodes, cap;
    long *start;
    /* dense scratch of each component: Σ_p α_p, then Σ_p α_p U_p and the
     * impulse of the forcing (zero outside the node lists between uses) */
    double *asum[3], *aux[3];
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
} ibm_priv_t;

static inline ibm_priv_t *ibm_priv(const ibm_t *ibm) { return (ibm_priv_t *)ibm->priv; }

/* alpha.c */
void ibm_build_nodes(ibm_t *ibm);
/* Position of the node of entry e relative to the centre of sphere p. */
void ibm_node_offset(const ibm_t *ibm, const ibm_node_t *e, const ibm_sphere_t *s, double r[3]);
/* Rigid-body velocity component c of sphere s at offset r. */
static inline double ibm_rigid_velocity(const ibm_sphere_t *s, int c, const double r[3])
{
    switch (c) {
    case 0: return s->u[0] + s->omega[1] * r[2] - s->omega[2] * r[1];
    case 1: return s->u[1] + s->omega[2] * r[0] - s->omega[0] * r[2];
    default: return s->u[2] + s->omega[0] * r[1] - s->omega[1] * r[0];
    }
}
/* forcing.c */
void ibm_momentum(ibm_t *ibm, double *out6);
void ibm_stage_force(fluid_t *f, int stage, double dt_stage, void *ctx);
void ibm_stage_end(fluid_t *f, int stage, double dt_stage, void *ctx);

#endif
