/* porenet.h — pore-network reduced fluid model (DEM–PFV, pore-scale finite
 * volume; Catalano 2012, Chareyre et al. 2012; docs/theory.md "Pore network").
 *
 * One pressure per pore of the regular (weighted Delaunay, weights r²)
 * triangulation of the sphere centres; fluxes q = k (p_i − p_j) through the
 * triangular facets with the hydraulic-radius conductance k = α A R_h²/(μ L)
 * (thesis eq. 3.3–3.5); pore mass balance Σ_j q_ij = −dV_i/dt (3.2); fluid
 * forces on the spheres from the pore pressures (3.10, 3.13–3.14, with the
 * drag along the flow: project decision 10).
 *
 * Three stages, each behind a small interface:
 *   pn_triangulate   regular triangulation of the spheres and their images
 *                    (periodic copies, mirror copies across walls) — CGAL's
 *                    Regular_triangulation_3 or qhull's 4-D lift (triangulate.c)
 *   pn_network_build pores (tetrahedra with coincident power centres merged),
 *                    throats, geometry, conductances, force coefficients
 *                    (network.c)
 *   pn_solver_*      the sparse SPD system: CHOLMOD factorised once per
 *                    triangulation and back-substituted each step, or
 *                    Jacobi-preconditioned CG (solve.c)
 *
 * Boundaries: an axis is either periodic or bounded by two walls.  A wall is
 * represented by the mirror images of the spheres near it: the power bisector
 * of a sphere and its image is exactly the wall plane, so no sphere's power
 * cell crosses it and the pores whose power centre lies ON the plane are the
 * boundary pores, symmetric about it.  Only the part inside the box counts:
 * weight ½ per wall plane through the pore (¼ on an edge, ⅛ at a corner), the
 * same for the throats (docs/theory.md).  This is an exact symmetry (slip)
 * wall with no huge "infinite sphere" weights in the lifted coordinates
 * (catalano_pfv.md §5.3 option 3).  No-slip walls add the wall area inside the
 * throat to its wetted perimeter γ.
 *
 * Everything is replicated: every rank holds the whole network and computes
 * the same numbers (the DEM is replicated too).
 */
#ifndef IBMDEM_PORENET_H
#define IBMDEM_PORENET_H

#include <hdf5.h>
#include <stddef.h>

/* Flow boundary condition of a wall face (face f = 2*axis + side, side 0 = lo). */
typedef enum { PN_BC_NOFLUX = 0, PN_BC_PRESSURE, PN_BC_FLUX } pn_bc_t;

typedef struct {
    double lo[3], hi[3];
    int periodic[3];    /* axis periodic (else two walls) */
    int noslip[6];      /* wall face is no-slip (else slip / symmetry) */
    pn_bc_t bc[6];      /* flow condition of each wall face */
    double bc_value[6]; /* PN_BC_PRESSURE: pressure (Pa); PN_BC_FLUX: volume flux INTO the domain (m³/s) */
    double grad[3];     /* periodic axes: imposed mean pressure gradient ∇p (Pa/m) */
    double clear_h;     /* > 0: pores whose power radius exceeds this (m), connected through such pores to the
                           outside of the packing, are clear fluid at the hydrostatic pressure
                           (dirichlet = PN_CLEAR; pn_tri_t.clear); 0: off (porenet.clear_fluid_radius) */
} pn_domain_t;

/* net->dirichlet of a clear-fluid pore (the other Dirichlet pores hold the face 0..5 of their value). */
#define PN_CLEAR 6

/* ---- regular triangulation (triangulate.c) ---------------------------------- */

typedef struct {
    /* Extended point set: the spheres and their images. */
    int npts;
    double *x;          /* 3*npts, positions */
    double *r;          /* radii */
    int *id;            /* index of the sphere in the input arrays */
    signed char *img;   /* 3*npts: per axis -1, 0, +1: periodic shift (× length) or mirror across lo / hi */
    double *xm, *xo;    /* 3*npts: the image as an affine map of its sphere's centre, x_img = xm x + xo
                           (xm = ±1; pn_tri_point, the pore volumes of every step) */
    /* Tetrahedra of the lower hull of the lifted points (all of them, images included). */
    int ntet;
    int *tet;           /* 4*ntet point indices */
    int *nbr;           /* 4*ntet: tetrahedron across the face opposite vertex k; -1: none (hull edge) */
    double *P;          /* 3*ntet power centres (orthocentres) */
    double *cond;       /* conditioning of each power-centre solve (|det| relative to the scale³; 0: hyperplane) */
    int *grp;           /* qhull facet the tetrahedron was split from (Qt: co-spherical set), or -1 */
    double margin;      /* width of the image layer */
    double margin_needed; /* the width the tetrahedra of the box need (≤ margin) */
    int n_flat;         /* lower facets whose tetrahedron is flat (power centre from the hyperplane) */
    unsigned char *clear; /* ntet: tetrahedron of the clear fluid (dom->clear_h): power radius above clear_h and
                             connected through such tetrahedra to the rim of the cloud (NULL: none) */
} pn_tri_t;

/* Regular triangulation of n spheres (x: 3n, r: n) in the domain.  Returns 0,
 * or -1 with a reason in err (a centre inside another sphere or outside the
 * box, qhull failure).  The image layer is `margin` wide (<= 0: 2.75 maximum
 * radii), widened when the tetrahedra of the box need more, up to 6 maximum
 * radii or `margin` (t->margin: the width used; t->margin_needed <= t->margin:
 * every pore of the box is exact). */
int pn_triangulate(const pn_domain_t *dom, int n, const double *x, const double *r, double margin, pn_tri_t *t,
                   char *err, size_t nerr);
/* The triangulation engine: CGAL's Regular_triangulation_3 (exact predicates;
 * the default, pn_triangulate) or qhull's 4-D lift (option Qt). */
typedef enum { PN_TRI_CGAL = 0, PN_TRI_QHULL } pn_tri_kind_t;
int pn_triangulate_with(const pn_domain_t *dom, int n, const double *x, const double *r, double margin,
                        pn_tri_kind_t kind, pn_tri_t *t, char *err, size_t nerr);
void pn_tri_free(pn_tri_t *t);
/* The clear fluid (clear.c): t->clear, the tetrahedra whose power radius exceeds
 * dom->clear_h connected through such tetrahedra to the rim of the cloud (left
 * NULL when dom->clear_h is 0; pn_triangulate calls it). */
void pn_mark_clear(const pn_domain_t *dom, pn_tri_t *t);
/* The pore (of np, their power centres cP + 3 root[k]) nearest to point P
 * brought into the box along the periodic axes, pore `skip` excluded (clear.c). */
int pn_nearest_pore(const pn_domain_t *dom, const double *cP, const int *root, int np, int skip, const double P[3]);
/* Position of extended point `p` for sphere positions x (images follow their sphere). */
void pn_tri_point(const pn_domain_t *dom, const pn_tri_t *t, const double *x, int p, double out[3]);

/* ---- pore network (network.c) ------------------------------------------------- */

/* Conductance of the throats lying in a wall plane (between two pores on the
 * same wall; docs/theory.md "Pore network", wall throats). */
typedef enum {
    PN_WALL_MIRROR = 0, /* each facet of the mirrored set its own throat, weight ½ per plane: exact symmetry */
    PN_WALL_YADE        /* YADE FlowEngine (slipBoundary): the facets between two wall pores merged into one
                           throat (the in-box half of the mirrored set), R_h × 2^(-1/4) per slip wall plane */
} pn_wall_model_t;

typedef struct {
    double alpha;     /* conductance factor α (thesis: ½) */
    double mu;        /* dynamic viscosity (Pa s) */
    pn_wall_model_t wall_model;
} pn_params_t;

typedef struct {
    int npore;
    double *P;        /* 3*npore: pore node (power centre) */
    double *w;        /* fraction of the pore inside the box (1, ½, ¼, ⅛) */
    double *vol;      /* volume inside the box */
    double *vvoid;    /* void volume inside the box */
    int *face;        /* wall face the pore lies on (the first one; -1: interior) */
    int *dirichlet;   /* face with an imposed pressure the pore lies on, -1: none */
    int *faces;       /* bit f set: the pore lies on wall face f */
    double *sect;     /* 3*npore: −Σ w S_f over the pore's throats (outward): the area vector of its
                         section(s) with the wall plane(s), pointing out of the box (0 inside) */
    double *bc_area;  /* area of the pore's section with its first wall face (PN_BC_FLUX shares) */
    int *ntets, *tets;/* tetrahedra of each pore: tets[ntets[i] .. ntets[i+1]-1] (CSR) */
    int *tetv;        /* 4 per entry of tets: its extended points, contiguous (pn_pore_volumes) */
    int nthroat;
    int *tp;          /* 2*nthroat: pores i, j (q > 0 from i to j) */
    double *dx;       /* 3*nthroat: P_j(image) − P_i (the periodic image of j when across a periodic face) */
    double *k;        /* weighted conductance w_f α A R_h²/(μ L) */
    double *wt;       /* throat weight w_f */
    double *area;     /* fluid area A of the facet */
    double *rh;       /* hydraulic radius */
    double *len;      /* L = |P_i P_j| */
    int *fv;          /* 3*nthroat: extended points of the facet */
    double *nrm;      /* 3*nthroat: unit normal of the facet, from P_i to P_j */
    double *fsec;     /* 3*nthroat: w_f × sector area ½r²θ of each vertex (pressure force 3.10) */
    double *fvis;     /* 3*nthroat: w_f × A γ_k/γ of each vertex (viscous force 3.13–3.14) */
    int *wallf;       /* no-slip wall face in the throat (its share of the viscous force), -1 */
    int *fsph;        /* 3*nthroat: sphere of each vertex of the facet */
    double *fdir;     /* 9*nthroat: force on that sphere per unit pressure jump, (fsec + fvis) n,
                         reflected for a mirror image (pn_forces without its parts) */
    /* statistics */
    double void_sum, solid_area_sum; /* Σ w φ_ij, Σ w γ_ij (partition checks) */
    double box_volume, solid_volume; /* box volume; Σ (4/3)π r³ of the spheres */
    int n_negative_area;             /* facets whose fluid area was ≤ 0 (overlaps) */
    int n_seam;                      /* with the clear fluid: neighbours across a periodic face that are no pore of
                                        the box (a period narrower than the image layer the pores need), taken
                                        as the pore of the box nearest to their power centre */
} pn_net_t;

/* Build the network of a triangulation for sphere positions x / radii r.  0; -2 when a pore of
 * the box reaches the rim of the point cloud (the image layer is too narrow), -1 otherwise. */
int pn_network_build(const pn_domain_t *dom, const pn_params_t *prm, const pn_tri_t *t, const double *x,
                     const double *r, int n, pn_net_t *net, char *err, size_t nerr);
void pn_network_free(pn_net_t *net);
/* Volume of each pore inside the box for positions x (same topology): for the
 * rate of change of the pore volumes as the spheres move. */
void pn_pore_volumes(const pn_domain_t *dom, const pn_tri_t *t, const pn_net_t *net, const double *x, double *vol);

/* ---- linear system and solve (solve.c) ------------------------------------------ */

typedef enum { PN_SOLVER_CHOLMOD = 0, PN_SOLVER_PCG } pn_solver_kind_t;

typedef struct pn_solver pn_solver_t;

/* Assemble G (and factorise it with CHOLMOD) for the network's boundary
 * conditions.  Unknowns are the pores without an imposed pressure; when no
 * pressure is imposed anywhere, pore 0 is held at 0 (the pressure is then
 * defined up to a constant).  Returns NULL with err on failure. */
pn_solver_t *pn_solver_create(const pn_domain_t *dom, const pn_net_t *net, pn_solver_kind_t kind, double pcg_tol,
                              char *err, size_t nerr);
/* The same with a choice of the fill-reducing ordering of CHOLMOD: METIS
 * (pn_solver_create), or geometric nested dissection of the pores' positions
 * (ordering.c: cheaper to compute, more fill; for a system solved once). */
typedef enum { PN_ORDER_METIS = 0, PN_ORDER_GEOMETRIC } pn_ordering_t;
pn_solver_t *pn_solver_create_ordered(const pn_domain_t *dom, const pn_net_t *net, pn_solver_kind_t kind,
                                      pn_ordering_t ordering, double pcg_tol, char *err, size_t nerr);
void pn_solver_free(pn_solver_t *s);
/* Pressures (p: npore) for pore volume rates dvdt (npore, NULL: zero, rigid
 * skeleton) and the domain's boundary values.  Returns 0, or -1 if PCG did not
 * converge. */
int pn_solve(pn_solver_t *s, const pn_domain_t *dom, const pn_net_t *net, const double *dvdt, double *p);
/* The unknowns' values of the last solve (the PCG's starting guess of the
 * next one) set from pore pressures p (a restart continues as the run). */
void pn_solver_set_solution(pn_solver_t *s, const double *p, int npore);
/* Iterations of the last PCG solve (0 for CHOLMOD); time of the factorisation. */
int pn_solver_iterations(const pn_solver_t *s);
double pn_solver_factor_time(const pn_solver_t *s);

/* Pressure difference p_i − p_j across throat f, periodic mean gradient included. */
double pn_throat_dp(const pn_domain_t *dom, const pn_net_t *net, const double *p, int f);

/* Flux through each wall face INTO the domain (6 values, m³/s), from the pores
 * on that face. */
void pn_face_fluxes(const pn_domain_t *dom, const pn_net_t *net, const double *p, double q[6]);
/* Mean superficial velocity ⟨U⟩ = (1/V) Σ_f q_f (P_j − P_i) (periodic permeability). */
void pn_mean_velocity(const pn_domain_t *dom, const pn_net_t *net, const double *p, double U[3]);

/* Force of the fluid on each wall face (6×3): the pore pressures on the
 * sections of the wall pores, plus the viscous share of no-slip walls.  With
 * the forces on the spheres it satisfies Σ F_spheres + Σ F_faces = 0 exactly
 * (the faces with imposed pressure included: they stand for the reservoirs). */
void pn_face_forces(const pn_domain_t *dom, const pn_net_t *net, const double *p, double F[6][3]);

/* Fluid force on each sphere (3n, overwritten): pressure (3.10) + viscous
 * (3.13–3.14, along the flow).  fp / fv (may be NULL): the two parts (both
 * or neither; without them the sum comes from the precomputed net->fdir, equal
 * to round-off).  Torque is zero: every part acts through the centre. */
void pn_forces(const pn_domain_t *dom, const pn_tri_t *t, const pn_net_t *net, const double *p, int n, double *f,
               double *fp, double *fv);

/* ---- the model: triangulation + network + solver, as used in a run (model.c) ---- */

typedef struct {
    pn_domain_t dom;
    pn_params_t prm;
    pn_solver_kind_t kind;
    pn_tri_kind_t tri_kind; /* porenet.triangulation */
    pn_ordering_t ordering; /* porenet.ordering (auto resolved: geometric for a fixed packing) */
    double pcg_tol;
    double eps_retri;   /* re-triangulate when Σ_steps max_i |ΔV_i/V_i| exceeds this (thesis 5.13–5.14); 0: every step */
    double margin;      /* image layer (0: auto) */
    int margin_warned;  /* warned once: 1 the given margin was widened, 2 some pores need more than the widest */
    double margin_used; /* the width of the last triangulation (the next one starts from it) */
    double clear_radius; /* porenet.clear_fluid_radius: dom.clear_h in mean diameters of the spheres (0: off) */
    double rho_f;       /* fluid density (Reynolds number, buoyancy) */
    int n;
    pn_tri_t tri;
    pn_net_t net;
    pn_solver_t *sol;
    int built;
    double *p, *vol, *vol_prev, *dvdt, *x_prev;
    int vol_current;    /* vol holds the pore volumes at x_prev on the current topology (the next step's start) */
    double *f, *fp, *fv; /* fp, fv: filled by pn_write_snapshot only */
    double *x_cont;     /* previous positions continuous with the current ones (periodic unwrapping) */
    double *x_tri;      /* 3n: the positions the current triangulation was built from (exact restarts) */
    double *xid, *rid;  /* DEM coupling: positions / radii in the order of the particle ids (couple.c) */
    double dt_factor;   /* ζ of the coupled time step (thesis 4.21) */
    int dem_steps;      /* DEM steps per coupled step (multi-rate), within ζ Δt_{M−V} */
    double eps_acc;     /* accumulated pore strain since the last triangulation */
    long n_retri, n_steps;
    /* re-meshing statistics: over the rebuilds of a run that replaced a triangulation, the sum and
     * the smallest of the fraction of the new triangulation's tetrahedra of the box (power centre
     * inside) that the one it replaced had (same spheres, same images) */
    long kept_count;
    double kept_sum, kept_min;
    /* CPU times of the process (cputime(): the machine may be shared): last triangulation / network /
     * factorisation, cumulated rebuilds (all three), volume rates, solves (right-hand side and
     * back-substitution) and forces */
    double t_tri, t_net, t_factor, t_rebuild, t_solve, t_force, t_vol;
    double *snap_time;  /* times of the snapshots written (output.c) */
    long *snap_counts;  /* points, tetrahedra, throats, spheres of each snapshot */
    int nsnap;
    char err[512];
} pn_model_t;

/* Keys of [porenet] (config.c) and the domain of a case file. */
void porenet_register_keys(void);
struct cfg;
void pn_model_from_config(struct cfg *cfg, pn_model_t *m);

/* Build the network for positions x and radii r (n spheres); 0 or -1 (m->err). */
int pn_model_rebuild(pn_model_t *m, int n, const double *x, const double *r);
/* One coupled step: the spheres moved from the previous call's positions to
 * x during dt (dt <= 0 or first call: rigid skeleton, no volume change).
 * Re-triangulates when due, solves, computes m->f.  0 or -1 (m->err). */
int pn_model_step(pn_model_t *m, int n, const double *x, const double *r, double dt);
/* The pore whose tetrahedra hold point y at the positions of the last step
 * (a point of the box; its periodic copies and mirror images across the walls
 * are tried too): the pressure there
 * is m->p of that pore (pressure probes); PN_CLEAR_AT (with the clear fluid
 * on): a tetrahedron of the clear fluid that is no pore of the box, or no
 * tetrahedron (beyond the cloud of spheres and images): hydrostatic; -1: none. */
#define PN_CLEAR_AT (-2)
int pn_model_pore_at(const pn_model_t *m, const double y[3]);
void pn_model_free(pn_model_t *m);
/* The model's exact state in an HDF5 group of a checkpoint (state.c): the
 * positions of the last triangulation, the previous positions and pore
 * volumes, the strain accumulated since the triangulation, the pressures,
 * the forces and the snapshot index.  pn_model_state_read rebuilds the
 * triangulation from the saved positions (the same network and
 * factorisation) and restores the rest, so that the next step is the one of
 * the run that wrote it; r: the radii (n spheres, in the model's order).
 * 0, or -1 with m->err. */
int pn_model_state_write(const pn_model_t *m, hid_t group);
int pn_model_state_read(pn_model_t *m, hid_t group, int n, const double *r);

/* ---- coupling with the DEM engine (couple.c) ------------------------------------- */

struct dem;
/* One coupled step after the DEM moved during dt (thesis fig. 4.3, 5.9):
 * gathers the particle positions in the order of their ids (the DEM reorders
 * its arrays), steps the model (pore volume rates from the motion, solve,
 * forces) and writes the fluid force plus the buoyancy −ρ_f V g of the
 * hydrostatic part into dem_ext_force() (the pore pressures are excess
 * pressures; the model's forces act through the centres: zero torque).
 * dt <= 0: rigid skeleton (the initial state).  0 or -1 (m->err). */
int pn_model_couple_dem(pn_model_t *m, struct dem *d, const double g[3], double dt);
/* The fluid force of the last step (m->f) plus the buoyancy −ρ_f V g into
 * dem_ext_force() (the second half of pn_model_couple_dem; a restart applies
 * the saved forces with it). */
void pn_model_apply_forces(const pn_model_t *m, struct dem *d, const double g[3]);
/* m->xid, m->rid: the DEM's positions and radii in the order of the
 * particle ids (the first half of pn_model_couple_dem). */
void pn_model_gather(pn_model_t *m, const struct dem *d);
/* Time-step limit of the coupled problem, ζ · min_k Δt_{M−V} with the viscous
 * limit of each mobile particle Δt_{M−V} = π ρ_k d_k²/(1200 μ) = M_k/(200 μ d_k)
 * (thesis 4.19–4.22, β = 400 calibrated for d_max/d_min ≤ 10). */
double pn_coupled_dt(const pn_model_t *m, const struct dem *d);
/* The coupled step of a run: porenet.dem_steps DEM steps, at most the limit
 * pn_coupled_dt (docs/theory.md §8, multi-rate coupling). */
double pn_coupled_step(const pn_model_t *m, const struct dem *d);

/* Permeability along axis a: imposed-pressure faces on both ends of a
 * walled axis (κ = μ Q L/(ΔP S)), or a mean gradient on a periodic axis
 * (κ = −μ ⟨U_a⟩/∂_a p).  NAN when the case has neither. */
double pn_model_permeability(const pn_model_t *m, int a);

/* Validity of the model (catalano_pfv.md §5.1): pore Reynolds number
 * ρ_f u d/μ with u = max |q|/A, smallest r / mean r, porosity.  Returns the
 * number of warnings written into buf (one line each). */
int pn_model_validity(const pn_model_t *m, const double *r, char *buf, size_t nbuf, double *re, double *size_ratio,
                      double *porosity);

/* Output (output.c, rank 0, plain HDF5): the tetrahedra of the pores (with
 * pore pressure), the throats (segments P_i P_j with flux) and the spheres
 * (fluid force) in DIR/porenet_NNNNN.h5 (NNNNN = m->nsnap), indexed by
 * DIR/porenet.xmf (XDMF 2, unstructured grids ParaView opens).  The
 * tetrahedra are those of the pores, the halves of the wall pores outside the
 * box included (each carries its pore's pressure). */
void pn_write_snapshot(pn_model_t *m, const double *x, const char *dir, double time);
/* Rank 0: rewrite DIR/porenet.xmf for the snapshots listed in m (a restart). */
void pn_write_index(const pn_model_t *m, const char *dir);

#endif
