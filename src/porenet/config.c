/* config.c — case-file keys of the pore-network model ([porenet]) and the
 * domain it reads from [domain] (length, origin). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "config.h"
#include "porenet.h"

#define BIG 1e300
#define FACE_KEYS(F)                                                                                            \
    {"porenet", F, CFG_ENUM, "slip", 1, 0, "periodic|slip|noslip",                                              \
     "face " F ": periodic (both faces of the axis), slip (symmetry) wall or no-slip wall"},                     \
        {"porenet", F "_flow", CFG_ENUM, "noflux", 1, 0, "noflux|pressure|flux",                                \
         "flow condition of wall face " F ": impermeable, imposed pressure, or imposed flux"},                  \
        {"porenet", F "_value", CFG_DOUBLE, "0", -BIG, BIG, NULL,                                               \
         "face " F ": the imposed pressure (Pa, relative to hydrostatic) or volume flux into the domain (m^3/s)"}

static const cfg_key_t porenet_keys[] = {
    {"porenet", "viscosity", CFG_DOUBLE, NULL, 1e-300, BIG, NULL, "dynamic viscosity of the fluid mu (Pa s)"},
    {"porenet", "fluid_density", CFG_DOUBLE, "1000", 0, BIG, NULL,
     "fluid density (kg/m^3): buoyancy and the pore Reynolds number"},
    {"porenet", "alpha", CFG_DOUBLE, "0.5", 1e-6, 1e6, NULL,
     "conductance factor alpha in g = alpha A R_h^2/mu (Catalano eq. 3.4; 1/2: Hagen-Poiseuille analogy)"},
    {"porenet", "wall_throats", CFG_ENUM, "mirror", 1, 0, "mirror|yade",
     "conductance of the throats in a wall plane: mirror (exact symmetry) or yade (YADE FlowEngine's model: one "
     "merged throat per pore pair, R_h x 2^-1/4 per slip wall; for comparisons with YADE; slip walls only)"},
    {"porenet", "solver", CFG_ENUM, "cholmod", 1, 0, "cholmod|pcg",
     "pore-pressure system: CHOLMOD Cholesky (factorised once per triangulation) or Jacobi-preconditioned CG"},
    {"porenet", "pcg_tol", CFG_DOUBLE, "1e-10", 1e-16, 1e-2, NULL, "pcg: relative residual at which CG stops"},
    {"porenet", "retriangulate", CFG_DOUBLE, "0.01", 0, 10, NULL,
     "re-triangulate when the accumulated largest pore volume strain exceeds this (thesis 5.13-5.14); 0: every step"},
    {"porenet", "dt_factor", CFG_DOUBLE, "0.8", 1e-6, 1, NULL,
     "with DEM particles: time step = dt_factor x the viscous limit pi rho d^2/(1200 mu) (thesis 4.20-4.22)"},
    {"porenet", "dem_steps", CFG_INT, "1", 1, 1000, NULL,
     "with DEM particles: DEM steps per coupled step (multi-rate: the pressures are solved and the fluid forces "
     "updated every dem_steps DEM steps); the coupled step stays within dt_factor x the viscous limit"},
    {"porenet", "triangulation", CFG_ENUM, "cgal", 1, 0, "cgal|qhull",
     "regular triangulation: CGAL's Regular_triangulation_3 (exact predicates) or qhull's 4-D lift (Qt)"},
    {"porenet", "ordering", CFG_ENUM, "auto", 1, 0, "auto|metis|geometric",
     "cholmod: fill-reducing ordering: metis, or geometric nested dissection of the pores (a fifth of METIS's time, "
     "1.5x the fill: for a system solved once); auto: geometric for a fixed packing, metis with DEM particles "
     "(many back-substitutions per factorisation)"},
    {"porenet", "snapshots", CFG_ENUM, "auto", 1, 0, "auto|on|off",
     "network snapshots (porenet_NNNNN.h5 + porenet.xmf, at the run's snapshot times): auto = with DEM particles "
     "only (a fixed packing is solved once: its results are in summary.json), on, off"},
    {"porenet", "margin", CFG_DOUBLE, "0", 0, BIG, NULL,
     "width of the layer of sphere images across the faces (m); 0: 2.75 largest radii; widened (with a warning "
     "when given) to what the pores of the box need: a narrower layer would lose or change pores"},
    {"porenet", "clear_fluid_radius", CFG_DOUBLE, "0", 0, 100, NULL,
     "pores of the clear fluid outside a packing that does not fill the box: a pore whose power radius exceeds "
     "this many mean diameters holds the hydrostatic pressure (a reservoir: excess pressure 0); 0: off (every "
     "pore is solved for)"},
    {"porenet", "packing", CFG_STRING, NULL, 1, 0, NULL,
     "fixed packing when the scene has no DEM particles ([particles]): text (x y z r per line, # comments) "
     "or HDF5 (.h5: datasets position [n][3] and radius, the layout of ibm.spheres_file)", CFG_CONDITIONAL},
    {"porenet", "gradient", CFG_VEC3, "0 0 0", -BIG, BIG, NULL,
     "mean pressure gradient imposed along the periodic axes (Pa/m)"},
    FACE_KEYS("x_lo"), FACE_KEYS("x_hi"), FACE_KEYS("y_lo"), FACE_KEYS("y_hi"), FACE_KEYS("z_lo"), FACE_KEYS("z_hi"),
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void porenet_register_keys(void) { cfg_schema_add(porenet_keys); }

void pn_model_from_config(cfg_t *cfg, pn_model_t *m)
{
    static const char *fn[6] = {"x_lo", "x_hi", "y_lo", "y_hi", "z_lo", "z_hi"};
    memset(m, 0, sizeof *m);
    double L[3], o[3];
    cfg_vec3(cfg, "domain", "length", L);
    cfg_vec3(cfg, "domain", "origin", o);
    for (int a = 0; a < 3; a++) {
        m->dom.lo[a] = o[a];
        m->dom.hi[a] = o[a] + L[a];
    }
    for (int f = 0; f < 6; f++) {
        char k[32];
        int kind = cfg_enum(cfg, "porenet", fn[f]);
        int a = f / 2;
        if (f % 2 == 1 && (kind == 0) != m->dom.periodic[a])
            cfg_fail(cfg, "porenet", fn[f], "must be periodic exactly when %s is", fn[f - 1]);
        m->dom.periodic[a] = kind == 0;
        m->dom.noslip[f] = kind == 2;
        snprintf(k, sizeof k, "%s_flow", fn[f]);
        m->dom.bc[f] = (pn_bc_t)cfg_enum(cfg, "porenet", k);
        if (kind == 0 && m->dom.bc[f] != PN_BC_NOFLUX)
            cfg_fail(cfg, "porenet", k, "a periodic face has no flow condition (use porenet.gradient)");
        snprintf(k, sizeof k, "%s_value", fn[f]);
        m->dom.bc_value[f] = cfg_double(cfg, "porenet", k);
    }
    double g[3];
    cfg_vec3(cfg, "porenet", "gradient", g);
    for (int a = 0; a < 3; a++) {
        if (g[a] != 0 && !m->dom.periodic[a])
            cfg_fail(cfg, "porenet", "gradient", "component %c is not zero but the axis is not periodic", 'x' + a);
        m->dom.grad[a] = g[a];
    }
    m->prm.mu = cfg_double(cfg, "porenet", "viscosity");
    m->prm.alpha = cfg_double(cfg, "porenet", "alpha");
    m->prm.wall_model = cfg_enum(cfg, "porenet", "wall_throats") == 1 ? PN_WALL_YADE : PN_WALL_MIRROR;
    /* YADE's wall throats are its slip walls (slipBoundary): with a no-slip
     * wall they conduct more than with a slip one, which cannot be
     * (docs/theory.md, porenet.wall_throats) */
    for (int f = 0; f < 6; f++)
        if (m->prm.wall_model == PN_WALL_YADE && m->dom.noslip[f])
            cfg_fail(cfg, "porenet", "wall_throats",
                     "yade reproduces YADE's slip walls only, and face %s is noslip: its wall throats would conduct "
                     "more than slip ones (use mirror, whose no-slip walls add their area to the wetted perimeter)",
                     fn[f]);
    m->rho_f = cfg_double(cfg, "porenet", "fluid_density");
    m->kind = cfg_enum(cfg, "porenet", "solver") == 0 ? PN_SOLVER_CHOLMOD : PN_SOLVER_PCG;
    m->tri_kind = cfg_enum(cfg, "porenet", "triangulation") == 0 ? PN_TRI_CGAL : PN_TRI_QHULL;
    const int ord = cfg_enum(cfg, "porenet", "ordering");
    /* auto: a fixed packing (no DEM particles) is factorised for one solve */
    const int dem = cfg_has_section(cfg, "particles") && cfg_enum(cfg, "particles", "source") != 0;
    m->ordering = ord == 2 || (ord == 0 && !dem) ? PN_ORDER_GEOMETRIC : PN_ORDER_METIS;
    m->pcg_tol = cfg_double(cfg, "porenet", "pcg_tol");
    m->eps_retri = cfg_double(cfg, "porenet", "retriangulate");
    m->margin = cfg_double(cfg, "porenet", "margin");
    m->clear_radius = cfg_double(cfg, "porenet", "clear_fluid_radius");
    m->dt_factor = cfg_double(cfg, "porenet", "dt_factor");
    m->dem_steps = cfg_int(cfg, "porenet", "dem_steps");
}
