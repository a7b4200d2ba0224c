/* dem_lammps.c — LAMMPS/LIGGGHTS data files (atom_style sphere/granular),
 * read and written, for the benchmark against LIGGGHTS and for packings made
 * by those codes.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_private.h"
#include "io.h"
#include "util.h"

/* Numbers of a data line: up to max decimal numbers (cfg_parse_real),
 * blank-separated; returns how many, -1 if a word is not a number. */
static int data_numbers(char *line, double *v, int max)
{
    int k = 0;
    char *save = NULL;
    for (char *tok = strtok_r(line, " \t\r\n", &save); tok; tok = strtok_r(NULL, " \t\r\n", &save)) {
        if (k == max || !cfg_parse_real(tok, &v[k])) return -1;
        k++;
    }
    return k;
}

/* A bad data file: an input error of particles.file (cfg), else fatal. */
#define DATA_FAIL(cfg, ...)                                                                                      \
    do {                                                                                                         \
        if (cfg) cfg_fail(cfg, "particles", "file", __VA_ARGS__);                                                \
        die(__VA_ARGS__);                                                                                        \
    } while (0)

void dem_read_lammps_data(dem_t *d, cfg_t *cfg, const char *path, double box_lo[3], double box_hi[3], int read_box)
{
    FILE *fp = fopen(path, "r");
    if (!fp) DATA_FAIL(cfg, "cannot open the LAMMPS data file %s", path);
    char *line = NULL;
    size_t cap = 0;
    long natoms = -1, lineno = 1;
    int section = 0; /* 1 Atoms, 2 Velocities */
    double *x = NULL, *v = NULL, *w = NULL, *dia = NULL, *rho = NULL;
    long seen = 0;
    int have_box[3] = {0, 0, 0};
    if (getline(&line, &cap, fp) < 0) DATA_FAIL(cfg, "%s is empty", path); /* title line */
    while (getline(&line, &cap, fp) > 0) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        char w1[64] = "";
        if (sscanf(line, "%63s", w1) != 1) continue;
        if (!strcmp(w1, "Atoms")) {
            section = 1;
            if (read_box) break;
            if (natoms <= 0) DATA_FAIL(cfg, "%s:%ld: Atoms before the atom count", path, lineno);
            x = xcalloc(3 * (size_t)natoms, sizeof(double));
            v = xcalloc(3 * (size_t)natoms, sizeof(double));
            w = xcalloc(3 * (size_t)natoms, sizeof(double));
            dia = xcalloc((size_t)natoms, sizeof(double));
            rho = xcalloc((size_t)natoms, sizeof(double));
            continue;
        }
        if (!strcmp(w1, "Velocities")) {
            if (section != 1) DATA_FAIL(cfg, "%s:%ld: Velocities before Atoms", path, lineno);
            section = 2;
            continue;
        }
        if (section == 0) {
            double a, b;
            char s1[32], s2[32], n1[64], n2[64];
            if (strstr(line, "atoms") && !strstr(line, "types")) {
                double nat;
                if (sscanf(line, "%63s", n1) != 1 || !cfg_parse_real(n1, &nat) || !(nat >= 1 && nat <= 2e9) ||
                    nat != floor(nat))
                    DATA_FAIL(cfg, "%s:%ld: bad atom count", path, lineno);
                natoms = (long)nat;
                continue;
            }
            if (sscanf(line, "%63s %63s %31s %31s", n1, n2, s1, s2) == 4) {
                const int ax = !strcmp(s1, "xlo") ? 0 : !strcmp(s1, "ylo") ? 1 : !strcmp(s1, "zlo") ? 2 : -1;
                if (ax >= 0) {
                    if (!cfg_parse_real(n1, &a) || !cfg_parse_real(n2, &b) || !(b > a))
                        DATA_FAIL(cfg, "%s:%ld: bad box bounds", path, lineno);
                    box_lo[ax] = a;
                    box_hi[ax] = b;
                    have_box[ax] = 1;
                }
            }
            continue;
        }
        double a[10];
        const int k = data_numbers(line, a, 10);
        if (section == 1 ? k != 7 && k != 10 : k != 7 && k != 4)
            DATA_FAIL(cfg, "%s:%ld: a %s line needs %s numbers", path, lineno, section == 1 ? "Atoms" : "Velocities",
                      section == 1 ? "7 (id type diameter density x y z [ix iy iz])" : "4 or 7 (id vx vy vz [wx wy wz])");
        if (!(a[0] >= 1 && a[0] <= natoms && a[0] == floor(a[0])))
            DATA_FAIL(cfg, "%s:%ld: atom id %g out of range", path, lineno, a[0]);
        const long id = (long)a[0] - 1;
        if (section == 1) {
            for (int c = 0; c < 3; c++) x[3 * id + c] = a[4 + c];
            dia[id] = a[2];
            rho[id] = a[3];
            if (!(dia[id] > 0) || !(rho[id] > 0))
                DATA_FAIL(cfg, "%s:%ld: the diameter and density must be positive", path, lineno);
            seen++;
        } else {
            for (int c = 0; c < 3; c++) {
                v[3 * id + c] = a[1 + c];
                w[3 * id + c] = k == 7 ? a[4 + c] : 0.0;
            }
        }
    }
    fclose(fp);
    free(line);
    if (read_box) {
        if (!have_box[0] || !have_box[1] || !have_box[2])
            DATA_FAIL(cfg, "%s: the box (xlo xhi, ylo yhi, zlo zhi) is missing", path);
        return;
    }
    if (natoms <= 0 || seen != natoms) DATA_FAIL(cfg, "%s: %ld atoms declared, %ld read", path, natoms, seen);
    const int n0 = d->n;
    for (long k = 0; k < natoms; k++) dem_add_particle(d, &x[3 * k], &v[3 * k], 0.5 * dia[k], rho[k], 0);
    for (long k = 0; k < natoms; k++)
        for (int c = 0; c < 3; c++) d->w[3 * (n0 + k) + c] = w[3 * k + c];
    free(x);
    free(v);
    free(w);
    free(dia);
    free(rho);
    msg("dem: read %ld particles from %s\n", natoms, path);
}

void dem_write_lammps_data(dem_t *d, const char *path)
{
    dem_sync_velocities(d);
    if (d->rank != 0) return;
    char tmp[4112];
    FILE *fp = atomic_open(path, tmp, sizeof tmp);
    if (!fp) die_local("%s", io_error_message());
    int *o = dem_id_order(d);
    fprintf(fp, "ibmdem DEM state at t = %.10g s\n\n%d atoms\n1 atom types\n\n", d->time, d->n);
    const char *ax = "xyz";
    for (int a = 0; a < 3; a++) fprintf(fp, "%.10g %.10g %clo %chi\n", d->lo[a], d->hi[a], ax[a], ax[a]);
    fprintf(fp, "\nAtoms\n\n");
    for (int k = 0; k < d->n; k++) {
        const int i = o[k];
        fprintf(fp, "%d 1 %.10g %.10g %.12e %.12e %.12e\n", k + 1, 2 * d->r[i], d->rho[i], d->x[3 * i], d->x[3 * i + 1],
                d->x[3 * i + 2]);
    }
    fprintf(fp, "\nVelocities\n\n");
    for (int k = 0; k < d->n; k++) {
        const int i = o[k];
        fprintf(fp, "%d %.6e %.6e %.6e %.6e %.6e %.6e\n", k + 1, d->v[3 * i], d->v[3 * i + 1], d->v[3 * i + 2],
                d->w[3 * i], d->w[3 * i + 1], d->w[3 * i + 2]);
    }
    free(o);
    if (atomic_commit(fp, tmp, path)) die_local("%s", io_error_message());
}
