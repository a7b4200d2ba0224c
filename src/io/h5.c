/* h5.c — parallel HDF5 helpers.  Grid fields are split in x-slabs, one per
 * rank, and each rank writes or reads its slab as a hyperslab of one global
 * dataset with collective MPI-IO, so the files do not depend on the rank
 * count that wrote them.  Small data (arrays, text, attributes) is passed
 * identically by every rank; rank 0's copy is written. */
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "io.h"
#include "util.h"

void h5_write_error(hid_t loc, const char *name);

static hid_t fapl_mpio(MPI_Comm comm)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
    /* metadata reads and writes collective: fewer small requests */
    H5Pset_all_coll_metadata_ops(fapl, 1);
    H5Pset_coll_metadata_write(fapl, 1);
    return fapl;
}

/* Create (truncate) a file on every rank of comm.  Open MPI's MPI-IO open
 * fails now and then (MPI_ERR_OTHER) when several MPI processes start and
 * open files at once on the machine: the ranks agree whether every one has
 * the file, and the creation is tried again, up to 5 times, 0.1-0.5 s apart,
 * before the run stops (HDF5's error report is printed for the last try). */
hid_t io_h5_create_with(const char *path, MPI_Comm comm, hid_t fapl)
{
    enum { TRIES = 5 };
    hid_t f = -1;
    for (int t = 0; t < TRIES; t++) {
        if (t < TRIES - 1) {
            H5E_BEGIN_TRY { f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl); }
            H5E_END_TRY;
        } else {
            f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
        }
        int ok = f >= 0, all = 0;
        MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, comm);
        if (all) break;
        if (f >= 0) H5Fclose(f);
        f = -1;
        if (t < TRIES - 1) {
            const struct timespec pause = {0, 100000000L * (t + 1)};
            nanosleep(&pause, NULL);
        }
    }
    if (f < 0) die("cannot create the HDF5 file %s", path);
    return f;
}

hid_t io_h5_create(const char *path, MPI_Comm comm)
{
    hid_t fapl = fapl_mpio(comm);
    hid_t f = io_h5_create_with(path, comm, fapl);
    H5Pclose(fapl);
    return f;
}

hid_t io_h5_open(const char *path, MPI_Comm comm)
{
    /* Decide on rank 0 whether the file can be opened, so that no rank is
     * left waiting in a collective open that another one skipped. */
    int rank, ok = 0;
    MPI_Comm_rank(comm, &rank);
    if (rank == 0) {
        H5E_BEGIN_TRY { ok = access(path, R_OK) == 0 && H5Fis_hdf5(path) > 0; }
        H5E_END_TRY;
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, comm);
    if (!ok) return -1;
    hid_t fapl = fapl_mpio(comm);
    hid_t f;
    H5E_BEGIN_TRY { f = H5Fopen(path, H5F_ACC_RDONLY, fapl); }
    H5E_END_TRY;
    H5Pclose(fapl);
    return f;
}

void io_h5_close(hid_t file)
{
    if (file < 0) return;
    char name[IO_PATH_MAX + 64] = "";
    unsigned intent = 0;
    const int writable = H5Fget_intent(file, &intent) >= 0 && (intent & H5F_ACC_RDWR);
    H5Fget_name(file, name, sizeof name);
    /* a file written: flushed to the disk (MPI_File_sync: fsync) before it is closed */
    const int flush_failed = writable && H5Fflush(file, H5F_SCOPE_GLOBAL) < 0;
    if (H5Fclose(file) < 0) {
        mpi_finalize_unsafe(); /* HDF5 1.10 keeps the file half closed: its own closing at MPI_Finalize crashes */
        io_error_collective("cannot write the HDF5 file %s (HDF5 error, see above)", name);
    } else if (flush_failed) {
        io_error_collective("cannot write the HDF5 file %s (HDF5 error, see above)", name);
    }
}

/* A dataset or attribute that could not be written: an I/O error naming the
 * file (the run goes on to its next check, every rank doing its part of the
 * collective calls). */
void h5_write_error(hid_t loc, const char *name)
{
    char file[IO_PATH_MAX + 64] = "?";
    H5Fget_name(loc, file, sizeof file);
    io_error_collective("cannot write %s in the HDF5 file %s (HDF5 error, see above)", name, file);
}

static hid_t dxpl_collective(void)
{
    hid_t x = H5Pcreate(H5P_DATASET_XFER);
    H5Pset_dxpl_mpio(x, H5FD_MPIO_COLLECTIVE);
    return x;
}

/* Memory space of a whole field with its ghosts, the interior selected. */
static hid_t field_memspace(const grid_t *g)
{
    hsize_t dims[3] = {(hsize_t)g->nxl + 2, (hsize_t)g->n[1] + 2, (hsize_t)g->n[2] + 2 * g->gz};
    hsize_t start[3] = {1, 1, (hsize_t)g->gz}, count[3] = {(hsize_t)g->nxl, (hsize_t)g->n[1], (hsize_t)g->n[2]};
    hid_t m = H5Screate_simple(3, dims, NULL);
    H5Sselect_hyperslab(m, H5S_SELECT_SET, start, NULL, count, NULL);
    return m;
}

/* File space [nx][ny][nz], this rank's slab selected. */
static hid_t field_filespace(const grid_t *g)
{
    hsize_t dims[3] = {(hsize_t)g->n[0], (hsize_t)g->n[1], (hsize_t)g->n[2]};
    hsize_t start[3] = {(hsize_t)g->ix0, 0, 0}, count[3] = {(hsize_t)g->nxl, (hsize_t)g->n[1], (hsize_t)g->n[2]};
    hid_t s = H5Screate_simple(3, dims, NULL);
    H5Sselect_hyperslab(s, H5S_SELECT_SET, start, NULL, count, NULL);
    return s;
}

void io_h5_write_field(hid_t loc, const char *name, const grid_t *g, const double *f)
{
    hid_t fs = field_filespace(g), ms = field_memspace(g), x = dxpl_collective();
    hid_t d = H5Dcreate2(loc, name, H5T_NATIVE_DOUBLE, fs, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d < 0 || H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, x, f) < 0) h5_write_error(loc, name);
    H5Dclose(d);
    H5Pclose(x);
    H5Sclose(ms);
    H5Sclose(fs);
}

int io_h5_read_field(hid_t loc, const char *name, const grid_t *g, double *f)
{
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) return -1;
    hid_t d = H5Dopen2(loc, name, H5P_DEFAULT);
    if (d < 0) return -1;
    hid_t s = H5Dget_space(d);
    hsize_t dims[3] = {0, 0, 0};
    int rank = H5Sget_simple_extent_ndims(s);
    if (rank == 3) H5Sget_simple_extent_dims(s, dims, NULL);
    H5Sclose(s);
    if (rank != 3 || dims[0] != (hsize_t)g->n[0] || dims[1] != (hsize_t)g->n[1] || dims[2] != (hsize_t)g->n[2]) {
        H5Dclose(d);
        return -1;
    }
    hid_t fs = field_filespace(g), ms = field_memspace(g), x = dxpl_collective();
    herr_t r = H5Dread(d, H5T_NATIVE_DOUBLE, ms, fs, x, f);
    H5Pclose(x);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Dclose(d);
    return r < 0 ? -1 : 0;
}

void io_h5_write_cells_xfast(hid_t loc, const char *name, const grid_t *g, int ncomp, const double *buf)
{
    int rank = ncomp > 1 ? 4 : 3;
    hsize_t dims[4] = {(hsize_t)g->n[2], (hsize_t)g->n[1], (hsize_t)g->n[0], (hsize_t)ncomp};
    hsize_t start[4] = {0, 0, (hsize_t)g->ix0, 0};
    hsize_t count[4] = {(hsize_t)g->n[2], (hsize_t)g->n[1], (hsize_t)g->nxl, (hsize_t)ncomp};
    hid_t fs = H5Screate_simple(rank, dims, NULL);
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL);
    hid_t ms = H5Screate_simple(rank, count, NULL);
    hid_t x = dxpl_collective();
    hid_t d = H5Dcreate2(loc, name, H5T_NATIVE_DOUBLE, fs, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d < 0 || H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, x, buf) < 0) h5_write_error(loc, name);
    H5Dclose(d);
    H5Pclose(x);
    H5Sclose(ms);
    H5Sclose(fs);
}

/* Write `data` of type t and shape fs on rank 0 only (collectively: the other
 * ranks select nothing). */
static void write_rank0(hid_t loc, const char *name, hid_t t, hid_t fs, const void *data)
{
    hid_t d = H5Dcreate2(loc, name, t, fs, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t ms = H5Scopy(fs), fsel = H5Scopy(fs), x = dxpl_collective();
    if (mpi_rank() != 0) {
        H5Sselect_none(ms);
        H5Sselect_none(fsel);
    }
    if (d < 0 || H5Dwrite(d, t, ms, fsel, x, data) < 0) h5_write_error(loc, name);
    H5Pclose(x);
    H5Sclose(fsel);
    H5Sclose(ms);
    H5Dclose(d);
}

void io_h5_write_array(hid_t loc, const char *name, long n, const double *v)
{
    hsize_t dim = (hsize_t)n;
    hid_t fs = H5Screate_simple(1, &dim, NULL);
    write_rank0(loc, name, H5T_NATIVE_DOUBLE, fs, v);
    H5Sclose(fs);
}

void io_h5_write_matrix(hid_t loc, const char *name, long n, int m, const double *v)
{
    hsize_t dim[2] = {(hsize_t)n, (hsize_t)m};
    hid_t fs = H5Screate_simple(2, dim, NULL);
    write_rank0(loc, name, H5T_NATIVE_DOUBLE, fs, v);
    H5Sclose(fs);
}

long io_h5_read_array(hid_t loc, const char *name, long nmax, double *v)
{
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) return -1;
    hid_t d = H5Dopen2(loc, name, H5P_DEFAULT);
    hid_t s = H5Dget_space(d);
    hssize_t n = H5Sget_simple_extent_npoints(s);
    H5Sclose(s);
    if (n < 0 || n > nmax) {
        H5Dclose(d);
        return -1;
    }
    herr_t r = H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v);
    H5Dclose(d);
    return r < 0 ? -1 : (long)n;
}

static hid_t string_type(size_t len)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, len ? len : 1);
    H5Tset_strpad(t, H5T_STR_NULLTERM);
    return t;
}

void io_h5_write_text(hid_t loc, const char *name, const char *text)
{
    hid_t t = string_type(strlen(text) + 1), s = H5Screate(H5S_SCALAR);
    write_rank0(loc, name, t, s, text);
    H5Sclose(s);
    H5Tclose(t);
}

char *io_h5_read_text(hid_t loc, const char *name)
{
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) return NULL;
    hid_t d = H5Dopen2(loc, name, H5P_DEFAULT);
    hid_t ft = H5Dget_type(d);
    size_t len = H5Tget_size(ft);
    H5Tclose(ft);
    char *text = calloc(len + 1, 1);
    hid_t t = string_type(len);
    if (H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, text) < 0) {
        free(text);
        text = NULL;
    }
    H5Tclose(t);
    H5Dclose(d);
    return text;
}

static void attr_write(hid_t loc, const char *name, hid_t t, const void *v)
{
    if (H5Aexists(loc, name) > 0) H5Adelete(loc, name);
    hid_t s = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(loc, name, t, s, H5P_DEFAULT, H5P_DEFAULT);
    if (a < 0 || H5Awrite(a, t, v) < 0) h5_write_error(loc, name);
    H5Aclose(a);
    H5Sclose(s);
}

void io_h5_attr_double(hid_t loc, const char *name, double v) { attr_write(loc, name, H5T_NATIVE_DOUBLE, &v); }
void io_h5_attr_long(hid_t loc, const char *name, long v) { attr_write(loc, name, H5T_NATIVE_LONG, &v); }

void io_h5_attr_string(hid_t loc, const char *name, const char *v)
{
    hid_t t = string_type(strlen(v) + 1);
    attr_write(loc, name, t, v);
    H5Tclose(t);
}

static int attr_read(hid_t loc, const char *name, hid_t t, void *v)
{
    if (H5Aexists(loc, name) <= 0) return -1;
    hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
    herr_t r = H5Aread(a, t, v);
    H5Aclose(a);
    return r < 0 ? -1 : 0;
}

int io_h5_get_attr_double(hid_t loc, const char *name, double *v) { return attr_read(loc, name, H5T_NATIVE_DOUBLE, v); }
int io_h5_get_attr_long(hid_t loc, const char *name, long *v) { return attr_read(loc, name, H5T_NATIVE_LONG, v); }

void io_h5_attr_hash(hid_t loc, const char *name, uint64_t h, MPI_Comm comm)
{
    MPI_Bcast(&h, 1, MPI_UINT64_T, 0, comm);
    char hex[24];
    snprintf(hex, sizeof hex, "%016" PRIx64, h);
    io_h5_attr_string(loc, name, hex);
}

int io_h5_get_attr_hash(hid_t loc, const char *name, uint64_t *h)
{
    if (H5Aexists(loc, name) <= 0) return -1;
    char hex[32] = "";
    hid_t a = H5Aopen(loc, name, H5P_DEFAULT), t = string_type(sizeof hex);
    herr_t r = H5Aread(a, t, hex);
    H5Tclose(t);
    H5Aclose(a);
    if (r < 0) return -1;
    char *end;
    *h = strtoull(hex, &end, 16);
    return end == hex ? -1 : 0;
}

int io_is_h5_path(const char *path)
{
    const size_t len = strlen(path);
    return (len > 3 && !strcmp(path + len - 3, ".h5")) || (len > 5 && !strcmp(path + len - 5, ".hdf5"));
}

hid_t io_h5_open_packing(cfg_t *cfg, const char *section, const char *key, const char *path, long *n)
{
    /* a missing or foreign file is an input error: without HDF5's error stack */
    H5E_auto2_t func;
    void *data;
    H5Eget_auto2(H5E_DEFAULT, &func, &data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    H5Eset_auto2(H5E_DEFAULT, func, data);
    if (f < 0) cfg_fail(cfg, section, key, "cannot open %s as HDF5", path);
    if (H5Lexists(f, "radius", H5P_DEFAULT) <= 0 || H5Lexists(f, "position", H5P_DEFAULT) <= 0)
        cfg_fail(cfg, section, key, "%s: needs the datasets position [n][3] and radius [n]", path);
    hid_t ds = H5Dopen2(f, "radius", H5P_DEFAULT), sp = H5Dget_space(ds);
    *n = (long)H5Sget_simple_extent_npoints(sp);
    H5Sclose(sp);
    H5Dclose(ds);
    return f;
}

/* ---- the values of a file: finite? -------------------------------------------- */

typedef struct {
    char **name;
    int n, cap;
} name_list_t;

static herr_t collect_dataset(hid_t g, const char *name, const H5L_info_t *info, void *data)
{
    (void)info;
    name_list_t *l = data;
    H5O_info_t oi;
    if (H5Oget_info_by_name(g, name, &oi, H5P_DEFAULT) < 0 || oi.type != H5O_TYPE_DATASET) return 0;
    if (l->n == l->cap) l->name = realloc(l->name, (size_t)(l->cap = l->cap ? 2 * l->cap : 32) * sizeof *l->name);
    l->name[l->n++] = strdup(name);
    return 0;
}

/* 1 if this rank's share of dataset d (a block of rows of its first
 * dimension) holds a NaN or an infinity. */
static int share_not_finite(hid_t d, MPI_Comm comm)
{
    int rank, size;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    hid_t s = H5Dget_space(d);
    int nd = H5Sget_simple_extent_ndims(s);
    hsize_t dims[H5S_MAX_RANK];
    if (nd > 0) H5Sget_simple_extent_dims(s, dims, NULL);
    int bad = 0;
    if (nd <= 0) { /* a scalar: rank 0 */
        double v = 0;
        if (rank == 0 && nd == 0 && H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v) >= 0) bad = !isfinite(v);
        H5Sclose(s);
        return bad;
    }
    hsize_t row = 1;
    for (int k = 1; k < nd; k++) row *= dims[k];
    const hsize_t lo = dims[0] * (hsize_t)rank / (hsize_t)size, hi = dims[0] * (hsize_t)(rank + 1) / (hsize_t)size;
    /* in blocks of at most ~8 MB */
    hsize_t block = row ? (1u << 20) / row : 1;
    if (block < 1) block = 1;
    double *buf = malloc((size_t)((block < hi - lo ? block : hi - lo) * row + 1) * sizeof *buf);
    for (hsize_t r0 = lo; r0 < hi && !bad; r0 += block) {
        hsize_t count[H5S_MAX_RANK], start[H5S_MAX_RANK];
        for (int k = 0; k < nd; k++) count[k] = dims[k], start[k] = 0;
        start[0] = r0;
        count[0] = r0 + block < hi ? block : hi - r0;
        H5Sselect_hyperslab(s, H5S_SELECT_SET, start, NULL, count, NULL);
        hsize_t nval = count[0] * row;
        hid_t m = H5Screate_simple(1, &nval, NULL);
        if (H5Dread(d, H5T_NATIVE_DOUBLE, m, s, H5P_DEFAULT, buf) < 0) bad = 1;
        for (hsize_t i = 0; i < nval && !bad; i++) bad = !isfinite(buf[i]);
        H5Sclose(m);
    }
    free(buf);
    H5Sclose(s);
    return bad;
}

int io_h5_check_finite(hid_t file, MPI_Comm comm, char *where, size_t n)
{
    name_list_t l = {NULL, 0, 0};
    H5Lvisit(file, H5_INDEX_NAME, H5_ITER_INC, collect_dataset, &l);
    int first = l.n; /* index of the first dataset with a bad value */
    for (int i = 0; i < l.n && first == l.n; i++) {
        hid_t d = H5Dopen2(file, l.name[i], H5P_DEFAULT);
        if (d < 0) continue;
        hid_t t = H5Dget_type(d);
        int bad = H5Tget_class(t) == H5T_FLOAT && share_not_finite(d, comm);
        H5Tclose(t);
        H5Dclose(d);
        MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, comm);
        if (bad) first = i;
    }
    if (first < l.n) snprintf(where, n, "/%s", l.name[first]);
    for (int i = 0; i < l.n; i++) free(l.name[i]);
    free(l.name);
    return first < l.n;
}
