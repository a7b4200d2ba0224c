/* dem_config.c — case-file keys of the DEM and the construction of a scene
 * from them: domain, contact law, walls, particles, rough bed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "io.h"
#include "util.h"

#define BIG 1e300

#define USER_WALL_KEYS(N)                                                                                         \
    {"walls", "wall" #N "_point", CFG_VEC3, NULL, -BIG, BIG, NULL, "a point of extra wall " #N " (m)", CFG_OPTIONAL},          \
        {"walls", "wall" #N "_normal", CFG_VEC3, NULL, -BIG, BIG, NULL,                                           \
         "normal of extra wall " #N ", pointing to the particles' side", CFG_OPTIONAL},                                         \
        {"walls", "wall" #N "_velocity", CFG_VEC3, "0 0 0", -BIG, BIG, NULL, "velocity of extra wall " #N " (m/s)"}, \
        {"walls", "wall" #N "_remove_time", CFG_DOUBLE, "-1", -1, BIG, NULL,                                      \
         "time at which extra wall " #N " is removed (s; -1: never), e.g. the gate of a column collapse"},        \
        {"walls", "wall" #N "_force", CFG_DOUBLE, "0", 0, BIG, NULL,                                              \
         "load-controlled extra wall " #N " (a piston): force pushing it along its normal (N); needs wall" #N     \
         "_mass"},                                                                                                \
        {"walls", "wall" #N "_mass", CFG_DOUBLE, "0", 0, BIG, NULL,                                               \
         "mass of the load-controlled extra wall " #N " (kg; 0: the wall follows wall" #N "_velocity); at least " \
         "the mass of the grains it touches, for the DEM time step"}

static const cfg_key_t dem_keys[] = {
    /* [particles] */
#define PARTICLE_KEY(N)                                                                                         \
    {"particles", "particle" #N, CFG_STRING, NULL, 1, 0, NULL,                                                   \
     "source = list: one particle, tagged values in any order: center X Y Z; radius R (or diameter D); "          \
     "density RHO (default particles.density); velocity U V W; omega WX WY WZ; fixed. "                           \
     "Example: center 0 10 0 diameter 1 density 8", CFG_CONDITIONAL}
    PARTICLE_KEY(1), PARTICLE_KEY(2), PARTICLE_KEY(3), PARTICLE_KEY(4), PARTICLE_KEY(5), PARTICLE_KEY(6),
    PARTICLE_KEY(7), PARTICLE_KEY(8), PARTICLE_KEY(9),
    {"particles", "source", CFG_ENUM, "none", 1, 0, "none|insert|file|lammps_data|list",
     "where the particles come from: none (added by a program), random insertion, an HDF5 packing or "
     "checkpoint (file), a LAMMPS data file (lammps_data)"},
    {"particles", "file", CFG_STRING, NULL, 1, 0, NULL,
     "HDF5 packing, DEM checkpoint or particle snapshot (particles_NNNNNN.h5), or LAMMPS data file to read; its "
     "particles are the state at t = 0 of the run", CFG_CONDITIONAL},
    {"particles", "count", CFG_INT, "0", 0, 2e9, NULL, "insert: number of particles (or give volume_fraction)"},
    {"particles", "volume_fraction", CFG_DOUBLE, "0", 0, 0.45, NULL,
     "insert: solid volume fraction of the insertion region (random sequential insertion jams near 0.38)"},
    {"particles", "radius", CFG_DOUBLE, NULL, 1e-12, BIG, NULL, "insert: mean radius (m)", CFG_CONDITIONAL},
    {"particles", "polydispersity", CFG_DOUBLE, "0", 0, 0.9, NULL,
     "insert: radii uniform in [R(1-p), R(1+p)] with R = radius"},
    {"particles", "density", CFG_DOUBLE, "2500", 1e-12, BIG, NULL, "particle density (kg/m^3)"},
    {"particles", "region_lo", CFG_VEC3, NULL, -BIG, BIG, NULL, "insert: low corner of the region (default: domain)", CFG_OPTIONAL},
    {"particles", "region_hi", CFG_VEC3, NULL, -BIG, BIG, NULL, "insert: high corner of the region (default: domain)", CFG_OPTIONAL},
    {"particles", "seed", CFG_INT, "1", 0, 2147483647, NULL, "insert: random seed"},
    {"particles", "velocity", CFG_VEC3, "0 0 0", -BIG, BIG, NULL, "insert: initial velocity (m/s)"},
    {"particles", "velocity_spread", CFG_DOUBLE, "0", 0, BIG, NULL,
     "insert: each velocity component gets a uniform random part in [-s, s] (m/s)"},
    /* [contact] */
    {"contact", "law", CFG_ENUM, "linear", 1, 0, dem_contact_law_choices,
     "contact law: linear spring-dashpot (seed) or Hertz-Mindlin"},
    {"contact", "parameters", CFG_ENUM, "restitution", 1, 0, "restitution|stiffness",
     "linear: constants from restitution and contact_time (per pair effective mass), or kn and gamma_n given"},
    {"contact", "restitution", CFG_DOUBLE, NULL, 1e-6, 1, NULL, "dry restitution coefficient e_dry"},
    {"contact", "contact_time", CFG_DOUBLE, NULL, 1e-15, BIG, NULL, "linear: contact duration t_c (s)", CFG_CONDITIONAL},
    {"contact", "calibration", CFG_ENUM, "clipped", 1, 0, "clipped|seed",
     "linear: k_n, gamma_n such that the clipped law gives exactly e_dry and t_c (clipped), or eq. 3.16-3.17 "
     "of the seed (exact for the unclipped law)"},
    {"contact", "normal_clip", CFG_BOOL, "true", 1, 0, NULL, "normal force clipped at zero (no attraction)"},
    {"contact", "spring_kink", CFG_ENUM, "energy", 1, 0, "energy|plain",
     "linear: first and last step of a contact weighted so that velocity Verlet keeps the energy across the kink "
     "of k_n max(delta, 0) (docs/theory.md 7.7; unclipped or undamped contacts); plain: no weight"},
    {"contact", "kn", CFG_DOUBLE, NULL, 0, BIG, NULL, "linear, parameters = stiffness: normal stiffness (N/m)", CFG_CONDITIONAL},
    {"contact", "gamma_n", CFG_DOUBLE, "0", 0, BIG, NULL,
     "linear, parameters = stiffness: normal damping per unit effective mass (1/s)"},
    {"contact", "kt_ratio", CFG_DOUBLE, "0.2", 0, 10, NULL, "linear: tangential/normal stiffness ratio k_t/k_n"},
    {"contact", "friction", CFG_DOUBLE, NULL, 0, 1e6, NULL, "Coulomb friction coefficient mu_c (particle-particle)"},
    {"contact", "wall_friction", CFG_DOUBLE, "-1", -1, 1e6, NULL, "particle-wall friction (-1: the same as friction)"},
    {"contact", "rolling_friction", CFG_DOUBLE, "0", 0, 10, NULL,
     "constant-torque rolling resistance mu_r (torque mu_r R* F_n), 0: off"},
    {"contact", "youngs_modulus", CFG_DOUBLE, NULL, 1e-6, BIG, NULL, "hertz_mindlin: Young's modulus E (Pa)", CFG_CONDITIONAL},
    {"contact", "poisson_ratio", CFG_DOUBLE, "0.3", 0, 0.499, NULL, "hertz_mindlin: Poisson ratio"},
    {"contact", "reference_velocity", CFG_DOUBLE, "1", 1e-12, BIG, NULL,
     "hertz_mindlin: impact velocity of the contact time used for the time step (m/s)"},
    /* [walls] */
    {"walls", "faces", CFG_STRING, "auto", 1, 0, NULL,
     "planar walls on the domain faces: auto (every non-periodic face), none, or a list such as 'x_lo z_lo'"},
    USER_WALL_KEYS(1), USER_WALL_KEYS(2), USER_WALL_KEYS(3), USER_WALL_KEYS(4), USER_WALL_KEYS(5),
    USER_WALL_KEYS(6),
    /* [bed] */
    {"bed", "type", CFG_ENUM, "none", 1, 0, "none|random|hexagonal|dense",
     "rough bed of fixed half-grains with centres on a plane: random (2-D random insertion), hexagonal, or dense "
     "(random discs pushed apart until none overlaps: a disordered monolayer up to coverage ~0.8)"},
    {"bed", "axis", CFG_ENUM, "z", 1, 0, "x|y|z", "normal of the bed plane"},
    {"bed", "position", CFG_DOUBLE, "0", -BIG, BIG, NULL, "coordinate of the bed grains' centres along axis (m)"},
    {"bed", "radius", CFG_DOUBLE, NULL, 1e-12, BIG, NULL, "mean radius of the bed grains (m)", CFG_CONDITIONAL},
    {"bed", "polydispersity", CFG_DOUBLE, "0", 0, 0.9, NULL, "bed radii uniform in [R(1-p), R(1+p)]"},
    {"bed", "coverage", CFG_DOUBLE, "0.5", 0.01, 0.9, NULL,
     "random, dense: area fraction covered by the grains' equatorial discs (random insertion jams near 0.547, "
     "dense reaches ~0.8)"},
    {"bed", "seed", CFG_INT, "2", 0, 2147483647, NULL, "random, dense: seed"},
    {"bed", "freeze_below", CFG_DOUBLE, "-1e300", -BIG, BIG, NULL,
     "after the packing preparation, particles with centre below this coordinate along axis become fixed"},
    /* [packing] */
    {"packing", "prepare", CFG_BOOL, "false", 1, 0, NULL, "settle the particles to rest before the run"},
    {"packing", "variant", CFG_ENUM, "dense", 1, 0, "dense|loose|as_is",
     "settling with no friction (dense), with loose_friction (loose), or with the run's contact law (as_is)"},
    {"packing", "loose_friction", CFG_DOUBLE, "1.0", 0, 1e6, NULL, "friction coefficient while settling a loose packing"},
    {"packing", "gravity", CFG_VEC3, NULL, -BIG, BIG, NULL, "gravity while settling (default: dem.gravity)", CFG_OPTIONAL},
    {"packing", "max_time", CFG_DOUBLE, "5", 0, BIG, NULL, "longest settling time (s)"},
    {"packing", "rest_energy", CFG_DOUBLE, "1e-7", 0, BIG, NULL,
     "at rest when the kinetic energy per mobile particle < rest_energy × m g d (mean m and d)"},
    {"packing", "output", CFG_STRING, "packing.h5", 1, 0, NULL, "file (in the output directory) of the settled packing"},
    /* [dem] */
    {"dem", "gravity", CFG_VEC3, "0 0 -9.81", -BIG, BIG, NULL, "gravity (m/s^2), any direction"},
    {"dem", "damping", CFG_DOUBLE, "0", 0, 0.99, NULL,
     "local non-viscous damping alpha (Cundall): every force and torque component F - alpha |F| sgn(v); "
     "0: off. For quasi-static loading (oedometer): it vanishes at equilibrium"},
    {"dem", "steps_per_contact", CFG_INT, "50", 20, 1000000, NULL, "n_c: time step dt = t_c / n_c"},
    {"dem", "dt", CFG_DOUBLE, "0", 0, BIG, NULL, "time step (s); 0: t_c / steps_per_contact; must be <= t_c/20"},
    {"dem", "skin", CFG_DOUBLE, "0.1", 1e-4, 2, NULL, "Verlet skin as a fraction of the largest diameter"},
    {"dem", "sort_every", CFG_INT, "1", 0, 1000000, NULL,
     "reorder the particles by cell every this many list rebuilds (0: never)"},
    {"dem", "threads", CFG_INT, "1", 1, 64, NULL,
     "OpenMP threads per rank for the pair forces and the integration (each thread sums into its own force "
     "array; same thread count: same result)"},
    {"dem", "parallel", CFG_ENUM, "auto", 1, 0, "auto|replicated|split",
     "several ranks: every rank computes everything (replicated), or the pairs are shared and the forces summed "
     "(split); auto: split from 4000 particles"},
    {"dem", "substeps", CFG_INT, "100", 1, 100000000, NULL,
     "ibmdem run, scene without fluid: DEM steps per step of the run driver (its outputs and checks)"},
    {"dem", "max_overlap", CFG_DOUBLE, "0.01", 1e-9, 1, NULL,
     "stop (with a checkpoint) when an overlap exceeds this fraction of the smaller diameter"},
    {"dem", "series_interval", CFG_DOUBLE, "0", 0, BIG, NULL,
     "dem_run_case: time between lines of dem_series.csv (s); 0: t_end/500"},
    {"dem", "rest_after", CFG_DOUBLE, "0", 0, BIG, NULL,
     "the grains' rate of change (rms velocity / mean diameter) counts for time.steady_tol after this time (s)"},
    {NULL, NULL, 0, NULL, 0, 0, NULL, NULL}};

void dem_register_keys(void) { cfg_schema_add(dem_keys); }

static const char *face_names[3][2] = {{"x_lo", "x_hi"}, {"y_lo", "y_hi"}, {"z_lo", "z_hi"}};

static int has_word(const char *list, const char *w)
{
    const size_t lw = strlen(w);
    for (const char *p = list; (p = strstr(p, w)); p += lw) {
        const int start = p == list || p[-1] == ' ' || p[-1] == ',';
        const int end = p[lw] == 0 || p[lw] == ' ' || p[lw] == ',';
        if (start && end) return 1;
    }
    return 0;
}

static void config_walls(dem_t *d, cfg_t *cfg)
{
    const char *faces = cfg_string(cfg, "walls", "faces");
    const int autow = !strcmp(faces, "auto"), none = !strcmp(faces, "none");
    if (!autow && !none) {
        /* every word must be a face name */
        char *buf = strdup(faces), *save = NULL;
        for (char *tok = strtok_r(buf, " \t,", &save); tok; tok = strtok_r(NULL, " \t,", &save)) {
            int ok = 0;
            for (int a = 0; a < 3; a++)
                for (int s = 0; s < 2; s++) ok |= !strcmp(tok, face_names[a][s]);
            if (!ok) cfg_fail(cfg, "walls", "faces", "'%.40s' is not auto, none or a face name (x_lo ... z_hi)", tok);
        }
        free(buf);
    }
    for (int a = 0; a < 3; a++)
        for (int s = 0; s < 2; s++) {
            const int want = autow ? !d->periodic[a] && !(d->axisymmetric && a != 1)
                                   : (!none && has_word(faces, face_names[a][s]));
            if (!want) continue;
            if (d->axisymmetric && a != 1)
                cfg_fail(cfg, "walls", "faces", "axisymmetric scene: walls only on the y faces (the spheres stay on the axis)");
            if (d->periodic[a])
                cfg_fail(cfg, "walls", "faces", "face %s is periodic and cannot carry a wall", face_names[a][s]);
            double p[3] = {d->lo[0], d->lo[1], d->lo[2]}, n[3] = {0, 0, 0};
            p[a] = s ? d->hi[a] : d->lo[a];
            n[a] = s ? -1.0 : 1.0;
            dem_add_wall(d, face_names[a][s], p, n, NULL, INFINITY);
        }
    for (int w = 1; w <= DEM_MAX_USER_WALLS; w++) {
        char kp[32], kn[32], kv[32], kr[32], name[16];
        snprintf(kp, sizeof kp, "wall%d_point", w);
        snprintf(kn, sizeof kn, "wall%d_normal", w);
        snprintf(kv, sizeof kv, "wall%d_velocity", w);
        snprintf(kr, sizeof kr, "wall%d_remove_time", w);
        if (!cfg_has(cfg, "walls", kp) && !cfg_has(cfg, "walls", kn)) continue;
        double p[3], n[3], v[3];
        cfg_vec3(cfg, "walls", kp, p);
        cfg_vec3(cfg, "walls", kn, n);
        cfg_vec3(cfg, "walls", kv, v);
        if (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] == 0) cfg_fail(cfg, "walls", kn, "the normal must not be zero");
        const double tr = cfg_double(cfg, "walls", kr);
        snprintf(name, sizeof name, "wall%d", w);
        dem_add_wall(d, name, p, n, v, tr < 0 ? INFINITY : tr);
        char kf[32], km[32];
        snprintf(kf, sizeof kf, "wall%d_force", w);
        snprintf(km, sizeof km, "wall%d_mass", w);
        const double push = cfg_double(cfg, "walls", kf), mass = cfg_double(cfg, "walls", km);
        if (push > 0 && mass <= 0) cfg_fail(cfg, "walls", kf, "a load-controlled wall needs a mass (wall%d_mass > 0)", w);
        dem_wall_set_load(d, d->nwall - 1, push, mass);
    }
}

/* One particle of source = list: "center X Y Z diameter D density RHO ...". */
static void config_list_particle(dem_t *d, cfg_t *cfg, const char *key)
{
    char *buf = strdup(cfg_string(cfg, "particles", key));
    double x[3] = {0, 0, 0}, v[3] = {0, 0, 0}, w[3] = {0, 0, 0}, r = -1, rho = cfg_double(cfg, "particles", "density");
    int have_x = 0, fixed = 0;
    char *save = NULL;
    for (char *tok = strtok_r(buf, " \t,", &save); tok; tok = strtok_r(NULL, " \t,", &save)) {
        int nv = 0, diam = 0;
        double *dst = NULL;
        if (!strcmp(tok, "center") || !strcmp(tok, "centre") || !strcmp(tok, "position")) nv = 3, dst = x, have_x = 1;
        else if (!strcmp(tok, "radius")) nv = 1, dst = &r;
        else if (!strcmp(tok, "diameter")) nv = 1, dst = &r, diam = 1;
        else if (!strcmp(tok, "density")) nv = 1, dst = &rho;
        else if (!strcmp(tok, "velocity")) nv = 3, dst = v;
        else if (!strcmp(tok, "omega")) nv = 3, dst = w;
        else if (!strcmp(tok, "fixed")) fixed = 1;
        else cfg_fail(cfg, "particles", key, "'%.40s' is not one of center, radius, diameter, density, velocity, omega, fixed", tok);
        for (int i = 0; i < nv; i++) {
            char *t = strtok_r(NULL, " \t,", &save);
            if (!t) cfg_fail(cfg, "particles", key, "%s needs %d number%s", tok, nv, nv > 1 ? "s" : "");
            if (!cfg_parse_real(t, &dst[i])) cfg_fail(cfg, "particles", key, "%s: '%.40s' is not a number", tok, t);
        }
        if (diam) r *= 0.5;
    }
    if (!have_x) cfg_fail(cfg, "particles", key, "no center X Y Z");
    if (!(r > 0)) cfg_fail(cfg, "particles", key, "no positive radius R (or diameter D)");
    if (!(rho > 0)) cfg_fail(cfg, "particles", key, "the density must be positive");
    for (int a = 0; a < 3; a++)
        if (!d->periodic[a] && (x[a] - r < d->lo[a] || x[a] + r > d->hi[a]) && !(d->axisymmetric && a != 1))
            cfg_fail(cfg, "particles", key, "the particle (centre %g %g %g, radius %g) does not fit the domain", x[0], x[1],
                     x[2], r);
    const int i = dem_add_particle(d, x, v, r, rho, fixed);
    dem_set_omega(d, d->id[i], w);
    free(buf);
}

/* The particles of a file must fit the scene (bad input, before the reader
 * builds anything): finite radii and centres, centres inside the domain
 * across its walls, periodic lengths of at least twice the largest diameter. */
static void check_file_particles(const dem_t *d, cfg_t *cfg, hid_t f, const char *path, long np)
{
    double *r = malloc(((size_t)np + 1) * sizeof *r), *x = malloc((3 * (size_t)np + 1) * sizeof *x);
    if (io_h5_read_array(f, "radius", np, r) != np || io_h5_read_array(f, "position", 3 * np, x) != 3 * np)
        cfg_fail(cfg, "particles", "file", "%s: position and radius must be [n][3] and [n] real arrays", path);
    double rmax = 0;
    for (long k = 0; k < np; k++) {
        if (!(r[k] > 0 && isfinite(r[k])))
            cfg_fail(cfg, "particles", "file", "%s: particle %ld has the radius %g", path, k, r[k]);
        rmax = fmax(rmax, r[k]);
        for (int a = 0; a < 3; a++) {
            const double c = x[3 * k + a];
            const int bounded = !d->periodic[a] && !(d->axisymmetric && a != 1);
            if (!isfinite(c) || (bounded && (c < d->lo[a] || c > d->hi[a])))
                cfg_fail(cfg, "particles", "file", "%s: particle %ld (centre %g %g %g) is outside the domain in %c [%g, %g]",
                         path, k, x[3 * k], x[3 * k + 1], x[3 * k + 2], "xyz"[a], d->lo[a], d->hi[a]);
        }
    }
    for (int a = 0; a < 3; a++)
        if (d->periodic[a] && d->L[a] < 4 * rmax)
            cfg_fail(cfg, "particles", "file",
                     "%s: the largest particle (diameter %g m) needs a periodic length in %c of at least twice its "
                     "diameter (the domain's is %g m)",
                     path, 2 * rmax, "xyz"[a], d->L[a]);
    free(r);
    free(x);
}

void dem_config_particles(dem_t *d, cfg_t *cfg)
{
    const int source = cfg_enum(cfg, "particles", "source");
    dem_origin_mark(d, "particles", source == 2 || source == 3 ? "file"
                                : source == 1 && cfg_has(cfg, "particles", "region_lo") ? "region_lo"
                                                                                         : "source");
    if (source == 1) {
        double lo[3], hi[3], v0[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = d->lo[a];
            hi[a] = d->hi[a];
        }
        if (cfg_has(cfg, "particles", "region_lo")) cfg_vec3(cfg, "particles", "region_lo", lo);
        if (cfg_has(cfg, "particles", "region_hi")) cfg_vec3(cfg, "particles", "region_hi", hi);
        for (int a = 0; a < 3; a++)
            if (!(hi[a] > lo[a])) cfg_fail(cfg, "particles", "region_hi", "must exceed region_lo in every component");
        cfg_vec3(cfg, "particles", "velocity", v0);
        const long count = cfg_int(cfg, "particles", "count");
        const double phi = cfg_double(cfg, "particles", "volume_fraction");
        if ((count > 0) == (phi > 0)) cfg_fail(cfg, "particles", "count", "give either count or volume_fraction");
        /* what cannot be: more particles than the region holds at random close
         * packing (0.64), or than the memory holds (the particle arrays alone
         * take about 280 bytes a particle) */
        const double rad = cfg_double(cfg, "particles", "radius"), poly = cfg_double(cfg, "particles", "polydispersity");
        const char *nkey = phi > 0 ? "volume_fraction" : "count";
        double vol = 1;
        for (int a = 0; a < 3; a++) vol *= fmin(hi[a], d->hi[a]) - fmax(lo[a], d->lo[a]);
        const double expect = count > 0 ? (double)count : phi * vol / dem_sphere_volume(rad);
        if (count > 0 && count * dem_sphere_volume(rad * (1 - poly)) > 0.64 * fmax(vol, 0.0))
            cfg_fail(cfg, "particles", nkey, "%ld particles of radius %g m do not fit in the region (volume %g m^3)",
                     count, rad, fmax(vol, 0.0));
        const double most = count > 0 ? (double)count : phi * vol / dem_sphere_volume(rad * (1 - poly));
        if (expect * 280.0 + most * 8.0 > physical_memory_bytes())
            cfg_fail(cfg, "particles", nkey, "about %.3g particles need more than the %.3g GB of memory of this machine",
                     expect, physical_memory_bytes() / 1e9);
        const char *why = NULL;
        const int n0 = d->n;
        if (dem_insert_random(d, lo, hi, count, phi, cfg_double(cfg, "particles", "radius"),
                              cfg_double(cfg, "particles", "polydispersity"), cfg_double(cfg, "particles", "density"),
                              v0, cfg_double(cfg, "particles", "velocity_spread"),
                              (unsigned long)cfg_int(cfg, "particles", "seed"), &why) != 0)
            cfg_fail(cfg, "particles", phi > 0 ? "volume_fraction" : "count", "%s", why);
        msg("dem: inserted %d particles at random\n", d->n - n0);
    } else if (source == 2) {
        const char *path = cfg_string(cfg, "particles", "file");
        long np;
        hid_t f = io_h5_open_packing(cfg, "particles", "file", path, &np);
        static const char *need[] = {"velocity", "omega", "density", "id", "fixed"};
        for (int k = 0; k < 5; k++)
            if (H5Lexists(f, need[k], H5P_DEFAULT) <= 0)
                cfg_fail(cfg, "particles", "file", "%s: no dataset %s (a DEM packing or checkpoint has position, "
                         "velocity, omega, radius, density, id, fixed)", path, need[k]);
        if (H5Aexists(f, "time") <= 0) cfg_fail(cfg, "particles", "file", "%s: no attribute time", path);
        check_file_particles(d, cfg, f, path, np);
        H5Fclose(f);
        dem_read_particles_file(d, path);
        /* a new run starts its clock at 0 (a restart reads its checkpoint's
         * own DEM state, not this file): a file written at t > 0, e.g. the
         * last particle snapshot of a settling run, is the state at t = 0 */
        if (dem_time(d) != 0) {
            msg("dem: %s holds the particles at t = %g s: they are the state at t = 0 of this run\n", path,
                dem_time(d));
            dem_set_time(d, 0.0);
        }
    } else if (source == 3) {
        double blo[3], bhi[3];
        dem_read_lammps_data(d, cfg, cfg_string(cfg, "particles", "file"), blo, bhi, 0);
    } else if (source == 4) {
        int count = 0;
        for (int k = 1; k <= 9; k++) {
            char key[24];
            snprintf(key, sizeof key, "particle%d", k);
            if (!cfg_has(cfg, "particles", key)) continue;
            dem_origin_mark(d, "particles", key);
            config_list_particle(d, cfg, key);
            count++;
        }
        if (!count) cfg_fail(cfg, "particles", "source", "list: no particle1 ... particle9 key");
    }
    if (d->axisymmetric)
        for (int i = 0; i < d->n; i++)
            if (d->x[3 * i] != 0 || d->x[3 * i + 2] != 0 || d->v[3 * i] != 0 || d->v[3 * i + 2] != 0)
                cfg_fail(cfg, "particles", "source",
                         "axisymmetric scene: every particle must lie and move on the axis (x = z = 0, u = w = 0)");
}

/* Random sequential insertion in [lo, hi] (centres at least R from the
 * region's faces, except along a periodic direction the region spans),
 * avoiding the particles already present. */
int dem_insert_random(dem_t *d, const double lo[3], const double hi[3], long count, double phi, double rmean,
                      double poly, double rho, const double v0[3], double vspread, unsigned long seed,
                      const char **why)
{
    static char buf[256];
    dem_rng_t g;
    dem_rng_seed(&g, seed);
    const double rmx = rmean * (1 + poly);
    double rmax_all = rmx;
    for (int i = 0; i < d->n; i++)
        if (d->r[i] > rmax_all) rmax_all = d->r[i];
    int wrap[3];
    double span[3];
    for (int a = 0; a < 3; a++) {
        wrap[a] = d->periodic[a] && lo[a] <= d->lo[a] && hi[a] >= d->hi[a];
        span[a] = wrap[a] ? d->L[a] : hi[a] - lo[a];
    }
    /* radii first: the count, or until the volume fraction is reached */
    const double vol = span[0] * span[1] * span[2];
    long cap = count > 0 ? count : (long)(phi * vol / dem_sphere_volume(rmean * (1 - poly))) + 16;
    double *rad = malloc((size_t)cap * sizeof(double));
    long nr = 0;
    double vsum = 0;
    while (count > 0 ? nr < count : vsum < phi * vol) {
        if (nr == cap) break;
        rad[nr] = rmean * (1 + poly * (2 * dem_rng_uniform(&g) - 1));
        vsum += dem_sphere_volume(rad[nr]);
        nr++;
    }
    /* hash grid over the region (cells ≥ 2 R_max) holding existing and new particles */
    int nc[3];
    double cs[3], glo[3];
    for (int a = 0; a < 3; a++) {
        glo[a] = wrap[a] ? d->lo[a] : lo[a] - rmax_all;
        const double ext = wrap[a] ? d->L[a] : hi[a] - lo[a] + 2 * rmax_all;
        nc[a] = (int)floor(ext / (2 * rmax_all));
        if (nc[a] < 1) nc[a] = 1;
        if (nc[a] > 512) nc[a] = 512;
        cs[a] = ext / nc[a];
    }
    const long ncell = (long)nc[0] * nc[1] * nc[2];
    int *head = malloc((size_t)ncell * sizeof(int));
    for (long c = 0; c < ncell; c++) head[c] = -1;
    const int ntot = d->n + (int)nr;
    int *next = malloc((size_t)ntot * sizeof(int));
    double *px = malloc(3 * (size_t)ntot * sizeof(double)), *pr = malloc((size_t)ntot * sizeof(double));
    int np = 0;
#define CELL_OF(p, c)                                                                    \
    do {                                                                                 \
        for (int a_ = 0; a_ < 3; a_++) {                                                 \
            int m_ = (int)floor(((p)[a_] - glo[a_]) / cs[a_]);                           \
            if (wrap[a_]) m_ = ((m_ % nc[a_]) + nc[a_]) % nc[a_];                        \
            c[a_] = m_ < 0 ? 0 : (m_ >= nc[a_] ? nc[a_] - 1 : m_);                       \
        }                                                                                \
    } while (0)
    for (int i = 0; i < d->n; i++) {
        int c[3];
        CELL_OF(&d->x[3 * i], c);
        /* existing particles outside the grid are clamped into the border cells */
        const long cc = ((long)c[2] * nc[1] + c[1]) * nc[0] + c[0];
        for (int a = 0; a < 3; a++) px[3 * np + a] = d->x[3 * i + a];
        pr[np] = d->r[i];
        next[np] = head[cc];
        head[cc] = np++;
    }
    long placed = 0;
    const long max_attempts = 200000;
    for (long q = 0; q < nr; q++) {
        const double r = rad[q];
        int ok = 0;
        double p[3];
        for (long att = 0; att < max_attempts && !ok; att++) {
            for (int a = 0; a < 3; a++) {
                if (wrap[a])
                    p[a] = d->lo[a] + dem_rng_uniform(&g) * d->L[a];
                else
                    p[a] = lo[a] + r + dem_rng_uniform(&g) * (hi[a] - lo[a] - 2 * r);
            }
            int c[3];
            CELL_OF(p, c);
            ok = 1;
            for (int oz = -1; oz <= 1 && ok; oz++)
                for (int oy = -1; oy <= 1 && ok; oy++)
                    for (int ox = -1; ox <= 1 && ok; ox++) {
                        int cc[3] = {c[0] + ox, c[1] + oy, c[2] + oz};
                        int skip = 0;
                        for (int a = 0; a < 3; a++) {
                            if (cc[a] < 0 || cc[a] >= nc[a]) {
                                if (wrap[a] && nc[a] >= 3)
                                    cc[a] = (cc[a] + nc[a]) % nc[a];
                                else
                                    skip = 1;
                            }
                        }
                        if (skip) continue;
                        for (int k = head[((long)cc[2] * nc[1] + cc[1]) * nc[0] + cc[0]]; k >= 0; k = next[k]) {
                            double r2 = 0;
                            for (int a = 0; a < 3; a++) {
                                double e = p[a] - px[3 * k + a];
                                if (d->periodic[a]) e -= d->L[a] * round(e / d->L[a]);
                                r2 += e * e;
                            }
                            const double rr = r + pr[k];
                            if (r2 < rr * rr) {
                                ok = 0;
                                break;
                            }
                        }
                    }
            /* with fewer than 3 cells along a wrapped direction the stencil
             * misses images: check every particle (small systems only) */
            if (ok && ((wrap[0] && nc[0] < 3) || (wrap[1] && nc[1] < 3) || (wrap[2] && nc[2] < 3))) {
                for (int k = 0; k < np && ok; k++) {
                    double r2 = 0;
                    for (int a = 0; a < 3; a++) {
                        double e = p[a] - px[3 * k + a];
                        if (d->periodic[a]) e -= d->L[a] * round(e / d->L[a]);
                        r2 += e * e;
                    }
                    if (r2 < (r + pr[k]) * (r + pr[k])) ok = 0;
                }
            }
        }
        if (!ok) break;
        int c[3];
        CELL_OF(p, c);
        const long cc = ((long)c[2] * nc[1] + c[1]) * nc[0] + c[0];
        for (int a = 0; a < 3; a++) px[3 * np + a] = p[a];
        pr[np] = r;
        next[np] = head[cc];
        head[cc] = np++;
        placed++;
    }
#undef CELL_OF
    int rc = 0;
    if (placed < nr) {
        double vp = 0;
        for (long q = 0; q < placed; q++) vp += dem_sphere_volume(rad[q]);
        snprintf(buf, sizeof buf,
                 "random insertion jammed after %ld of %ld particles (volume fraction %.3f of the region): use a "
                 "larger region or fewer particles",
                 placed, nr, vp / vol);
        *why = buf;
        rc = 1;
    } else {
        const int first = np - (int)placed;
        for (int k = first; k < np; k++) {
            double v[3];
            for (int a = 0; a < 3; a++) v[a] = v0[a] + vspread * (2 * dem_rng_uniform(&g) - 1);
            dem_add_particle(d, &px[3 * k], v, pr[k], rho, 0);
        }
    }
    free(rad);
    free(head);
    free(next);
    free(px);
    free(pr);
    return rc;
}

dem_t *dem_create_from_config(cfg_t *cfg, MPI_Comm comm)
{
    dem_t *d = calloc(1, sizeof *d);
    d->comm = comm;
    MPI_Comm_rank(comm, &d->rank);
    MPI_Comm_size(comm, &d->nranks);
    const int geometry = cfg_enum(cfg, "domain", "geometry");
    if (geometry == 1) cfg_fail(cfg, "domain", "geometry", "the DEM (spheres) needs geometry = 3d or axisymmetric");
    /* axisymmetric (x = r, y = axial): spheres on the axis, in a 3-D box
     * [−r_max, r_max] × y × [−r_max, r_max] with walls only on the y faces */
    d->axisymmetric = geometry == 2;
    const int source = cfg_enum(cfg, "particles", "source");
    double L[3], o[3];
    if (source == 3 && !cfg_has(cfg, "domain", "length")) {
        /* the box of the LAMMPS data file */
        double blo[3], bhi[3];
        dem_read_lammps_data(d, cfg, cfg_string(cfg, "particles", "file"), blo, bhi, 1);
        for (int a = 0; a < 3; a++) {
            o[a] = blo[a];
            L[a] = bhi[a] - blo[a];
        }
    } else {
        cfg_vec3(cfg, "domain", "length", L);
        cfg_vec3(cfg, "domain", "origin", o);
    }
    if (d->axisymmetric) {
        L[2] = L[0] = 2 * (o[0] + L[0]);
        o[2] = o[0] = -0.5 * L[0];
    }
    for (int a = 0; a < 3; a++) {
        if (!(L[a] > 0)) cfg_fail(cfg, "domain", "length", "every component must be positive");
        d->lo[a] = o[a];
        d->L[a] = L[a];
        d->hi[a] = o[a] + L[a];
        if (d->axisymmetric && a != 1) continue;
        const int plo = cfg_enum(cfg, "boundary", face_names[a][0]) == 0,
                  phi = cfg_enum(cfg, "boundary", face_names[a][1]) == 0;
        if (plo != phi)
            cfg_fail(cfg, "boundary", face_names[a][plo ? 1 : 0], "must be periodic too: %s is periodic",
                     face_names[a][plo ? 0 : 1]);
        d->periodic[a] = plo;
        d->any_periodic |= plo;
    }
    /* contact */
    d->law = dem_contact_law_find(cfg_string(cfg, "contact", "law"));
    if (!d->law) cfg_fail(cfg, "contact", "law", "unknown contact law");
    dem_contact_prm_t *cp = &d->cp;
    cp->clip = cfg_bool(cfg, "contact", "normal_clip");
    cp->mu = cfg_double(cfg, "contact", "friction");
    const double mw = cfg_double(cfg, "contact", "wall_friction");
    cp->mu_wall = mw < 0 ? cp->mu : mw;
    cp->mu_roll = cfg_double(cfg, "contact", "rolling_friction");
    d->law->setup(d, cfg);
    /* integration and neighbour search */
    cfg_vec3(cfg, "dem", "gravity", d->gravity);
    d->n_c = cfg_int(cfg, "dem", "steps_per_contact");
    d->dt_user = cfg_double(cfg, "dem", "dt");
    d->skin_rel = cfg_double(cfg, "dem", "skin");
    d->sort_every = cfg_int(cfg, "dem", "sort_every");
    d->max_overlap_allowed = cfg_double(cfg, "dem", "max_overlap");
    d->damping = cfg_double(cfg, "dem", "damping");
    d->parallel_mode = cfg_enum(cfg, "dem", "parallel");
    d->nthreads = cfg_int(cfg, "dem", "threads");
#ifndef _OPENMP
    if (d->nthreads > 1) cfg_fail(cfg, "dem", "threads", "this build has no OpenMP (compile src/dem with -fopenmp)");
#endif
    d->hist_update = 1;
    dem_lubrication_config(d, cfg);
    dem_drag_config(d, cfg);
    config_walls(d, cfg);
    const int src = cfg_enum(cfg, "particles", "source");
    if (src == 2 && cfg_enum(cfg, "bed", "type") != 0)
        cfg_fail(cfg, "bed", "type", "must be none when the particles come from a packing file (it holds the bed)");
    dem_origin_reset();
    dem_origin_mark(d, "bed", "type");
    dem_config_bed(d, cfg);
    dem_config_particles(d, cfg);
    dem_check_geometry(d, cfg);
    /* a time step too large for the contact time: stop now when it is known */
    if (d->dt_user > 0) {
        const double tc = d->law->contact_time(d);
        if (isfinite(tc) && d->dt_user > tc / 20.0 * (1 + 1e-12))
            cfg_fail(cfg, "dem", "dt", "%g s is too large for the contact time t_c = %g s: it must not exceed t_c/20 = %g s",
                     d->dt_user, tc, tc / 20.0);
    }
    return d;
}
