/* test_io.c — the output layer on synthetic fields: checkpoint fields read
 * back bit for bit, the global layout of the files independent of the rank
 * count, snapshot values (cell centres, interpolated face vectors) and the
 * XDMF index, the time-series restart, the input fingerprint and JSON.
 * RANKS: 1 2
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "grid.h"
#include "io.h"
#include "testutil.h"
#include "util.h"

static char tmpdir[256];

/* A value for global cell (i, j, k) that uses every bit of the mantissa, so
 * that any reordering or rounding in the round trip shows. */
static double code(int i, int j, int k, int c) { return sin(1.0 + i + 0.37 * j + 0.11 * k + 0.05 * c) * 1e3 / 3.0; }

static grid_t *make_grid(int dim, int stretched)
{
    int n[3] = {8, 6, dim == 3 ? 4 : 1};
    double L[3] = {2.0, 1.5, 1.0}, x0[3] = {-1.0, 0.5, 0.25};
    bc_t bc = {0};
    if (stretched) bc.type[0][0] = bc.type[0][1] = BC_NOSLIP;
    return grid_create(dim == 3 ? GEOM_3D : GEOM_2D, n, L, x0, &bc, stretched ? STRETCH_TANH_BOTH : STRETCH_UNIFORM,
                       1.5, MPI_COMM_WORLD);
}

/* Field written and read back: the interior is identical bit for bit, the
 * ghosts are not touched, and the file holds the global array [nx][ny][nz]
 * (checked by reading it serially on rank 0). */
static void test_field_roundtrip(void **state)
{
    for (int dim = 2; dim <= 3; dim++) {
        grid_t *g = make_grid(dim, 1);
        double *f = field_alloc(g), *r = field_alloc(g);
        for (int i = 0; i < g->nxl; i++)
            for (int j = 0; j < g->n[1]; j++)
                for (int k = 0; k < g->n[2]; k++) f[G_IDX(g, i, j, k)] = code(i + g->ix0, j, k, 0);
        for (long q = 0; q < g->nalloc; q++) r[q] = -7.0; /* ghost marker */
        char path[512];
        snprintf(path, sizeof path, "%s/field%d.h5", tmpdir, dim);
        hid_t h = io_h5_create(path, MPI_COMM_WORLD);
        io_h5_write_field(h, "u", g, f);
        io_h5_close(h);
        h = io_h5_open(path, MPI_COMM_WORLD);
        assert_true(h >= 0);
        assert_int_equal(io_h5_read_field(h, "u", g, r), 0);
        assert_int_equal(io_h5_read_field(h, "missing", g, r), -1);
        io_h5_close(h);
        int bad = 0;
        for (int i = -1; i <= g->nxl; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -g->gz; k < g->n[2] + g->gz; k++) {
                    int interior = i >= 0 && i < g->nxl && j >= 0 && j < g->n[1] && k >= 0 && k < g->n[2];
                    long q = G_IDX(g, i, j, k);
                    if (interior ? memcmp(&r[q], &f[q], sizeof(double)) != 0 : r[q] != -7.0) bad++;
                }
        /* a grid of another size must be refused, not read */
        int n2[3] = {g->n[0], g->n[1] + 2, g->n[2]};
        grid_t *g2 = grid_create(g->geom, n2, g->L, g->x0, &g->bc, g->stretch, g->stretch_beta, MPI_COMM_WORLD);
        double *f2 = field_alloc(g2);
        h = io_h5_open(path, MPI_COMM_WORLD);
        assert_int_equal(io_h5_read_field(h, "u", g2, f2), -1);
        io_h5_close(h);
        /* global layout, serially on rank 0 */
        if (g->rank == 0) {
            hid_t fs = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
            hid_t d = H5Dopen2(fs, "u", H5P_DEFAULT);
            long ntot = (long)g->n[0] * g->n[1] * g->n[2];
            double *all = malloc((size_t)ntot * sizeof *all);
            H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, all);
            for (int i = 0; i < g->n[0]; i++)
                for (int j = 0; j < g->n[1]; j++)
                    for (int k = 0; k < g->n[2]; k++)
                        if (all[((long)i * g->n[1] + j) * g->n[2] + k] != code(i, j, k, 0)) bad++;
            free(all);
            H5Dclose(d);
            H5Fclose(fs);
        }
        bad = (int)grid_sum(g, bad);
        assert_int_equal(bad, 0);
        free(f2);
        grid_free(g2);
        free(f);
        free(r);
        grid_free(g);
    }
}

/* Snapshot of a cell scalar and of a staggered vector field that is linear
 * in each coordinate: interpolation to cell centres is then exact (up to
 * round-off, 1e-13 relative), on a stretched grid.  The mesh nodes are the
 * faces, the file order is x fastest, and fields.xmf names every dataset
 * with its shape. */
static void test_snapshot(void **state)
{
    for (int dim = 2; dim <= 3; dim++) {
        grid_t *g = make_grid(dim, 1);
        double *p = field_alloc(g), *u[3] = {field_alloc(g), field_alloc(g), dim == 3 ? field_alloc(g) : NULL};
        /* fill ghosts too: faces at index -1 are the low faces of the first cells */
        for (int i = -1; i <= g->nxl; i++)
            for (int j = -1; j <= g->n[1]; j++)
                for (int k = -g->gz; k < g->n[2] + g->gz; k++) {
                    long q = G_IDX(g, i, j, k);
                    double xc = g->xc[i], yc = grid_yc(g, j);
                    p[q] = code(i + g->ix0, j, k, 0);
                    u[0][q] = 2.0 * g->xf[i] + 0.5 * yc;
                    u[1][q] = -xc + 3.0 * grid_yf(g, j);
                    if (u[2]) u[2][q] = xc + 4.0 * grid_zf(g, k);
                }
        char dir[512];
        snprintf(dir, sizeof dir, "%s/snap%d", tmpdir, dim);
        if (g->rank == 0) mkdir_p(dir);
        MPI_Barrier(MPI_COMM_WORLD);
        io_snapshots_t *s = io_snapshots_create(g, dir, 0);
        for (int n = 0; n < 2; n++) {
            io_snapshot_begin(s, 0.5 * n, 10 * n);
            io_snapshot_cell_scalar(s, "pressure", p);
            io_snapshot_face_vector(s, "velocity", u);
            io_snapshot_end(s);
        }
        assert_int_equal(io_snapshots_count(s), 2);
        io_snapshots_free(s);
        int bad = 0;
        double err = 0;
        if (g->rank == 0) {
            char path[600];
            snprintf(path, sizeof path, "%s/fields_00001.h5", dir);
            hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
            int nx = g->n[0], ny = g->n[1], nz = g->n[2];
            double *pv = malloc((size_t)nx * ny * nz * sizeof *pv), *vv = malloc((size_t)nx * ny * nz * 3 * sizeof *vv);
            double *x = malloc((size_t)(nx + 1) * sizeof *x);
            hid_t d = H5Dopen2(f, "pressure", H5P_DEFAULT);
            H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, pv);
            H5Dclose(d);
            d = H5Dopen2(f, "velocity", H5P_DEFAULT);
            H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, vv);
            H5Dclose(d);
            d = H5Dopen2(f, "x", H5P_DEFAULT);
            H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x);
            H5Dclose(d);
            double t = -1;
            hid_t a = H5Aopen(f, "time", H5P_DEFAULT);
            H5Aread(a, H5T_NATIVE_DOUBLE, &t);
            H5Aclose(a);
            H5Fclose(f);
            if (t != 0.5) bad++;
            for (int i = 0; i <= nx; i++)
                if (x[i] != g->gxf[i - 1]) bad++; /* stretched faces, exactly */
            for (int k = 0; k < nz; k++)
                for (int j = 0; j < ny; j++)
                    for (int i = 0; i < nx; i++) {
                        long c = ((long)k * ny + j) * nx + i;
                        if (pv[c] != code(i, j, k, 0)) bad++;
                        double xc = g->gxc[i], yc = grid_yc(g, j), zc = grid_zc(g, k);
                        double ex[3] = {2.0 * xc + 0.5 * yc, -xc + 3.0 * yc, dim == 3 ? xc + 4.0 * zc : 0.0};
                        for (int q = 0; q < 3; q++) err = fmax(err, fabs(vv[3 * c + q] - ex[q]) / 10.0);
                    }
            free(pv);
            free(vv);
            free(x);
            /* the XDMF index */
            snprintf(path, sizeof path, "%s/fields.xmf", dir);
            FILE *xf = fopen(path, "r");
            char text[16384] = "";
            size_t len = xf ? fread(text, 1, sizeof text - 1, xf) : 0;
            text[len] = 0;
            if (xf) fclose(xf);
            char want[256];
            snprintf(want, sizeof want, "TopologyType=\"3DRectMesh\" Dimensions=\"%d %d %d\"", nz + 1, ny + 1, nx + 1);
            if (!strstr(text, want)) bad++;
            snprintf(want, sizeof want, "Dimensions=\"%d %d %d 3\"", nz, ny, nx);
            if (!strstr(text, want)) bad++;
            if (!strstr(text, "fields_00001.h5:/velocity") || !strstr(text, "<Time Value=\"0.5\"/>")) bad++;
            if (!strstr(text, "</Xdmf>")) bad++;
        }
        bad = (int)grid_sum(g, bad);
        err = grid_max(g, err);
        assert_int_equal(bad, 0);
        assert_true(err < 1e-13);
        /* a restart from snapshot 1 keeps the index entry of snapshot 0 and rewrites 1 */
        s = io_snapshots_create(g, dir, 1);
        io_snapshot_begin(s, 0.75, 15);
        io_snapshot_cell_scalar(s, "pressure", p);
        io_snapshot_end(s);
        io_snapshots_free(s);
        if (g->rank == 0) {
            char path[600], text[16384] = "";
            snprintf(path, sizeof path, "%s/fields.xmf", dir);
            FILE *xf = fopen(path, "r");
            size_t len = fread(text, 1, sizeof text - 1, xf);
            text[len] = 0;
            fclose(xf);
            if (!strstr(text, "<Time Value=\"0\"/>") || !strstr(text, "<Time Value=\"0.75\"/>") ||
                strstr(text, "<Time Value=\"0.5\"/>"))
                bad++;
        }
        bad = (int)grid_sum(g, bad);
        assert_int_equal(bad, 0);
        free(p);
        for (int d = 0; d < 3; d++) free(u[d]);
        grid_free(g);
    }
}

/* The series of a restarted run keeps the rows up to the restart step (the
 * last of them the one the checkpoint names) and cuts the rest, a row cut
 * in the middle by a crash included. */
static void test_series_restart(void **state)
{
    char path[512];
    snprintf(path, sizeof path, "%s/series.csv", tmpdir);
    const char *names[3] = {"step", "time", "ke"};
    io_series_t *s = io_series_open(path, 3, names, NULL);
    for (int n = 0; n <= 10; n++) {
        double v[3] = {n, 0.1 * n, 1.0 / (n + 1)};
        io_series_row(s, v);
    }
    assert_int_equal(io_series_last_step(s), mpi_rank() == 0 ? 10 : -1);
    uint64_t h10 = io_series_hash(s, 10), h9 = io_series_hash(s, 9);
    io_series_close(s);
    if (mpi_rank() == 0) { /* a crash in the middle of the row of step 11 */
        FILE *f = fopen(path, "a");
        fputs("11,1.1", f);
        fclose(f);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    /* a checkpoint of step 10 follows the rows 0..10, one of step 9 (a
     * diverged step 10 undone) the rows 0..9 */
    if (mpi_rank() == 0) assert_true(h9 != h10);
    /* a restart from step 5 */
    io_series_resume_t r = {5, 5, 0, 1};
    if (mpi_rank() == 0) {
        /* the hash of the header and rows 0..5 as they were written */
        FILE *f = fopen(path, "r");
        char line[256];
        uint64_t h = 14695981039346656037ULL;
        for (int k = 0; k < 7 && fgets(line, sizeof line, f); k++)
            for (char *c = line; *c; c++) h = (h ^ (unsigned char)*c) * 1099511628211ULL;
        fclose(f);
        r.hash = h;
    }
    MPI_Bcast(&r.hash, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    s = io_series_open(path, 3, names, &r);
    double v[3] = {6, 0.6, 42};
    io_series_row(s, v);
    io_series_close(s);
    int ok = 1;
    if (mpi_rank() == 0) {
        FILE *f = fopen(path, "r");
        char line[256];
        int nrow = -1;
        long last = -1;
        while (fgets(line, sizeof line, f)) {
            if (nrow >= 0) last = strtol(line, NULL, 10);
            nrow++;
            if (nrow == 7 && strcmp(line, "6,0.6,42\n") != 0) ok = 0;
        }
        fclose(f);
        ok = ok && nrow == 7 && last == 6;
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    assert_true(ok);
    assert_string_equal(io_error_message(), "");
}

static void count_diff(const char *key, const char *a, const char *b, void *ctx)
{
    if (!strcmp(key, "fluid.nu")) (*(int *)ctx)++;
}

/* The fingerprint ignores the run-control keys and origin notes, and sees a
 * change of any other key; the diff names it. */
static void test_fingerprint(void **state)
{
    const char *skip[] = {"time.t_end", "output.*", NULL};
    const char *a = "; resolved input of a.ini\n\n[fluid]\nnu = 0.01\nrho = 1 ; default\n\n[output]\ndir = x\n"
                    "\n[time]\nt_end = 1\n";
    const char *b = "; resolved input of b.ini\n\n[fluid]\nnu = 0.01 ; --set\nrho = 1\n\n[output]\ndir = y\n"
                    "fields_every = 3 ; default\n\n[time]\nt_end = 2\n";
    const char *c = "[fluid]\nnu = 0.02\nrho = 1\n[time]\nt_end = 1\n";
    assert_true(io_input_fingerprint(a, skip) == io_input_fingerprint(b, skip));
    assert_true(io_input_fingerprint(a, skip) != io_input_fingerprint(c, skip));
    assert_true(io_input_fingerprint(a, NULL) != io_input_fingerprint(b, NULL));
    int hits = 0;
    assert_int_equal(io_input_diff(a, c, skip, count_diff, &hits), 1);
    assert_int_equal(hits, 1);
    assert_int_equal(io_input_diff(a, b, skip, NULL, NULL), 0);
}

/* summary.json: nested objects from dotted keys, escaping, null for NaN;
 * parsed back by Python's json module when it is available. */
static void test_summary(void **state)
{
    io_summary_t *s = io_summary_create();
    io_summary_string(s, "case", "cav\"ity\n");
    io_summary_long(s, "steps", 12);
    io_summary_double(s, "fluid.kinetic_energy", 0.125);
    io_summary_double(s, "time", 1.5);
    io_summary_double(s, "fluid.div_max", NAN);
    io_summary_bool(s, "fluid.solver.ok", 1);
    io_summary_long(s, "steps", 13);
    char path[512];
    snprintf(path, sizeof path, "%s/summary.json", tmpdir);
    assert_int_equal(io_summary_write(s, path), 0);
    io_summary_free(s);
    int ok = 1;
    if (mpi_rank() == 0 && access("/usr/bin/python3", X_OK) == 0) {
        char cmd[1024];
        snprintf(cmd, sizeof cmd,
                 "/usr/bin/python3 -c \"import json,sys; d=json.load(open('%s')); "
                 "sys.exit(0 if d['case']=='cav\\\"ity\\n' and d['steps']==13 and d['fluid']['kinetic_energy']==0.125 "
                 "and d['fluid']['div_max'] is None and d['fluid']['solver']['ok'] is True and d['time']==1.5 "
                 "and list(d)==['case','steps','fluid','time'] else 1)\"",
                 path);
        ok = system(cmd) == 0;
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    assert_true(ok);
}

int main(int argc, char **argv)
{
    test_mpi_init(&argc, &argv);
    if (mpi_rank() == 0) {
        snprintf(tmpdir, sizeof tmpdir, "/tmp/ibmdem_test_io_XXXXXX");
        if (!mkdtemp(tmpdir)) return 1;
    }
    MPI_Bcast(tmpdir, sizeof tmpdir, MPI_CHAR, 0, MPI_COMM_WORLD);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_field_roundtrip), cmocka_unit_test(test_snapshot),
        cmocka_unit_test(test_series_restart),  cmocka_unit_test(test_fingerprint),
        cmocka_unit_test(test_summary),
    };
    int fails = _cmocka_run_group_tests("io", tests, sizeof tests / sizeof tests[0], NULL, NULL);
    int all;
    MPI_Allreduce(&fails, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Barrier(MPI_COMM_WORLD);
    if (mpi_rank() == 0 && getenv("IBMDEM_TEST_KEEP")) {
        printf("files kept in %s\n", tmpdir);
    } else if (mpi_rank() == 0 && all == 0) {
        char cmd[300];
        snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
        if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    }
    MPI_Finalize();
    return all;
}
