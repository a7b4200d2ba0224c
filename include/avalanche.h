/* avalanche.h — the measurements of a granular flow down a rough inclined
 * plane (Izard 2014 ch. 4; ../shared/reference/izard_ch4_ch5.md §2, §3.1–3.3):
 * the flow rate, the bed height and compacity, the profiles across the bed
 * averaged over the two periodic directions and a time window, the fluid's
 * velocity fluctuations, the force balance, and the dimensionless numbers of
 * the regime map.  docs/theory.md §10 gives the definitions.
 *
 * The grains' profiles come from the particles: each sphere's volume is cut
 * exactly by the horizontal slabs (bins) of the profile, so ⟨U⟩_g is the
 * α-weighted velocity of the thesis (eq. 4.8) and φ(z) its solid fraction,
 * whatever the fluid model.  The fluid's come from the resolved fluid, weighted
 * by (1 − α) at the cell centres.  Sums are time integrals (Σ value × Δt) over
 * the averaging window, identical on every rank, so a checkpoint holds them
 * whole and a restart continues them exactly.
 */
#ifndef IBMDEM_AVALANCHE_H
#define IBMDEM_AVALANCHE_H

#include <hdf5.h>

#include "dem.h"
#include "fluid.h"
#include "ibm.h"

/* Instantaneous values of one step (series.csv columns, AV_NCOL of them). */
enum {
    AV_Q = 0,     /* Q_g = (1/L) Σ V_p u_p·e_s over the mobile grains (m³/s) */
    AV_H,         /* h_g: bed height above the bed plane (m) */
    AV_PHI,       /* global compacity: mobile solid volume in [D/2, h_g − D/2] over that volume */
    AV_U,         /* mean downslope velocity of the mobile grains (volume-weighted, m/s) */
    AV_ST_MEAN,   /* mean particle Stokes number ρ_p/(9η) ⟨|u_p| D_p⟩ (Izard eq. 4.17) */
    AV_FC_PAIR,   /* contact force, mean norm per contact (N) */
    AV_FLUB_PAIR, /* normal lubrication force, mean norm per lubricated pair (N) */
    AV_FC_GRAIN,  /* contact force, mean norm of the resultant per mobile grain (N) */
    AV_FLUB_GRAIN,/* lubrication force, the same (N) */
    AV_FH_GRAIN,  /* hydrodynamic force, the same (N) */
    AV_NCOL
};

typedef struct {
    /* geometry: the bed's normal axis, the downslope axis, the bed plane */
    int an, as;
    double z0, zmax;        /* bed plane and top of the domain along an */
    double Ls, area;        /* downslope length, area of the bed plane */
    double bin;             /* profile slab height */
    int nbin;
    /* the scene's numbers */
    double D, rho_p, rho, eta, g, sin_theta;
    double St, r, Ar, Tv, Ti, Tff; /* Izard §4.1.1 and eq. 4.1 */
    /* averaging window */
    double t1, t2;
    /* time integrals over the window (Σ x Δt), identical on every rank */
    double tw, tw_fluid;
    double scal[AV_NCOL];
    double *grain;          /* per bin: V, V u_x, V u_y, V u_z   (4 nbin) */
    double *fluid;          /* per bin: W, W u_i (3), W u_i u_j (xx yy zz xy xz yz)  (10 nbin), W = (1 − α) dV */
    /* the last step's values */
    double now[AV_NCOL];
    double *work;           /* scratch: grid field of the resolved fluid's α */
    double *scratch;        /* scratch: 10 nbin (a step's slab sums) + 2 nbin (φ and its D average) */
} avalanche_t;

/* Set the geometry and numbers (rho, eta of the fluid; g the gravity vector
 * of the flow) from the particles; bin <= 0: D/5. */
void avalanche_init(avalanche_t *a, const dem_t *d, int normal_axis, double bed_plane, double zmax,
                    const double L[3], const double g[3], double rho, double eta, double bin, double t1,
                    double t2);
void avalanche_free(avalanche_t *a);

/* The values of the step just done (a->now), from the particles, the DEM's
 * force statistics (fs) and the hydrodynamic force of each particle (Fh:
 * 3 per particle id, NULL: none); accumulated over the window if the step
 * [t − dt, t] lies in it. */
void avalanche_sample_grains(avalanche_t *a, dem_t *d, const dem_force_stats_t *fs, const double *Fh, double t,
                             double dt);
/* The fluid's profiles of the step (collective); accumulated if in the window. */
void avalanche_sample_fluid(avalanche_t *a, const fluid_t *f, const ibm_t *ibm, double t, double dt);

/* Results over the window (0 when it holds no step). */
double avalanche_mean(const avalanche_t *a, int col);
/* Flow time T = V_g/Q̄_g with V_g = L W h̄_g (eq. 4.12, as printed: it grows with L). */
double avalanche_flow_time(const avalanche_t *a);

/* Rank 0: the profiles over the window into path (CSV), whole or not at all. */
int avalanche_write_profiles(const avalanche_t *a, const char *path);

/* The sums, exactly (checkpoints). */
void avalanche_state_write(const avalanche_t *a, hid_t g);
int avalanche_state_read(avalanche_t *a, hid_t g);
/* Copy of the sums (rollback). */
void avalanche_copy_sums(avalanche_t *dst, const avalanche_t *src);

#endif
