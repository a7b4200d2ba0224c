/* dem_io.c — particle output and state files of the DEM.
 *
 *  - snapshots: HDF5 (one file per output time, particles in id order) and
 *    one XDMF file listing them as a temporal collection of Polyvertex
 *    grids (ParaView: open particles.xdmf, Glyph filter with "radius");
 *  - checkpoints/packings: HDF5 with everything needed to continue
 *    bit-for-bit in a run with the same input (particles, contact and wall
 *    springs, wall positions, time).
 * (LAMMPS/LIGGGHTS data files: dem_lammps.c.)
 * HDF5 is opened with the MPI-IO driver on the DEM communicator; the data
 * are replicated, so rank 0 writes them and every rank takes part in the
 * collective calls (file, dataset and attribute creation).
 */
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dem_private.h"
#include "io.h"
#include "util.h"

static hid_t open_file(const dem_t *d, const char *path, int create)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_fapl_mpio(fapl, d->comm, MPI_INFO_NULL);
    /* a creation is tried again if MPI-IO fails to open the file (io_h5_create_with) */
    hid_t f = create ? io_h5_create_with(path, d->comm, fapl) : H5Fopen(path, H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    if (f < 0) die("dem: cannot %s HDF5 file %s", create ? "create" : "open", path);
    return f;
}

/* Close a file written: flushed to the disk first (MPI_File_sync); a failure
 * is an I/O error (util.h). */
static void close_written(hid_t f, const char *path)
{
    const int flush_failed = H5Fflush(f, H5F_SCOPE_GLOBAL) < 0;
    const int close_failed = H5Fclose(f) < 0;
    if (close_failed) mpi_finalize_unsafe(); /* the file is left half closed (HDF5 1.10) */
    if (close_failed || flush_failed) io_error_collective("cannot write the HDF5 file %s (HDF5 error, see above)", path);
}

/* A dataset or attribute not written: an I/O error naming its file. */
static void write_failed(hid_t loc, const char *name)
{
    char file[4096] = "?";
    H5Fget_name(loc, file, sizeof file);
    io_error_collective("cannot write %s in the HDF5 file %s (HDF5 error, see above)", name, file);
}

/* Collective creation, rank-0 write of an n×comp dataset. */
static void write_ds(const dem_t *d, hid_t file, const char *name, hid_t type, const void *data, long n, int comp)
{
    hsize_t dims[2] = {(hsize_t)n, (hsize_t)comp};
    hid_t sp = H5Screate_simple(comp > 1 ? 2 : 1, dims, NULL);
    hid_t ds = H5Dcreate2(file, name, type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (ds < 0 || (d->rank == 0 && n > 0 && H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
        write_failed(file, name);
    H5Dclose(ds);
    H5Sclose(sp);
}

static void write_attr_d(hid_t obj, const char *name, const double *v, int n)
{
    hsize_t dims = (hsize_t)n;
    hid_t sp = H5Screate_simple(1, &dims, NULL);
    hid_t a = H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a < 0 || H5Awrite(a, H5T_NATIVE_DOUBLE, v) < 0) write_failed(obj, name);
    H5Aclose(a);
    H5Sclose(sp);
}

static void write_attr_l(hid_t obj, const char *name, long v)
{
    hid_t sp = H5Screate(H5S_SCALAR);
    hid_t a = H5Acreate2(obj, name, H5T_NATIVE_LONG, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a < 0 || H5Awrite(a, H5T_NATIVE_LONG, &v) < 0) write_failed(obj, name);
    H5Aclose(a);
    H5Sclose(sp);
}

static int has_ds(hid_t f, const char *name) { return H5Lexists(f, name, H5P_DEFAULT) > 0; }

static long ds_length(hid_t f, const char *name)
{
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    if (ds < 0) die("dem: dataset %s missing", name);
    hid_t sp = H5Dget_space(ds);
    hsize_t dims[2] = {0, 0};
    H5Sget_simple_extent_dims(sp, dims, NULL);
    H5Sclose(sp);
    H5Dclose(ds);
    return (long)dims[0];
}

static void read_ds(hid_t f, const char *name, hid_t type, void *buf)
{
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    if (ds < 0) die("dem: dataset %s missing", name);
    H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
    H5Dclose(ds);
}

static void read_attr_d(hid_t obj, const char *name, double *v)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) die("dem: attribute %s missing", name);
    H5Aread(a, H5T_NATIVE_DOUBLE, v);
    H5Aclose(a);
}

/* Particles in id order: order[k] = index of the k-th smallest id. */
typedef struct {
    long id;
    int i;
} id_index_t;

static int cmp_id_index(const void *a, const void *b)
{
    const long x = ((const id_index_t *)a)->id, y = ((const id_index_t *)b)->id;
    return (x > y) - (x < y);
}

int *dem_id_order(const dem_t *d)
{
    id_index_t *t = xcalloc((size_t)d->n + 1, sizeof *t);
    for (int i = 0; i < d->n; i++) {
        t[i].id = d->id[i];
        t[i].i = i;
    }
    qsort(t, (size_t)d->n, sizeof *t, cmp_id_index);
    int *o = xcalloc((size_t)d->n + 1, sizeof(int));
    for (int k = 0; k < d->n; k++) o[k] = t[k].i;
    free(t);
    return o;
}

/* Snapshots: particles in id order.  Checkpoints (full): in the current
 * index order, with the neighbour lists, so that a reloaded run continues
 * bit for bit. */
static void write_particles(dem_t *d, hid_t f, int full)
{
    int *o = dem_id_order(d);
    if (full)
        for (int i = 0; i < d->n; i++) o[i] = i;
    const struct {
        const char *name;
        const double *a;
        int comp;
    } arrays[] = {{"position", d->x, 3}, {"velocity", d->v, 3}, {"omega", d->w, 3},   {"radius", d->r, 1},
                  {"density", d->rho, 1}, {"force", d->f, 3},   {"torque", d->t, 3}};
    /* force and torque (the integrator's state) in checkpoints only */
    const int narr = full ? 7 : 5;
    double *b = malloc((3 * (size_t)d->n + 1) * sizeof(double));
    for (int a = 0; a < narr; a++) {
        for (int k = 0; k < d->n; k++)
            for (int c = 0; c < arrays[a].comp; c++) b[arrays[a].comp * k + c] = arrays[a].a[arrays[a].comp * o[k] + c];
        write_ds(d, f, arrays[a].name, H5T_NATIVE_DOUBLE, b, d->n, arrays[a].comp);
    }
    free(b);
    long *ids = malloc(((size_t)d->n + 1) * sizeof(long));
    int *fx = malloc(((size_t)d->n + 1) * sizeof(int));
    for (int k = 0; k < d->n; k++) {
        ids[k] = d->id[o[k]];
        fx[k] = d->fixed[o[k]];
    }
    write_ds(d, f, "id", H5T_NATIVE_LONG, ids, d->n, 1);
    write_ds(d, f, "fixed", H5T_NATIVE_INT, fx, d->n, 1);
    free(ids);
    free(fx);
    free(o);
}

static void snap_record(dem_t *d, int index, double t, long n)
{
    if (d->nsnap == d->snap_cap) {
        d->snap_cap = d->snap_cap ? 2 * d->snap_cap : 64;
        d->snap_t = realloc(d->snap_t, (size_t)d->snap_cap * sizeof(double));
        d->snap_n = realloc(d->snap_n, (size_t)d->snap_cap * sizeof(long));
        d->snap_index = realloc(d->snap_index, (size_t)d->snap_cap * sizeof(int));
    }
    d->snap_t[d->nsnap] = t;
    d->snap_n[d->nsnap] = n;
    d->snap_index[d->nsnap] = index;
    d->nsnap++;
}

static void write_xdmf(dem_t *d, const char *dir)
{
    if (d->rank != 0) return;
    char path[4096], tmp[4112];
    snprintf(path, sizeof path, "%s/particles.xdmf", dir);
    FILE *fp = atomic_open(path, tmp, sizeof tmp);
    if (!fp) return;
    fprintf(fp, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
                "<Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (int s = 0; s < d->nsnap; s++) {
        char base[64];
        snprintf(base, sizeof base, "particles_%06d.h5", d->snap_index[s]);
        const long n = d->snap_n[s];
        fprintf(fp,
                "<Grid Name=\"p%06d\" GridType=\"Uniform\">\n<Time Value=\"%.10g\"/>\n"
                "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%ld\" NodesPerElement=\"1\"/>\n"
                "<Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" Precision=\"8\" "
                "Format=\"HDF\">%s:/position</DataItem></Geometry>\n",
                d->snap_index[s], d->snap_t[s], n, n, base);
        const char *vec[] = {"velocity", "omega"};
        for (int a = 0; a < 2; a++)
            fprintf(fp,
                    "<Attribute Name=\"%s\" AttributeType=\"Vector\" Center=\"Node\"><DataItem Dimensions=\"%ld 3\" "
                    "NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/%s</DataItem></Attribute>\n",
                    vec[a], n, base, vec[a]);
        fprintf(fp,
                "<Attribute Name=\"radius\" AttributeType=\"Scalar\" Center=\"Node\"><DataItem Dimensions=\"%ld\" "
                "NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/radius</DataItem></Attribute>\n"
                "<Attribute Name=\"id\" AttributeType=\"Scalar\" Center=\"Node\"><DataItem Dimensions=\"%ld\" "
                "NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">%s:/id</DataItem></Attribute>\n"
                "<Attribute Name=\"fixed\" AttributeType=\"Scalar\" Center=\"Node\"><DataItem Dimensions=\"%ld\" "
                "NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">%s:/fixed</DataItem></Attribute>\n</Grid>\n",
                n, base, n, base, n, base);
    }
    fprintf(fp, "</Grid>\n</Domain>\n</Xdmf>\n");
    atomic_commit(fp, tmp, path);
}

void dem_snapshots_resume(dem_t *d, const char *dir, int first)
{
    for (int k = 0; k < first; k++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/particles_%06d.h5", dir, k);
        if (access(path, R_OK) != 0) continue;
        hid_t f = open_file(d, path, 0);
        double t = 0;
        read_attr_d(f, "time", &t);
        const long n = ds_length(f, "radius");
        H5Fclose(f);
        snap_record(d, k, t, n);
    }
    write_xdmf(d, dir); /* the index of these only */
}

void dem_write_snapshot(dem_t *d, const char *dir, int index)
{
    dem_sync_velocities(d);
    char path[4096];
    snprintf(path, sizeof path, "%s/particles_%06d.h5", dir, index);
    hid_t f = open_file(d, path, 1);
    write_attr_d(f, "time", &d->time, 1);
    write_attr_l(f, "step", d->step);
    write_particles(d, f, 0);
    close_written(f, path);
    snap_record(d, index, d->time, d->n);
    write_xdmf(d, dir);
}

void dem_write_checkpoint(dem_t *d, const char *path)
{
    hid_t f = open_file(d, path, 1);
    dem_checkpoint_write_loc(d, f);
    close_written(f, path);
}

void dem_checkpoint_write_loc(dem_t *d, hid_t f)
{
    dem_sync_velocities(d);
    /* springs live on their owner rank: share them first (the lists are
     * not changed: a checkpoint does not change the run) */
    if (d->split && d->nb_start) dem_neigh_gather(d);
    write_attr_d(f, "time", &d->time, 1);
    write_attr_l(f, "step", d->step);
    write_attr_d(f, "gravity", d->gravity, 3);
    write_attr_d(f, "domain_lo", d->lo, 3);
    write_attr_d(f, "domain_hi", d->hi, 3);
    write_particles(d, f, 1);
    /* pair springs by particle ids */
    long m = 0;
    if (d->nb_start)
        for (int i = 0; i < d->nb_n_rows; i++)
            for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++) m += d->nb_on[k];
    long *pid = malloc((2 * (size_t)m + 1) * sizeof(long));
    double *pxi = malloc((3 * (size_t)m + 1) * sizeof(double));
    m = 0;
    if (d->nb_start)
        for (int i = 0; i < d->nb_n_rows; i++)
            for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++)
                if (d->nb_on[k]) {
                    pid[2 * m] = d->id[i];
                    pid[2 * m + 1] = d->id[d->nb_j[k]];
                    for (int c = 0; c < 3; c++) pxi[3 * m + c] = d->nb_hist[3 * k + c];
                    m++;
                }
    write_ds(d, f, "contact_ids", H5T_NATIVE_LONG, pid, m, 2);
    write_ds(d, f, "contact_xi", H5T_NATIVE_DOUBLE, pxi, m, 3);
    free(pid);
    free(pxi);
    /* the drag's local solid fractions, held between their updates (by id) */
    if (d->drag.on && d->drag.phi_step >= 0) {
        write_attr_l(f, "drag_fraction_step", d->drag.phi_step);
        write_ds(d, f, "drag_fraction", H5T_NATIVE_DOUBLE, d->drag.phi, d->drag.nphi, 1);
        if (d->drag.uf_grains) write_ds(d, f, "drag_grain_velocity", H5T_NATIVE_DOUBLE, d->drag.ug, d->drag.nphi, 3);
    }
    /* walls: state and springs */
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        char name[64];
        snprintf(name, sizeof name, "wall_%s", W->name);
        hid_t g = H5Gcreate2(f, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        write_attr_d(g, "point", W->p, 3);
        write_attr_d(g, "normal", W->n, 3);
        const double act = W->active;
        write_attr_d(g, "active", &act, 1);
        write_attr_d(g, "velocity", W->vel, 3); /* a load-controlled wall's changes */
        /* a load-controlled wall: its load, mass and the particles' force of the last step (its next
         * leap-frog step reads it) */
        const double load[2] = {W->push, W->mass};
        write_attr_d(g, "load_mass", load, 2);
        write_attr_d(g, "force", W->force, 3);
        long nw = 0;
        for (int e = 0; e < W->nlist; e++) nw += W->on[e];
        long *wid = malloc(((size_t)nw + 1) * sizeof(long));
        double *wxi = malloc((3 * (size_t)nw + 1) * sizeof(double));
        nw = 0;
        for (int e = 0; e < W->nlist; e++)
            if (W->on[e]) {
                wid[nw] = d->id[W->idx[e]];
                for (int c = 0; c < 3; c++) wxi[3 * nw + c] = W->hist[3 * e + c];
                nw++;
            }
        write_ds(d, g, "ids", H5T_NATIVE_LONG, wid, nw, 1);
        write_ds(d, g, "xi", H5T_NATIVE_DOUBLE, wxi, nw, 3);
        free(wid);
        free(wxi);
        /* the wall's contact list as it is (exact continuation) */
        const double moved = W->moved;
        write_attr_d(g, "list_moved", &moved, 1);
        write_ds(d, g, "list_idx", H5T_NATIVE_INT, W->idx, W->nlist, 1);
        write_ds(d, g, "list_on", H5T_NATIVE_UCHAR, W->on, W->nlist, 1);
        write_ds(d, g, "list_xi", H5T_NATIVE_DOUBLE, W->hist, W->nlist, 3);
        H5Gclose(g);
    }
    /* the pair list as it is (exact continuation) */
    if (d->nb_start && d->nb_n_rows == d->n) {
        const double lattr[3] = {d->skin, d->disp_bound, (double)d->builds_since_sort};
        write_attr_d(f, "list_skin_disp_sort", lattr, 3);
        write_attr_l(f, "list_rebuilds", d->rebuilds);
        write_ds(d, f, "list_start", H5T_NATIVE_INT, d->nb_start, d->n + 1, 1);
        write_ds(d, f, "list_j", H5T_NATIVE_INT, d->nb_j, d->nb_n, 1);
        write_ds(d, f, "list_img", H5T_NATIVE_UCHAR, d->nb_img, d->nb_n, 1);
        write_ds(d, f, "list_on", H5T_NATIVE_UCHAR, d->nb_on, d->nb_n, 1);
        write_ds(d, f, "list_xi", H5T_NATIVE_DOUBLE, d->nb_hist, d->nb_n, 3);
    }
}

static int cmp_long(const void *a, const void *b)
{
    const long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

/* The motion of a wall: its point, whether it is active, and for a
 * load-controlled wall its velocity, load, mass and the particles' force of
 * the last step (its next leap-frog step reads it). */
static void read_wall_motion(hid_t g, dem_wall_t *W)
{
    double act = 1;
    read_attr_d(g, "point", W->p);
    read_attr_d(g, "active", &act);
    W->active = act != 0;
    if (H5Aexists(g, "velocity") > 0) read_attr_d(g, "velocity", W->vel);
    if (H5Aexists(g, "load_mass") > 0 && H5Aexists(g, "force") > 0) {
        double load[2];
        read_attr_d(g, "load_mass", load);
        read_attr_d(g, "force", W->force);
        W->push = load[0];
        W->mass = load[1];
    }
}

/* The neighbour and wall lists saved by dem_checkpoint_write_loc, if the
 * scene matches (same particles in the same order, skin, walls); 0 if not.
 * keep_walls: the walls' motion stays the scene's (a new run from a file). */
static int read_exact_lists(dem_t *d, hid_t f, int keep_walls)
{
    if (!has_ds(f, "list_start") || ds_length(f, "list_start") != d->n + 1) return 0;
    double lattr[3];
    if (H5Aexists(f, "list_skin_disp_sort") <= 0) return 0;
    read_attr_d(f, "list_skin_disp_sort", lattr);
    if (lattr[0] != d->skin) return 0;
    for (int w = 0; w < d->nwall; w++) {
        char name[64];
        snprintf(name, sizeof name, "wall_%s", d->wall[w].name);
        if (!has_ds(f, name)) return 0;
    }
    const long m = ds_length(f, "list_j");
    free(d->nb_start);
    d->nb_start = xcalloc((size_t)d->n + 1, sizeof(int));
    read_ds(f, "list_start", H5T_NATIVE_INT, d->nb_start);
    if (m > d->nb_cap) {
        free(d->nb_j);
        free(d->nb_img);
        free(d->nb_on);
        free(d->nb_hist);
        d->nb_j = xcalloc((size_t)m, sizeof(int));
        d->nb_img = xcalloc((size_t)m, 1);
        d->nb_on = xcalloc((size_t)m, 1);
        d->nb_hist = xcalloc(3 * (size_t)m, sizeof(double));
        d->nb_cap = m;
    }
    if (m > 0) {
        read_ds(f, "list_j", H5T_NATIVE_INT, d->nb_j);
        read_ds(f, "list_img", H5T_NATIVE_UCHAR, d->nb_img);
        read_ds(f, "list_on", H5T_NATIVE_UCHAR, d->nb_on);
        read_ds(f, "list_xi", H5T_NATIVE_DOUBLE, d->nb_hist);
    }
    d->nb_n = m;
    d->nb_n_rows = d->n;
    d->disp_bound = lattr[1];
    d->builds_since_sort = (int)lattr[2];
    hid_t a = H5Aopen(f, "list_rebuilds", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_LONG, &d->rebuilds);
    H5Aclose(a);
    for (int w = 0; w < d->nwall; w++) {
        dem_wall_t *W = &d->wall[w];
        char name[64];
        snprintf(name, sizeof name, "wall_%s", W->name);
        hid_t g = H5Gopen2(f, name, H5P_DEFAULT);
        if (!keep_walls) read_wall_motion(g, W);
        read_attr_d(g, "list_moved", &W->moved);
        const long nl = ds_length(g, "list_idx");
        if (nl > W->cap) {
            free(W->idx);
            free(W->on);
            free(W->hist);
            W->idx = xcalloc((size_t)nl, sizeof(int));
            W->on = xcalloc((size_t)nl, 1);
            W->hist = xcalloc(3 * (size_t)nl, sizeof(double));
            W->cap = (int)nl;
        }
        if (nl > 0) {
            read_ds(g, "list_idx", H5T_NATIVE_INT, W->idx);
            read_ds(g, "list_on", H5T_NATIVE_UCHAR, W->on);
            read_ds(g, "list_xi", H5T_NATIVE_DOUBLE, W->hist);
        }
        W->nlist = (int)nl;
        H5Gclose(g);
    }
    /* the cell grid is made at the next build; the rows of this rank */
    dem_neigh_partition(d);
    return 1;
}

static void checkpoint_read(dem_t *d, hid_t f, const char *path, int keep_walls);

void dem_read_checkpoint(dem_t *d, const char *path)
{
    hid_t f = open_file(d, path, 0);
    checkpoint_read(d, f, path, 0);
    H5Fclose(f);
}

void dem_read_particles_file(dem_t *d, const char *path)
{
    hid_t f = open_file(d, path, 0);
    checkpoint_read(d, f, path, 1);
    H5Fclose(f);
}

void dem_checkpoint_read_loc(dem_t *d, hid_t f, const char *path) { checkpoint_read(d, f, path, 0); }

/* Does the file hold a wall of this scene elsewhere (point or activity) than the scene has it? */
static int file_walls_differ(const dem_t *d, hid_t f)
{
    for (int w = 0; w < d->nwall; w++) {
        char name[64];
        snprintf(name, sizeof name, "wall_%s", d->wall[w].name);
        if (!has_ds(f, name)) return 1;
        hid_t g = H5Gopen2(f, name, H5P_DEFAULT);
        double p[3] = {0, 0, 0}, act = 1;
        read_attr_d(g, "point", p);
        read_attr_d(g, "active", &act);
        H5Gclose(g);
        if (p[0] != d->wall[w].p[0] || p[1] != d->wall[w].p[1] || p[2] != d->wall[w].p[2] ||
            (act != 0) != (d->wall[w].active != 0))
            return 1;
    }
    return 0;
}

static void checkpoint_read(dem_t *d, hid_t f, const char *path, int keep_walls)
{
    const long n = ds_length(f, "radius");
    double *x = malloc((3 * (size_t)n + 1) * sizeof(double)), *v = malloc((3 * (size_t)n + 1) * sizeof(double)),
           *w = malloc((3 * (size_t)n + 1) * sizeof(double)), *r = malloc(((size_t)n + 1) * sizeof(double)),
           *rho = malloc(((size_t)n + 1) * sizeof(double));
    long *ids = malloc(((size_t)n + 1) * sizeof(long));
    int *fx = malloc(((size_t)n + 1) * sizeof(int));
    read_ds(f, "position", H5T_NATIVE_DOUBLE, x);
    read_ds(f, "velocity", H5T_NATIVE_DOUBLE, v);
    read_ds(f, "omega", H5T_NATIVE_DOUBLE, w);
    read_ds(f, "radius", H5T_NATIVE_DOUBLE, r);
    read_ds(f, "density", H5T_NATIVE_DOUBLE, rho);
    read_ds(f, "id", H5T_NATIVE_LONG, ids);
    read_ds(f, "fixed", H5T_NATIVE_INT, fx);
    double t = 0;
    read_attr_d(f, "time", &t);
    /* replace the particles */
    d->n = 0;
    d->next_id = 0;
    for (long k = 0; k < n; k++) {
        const int i = dem_add_particle(d, &x[3 * k], &v[3 * k], r[k], rho[k], fx[k]);
        d->id[i] = ids[k];
        if (ids[k] >= d->next_id) d->next_id = ids[k] + 1;
        if (!fx[k])
            for (int a = 0; a < 3; a++) d->w[3 * i + a] = w[3 * k + a];
    }
    d->time = t;
    {
        hid_t a = H5Aopen(f, "step", H5P_DEFAULT);
        if (a >= 0) {
            H5Aread(a, H5T_NATIVE_LONG, &d->step);
            H5Aclose(a);
        }
    }
    /* springs: the saved lists if they fit this scene, else build the lists
     * and look the pairs up by id */
    int restored = 0;
    dem_check_scene(d);
    dem_decide_split(d);
    if (d->dt <= 0 && dem_set_dt(d) != DEM_OK) die("dem: %s", d->errmsg);
    /* a new run from a file keeps the walls of its case (a bed settled in a taller box gets this
     * case's lid); where they are not the file's, the lists are built for them and the wall
     * springs of the file are dropped (the pair springs are kept) */
    const int walls_moved = keep_walls && file_walls_differ(d, f);
    if (!walls_moved && read_exact_lists(d, f, keep_walls)) goto forces;
    dem_neigh_build(d);
    long *sorted = malloc(((size_t)n + 1) * sizeof(long));
    int *index_of = malloc(((size_t)n + 1) * sizeof(int));
    for (int i = 0; i < d->n; i++) sorted[i] = d->id[i];
    qsort(sorted, (size_t)d->n, sizeof(long), cmp_long);
    /* id → index through the sorted ids */
    for (int i = 0; i < d->n; i++) {
        long *p = bsearch(&d->id[i], sorted, (size_t)d->n, sizeof(long), cmp_long);
        index_of[p - sorted] = i;
    }
#define INDEX_OF(idv) (index_of[(long *)bsearch(&(idv), sorted, (size_t)d->n, sizeof(long), cmp_long) - sorted])
    if (has_ds(f, "contact_ids")) {
        const long m = ds_length(f, "contact_ids");
        long *pid = malloc((2 * (size_t)m + 1) * sizeof(long));
        double *pxi = malloc((3 * (size_t)m + 1) * sizeof(double));
        if (m > 0) {
            read_ds(f, "contact_ids", H5T_NATIVE_LONG, pid);
            read_ds(f, "contact_xi", H5T_NATIVE_DOUBLE, pxi);
        }
        for (long q = 0; q < m; q++) {
            int i = INDEX_OF(pid[2 * q]), j = INDEX_OF(pid[2 * q + 1]);
            double sgn = 1;
            for (int pass = 0; pass < 2; pass++) {
                int found = 0;
                for (int k = d->nb_start[i]; k < d->nb_start[i + 1]; k++)
                    if (d->nb_j[k] == j) {
                        d->nb_on[k] = 1;
                        for (int c = 0; c < 3; c++) d->nb_hist[3 * k + c] = sgn * pxi[3 * q + c];
                        found = 1;
                        break;
                    }
                if (found) break;
                const int tmp = i;
                i = j;
                j = tmp;
                sgn = -1;
            }
        }
        free(pid);
        free(pxi);
    }
    for (int wi = 0; wi < d->nwall; wi++) {
        dem_wall_t *W = &d->wall[wi];
        char name[64];
        snprintf(name, sizeof name, "wall_%s", W->name);
        if (!has_ds(f, name)) continue;
        hid_t g = H5Gopen2(f, name, H5P_DEFAULT);
        if (!keep_walls) read_wall_motion(g, W);
        const long nw = walls_moved ? 0 : ds_length(g, "ids");
        long *wid = malloc(((size_t)nw + 1) * sizeof(long));
        double *wxi = malloc((3 * (size_t)nw + 1) * sizeof(double));
        if (nw > 0) {
            read_ds(g, "ids", H5T_NATIVE_LONG, wid);
            read_ds(g, "xi", H5T_NATIVE_DOUBLE, wxi);
        }
        H5Gclose(g);
        if (!W->active) W->nlist = 0;
        for (long q = 0; q < nw; q++) {
            const int i = INDEX_OF(wid[q]);
            for (int e = 0; e < W->nlist; e++)
                if (W->idx[e] == i) {
                    W->on[e] = 1;
                    for (int c = 0; c < 3; c++) W->hist[3 * e + c] = wxi[3 * q + c];
                }
        }
        free(wid);
        free(wxi);
    }
#undef INDEX_OF
    free(sorted);
    free(index_of);
forces:
    /* forces of the saved state: the next step continues exactly as the run
     * that wrote the file would have */
    if (has_ds(f, "force") && has_ds(f, "torque")) {
        double *ff = malloc((3 * (size_t)n + 1) * sizeof(double)), *tt = malloc((3 * (size_t)n + 1) * sizeof(double));
        read_ds(f, "force", H5T_NATIVE_DOUBLE, ff);
        read_ds(f, "torque", H5T_NATIVE_DOUBLE, tt);
        for (int i = 0; i < d->n; i++) {
            /* the particles were added in the order of the file */
            for (int c = 0; c < 3; c++) {
                d->f[3 * i + c] = ff[3 * i + c];
                d->t[3 * i + c] = tt[3 * i + c];
            }
        }
        free(ff);
        free(tt);
        restored = 1;
    }
    free(x);
    free(v);
    free(w);
    free(r);
    free(rho);
    free(ids);
    free(fx);
    if (d->drag.on && has_ds(f, "drag_fraction")) {
        /* by particle id: as many as the writer's ids (this run's next_id may be larger) */
        hid_t a = H5Aopen(f, "drag_fraction_step", H5P_DEFAULT);
        const long nphi = ds_length(f, "drag_fraction"), nall = nphi > d->next_id ? nphi : d->next_id;
        if (a >= 0) {
            d->drag.phi = realloc(d->drag.phi, ((size_t)nall + 1) * sizeof *d->drag.phi);
            d->drag.fd = realloc(d->drag.fd, 3 * ((size_t)nall + 1) * sizeof *d->drag.fd);
            memset(d->drag.phi, 0, ((size_t)nall + 1) * sizeof *d->drag.phi);
            memset(d->drag.fd, 0, 3 * ((size_t)nall + 1) * sizeof *d->drag.fd);
            d->drag.ug = realloc(d->drag.ug, 3 * ((size_t)nall + 1) * sizeof *d->drag.ug);
            memset(d->drag.ug, 0, 3 * ((size_t)nall + 1) * sizeof *d->drag.ug);
            d->drag.nphi = nall;
            read_ds(f, "drag_fraction", H5T_NATIVE_DOUBLE, d->drag.phi);
            if (d->drag.uf_grains && has_ds(f, "drag_grain_velocity"))
                read_ds(f, "drag_grain_velocity", H5T_NATIVE_DOUBLE, d->drag.ug);
            H5Aread(a, H5T_NATIVE_LONG, &d->drag.phi_step);
            H5Aclose(a);
        }
    }
    d->ready = restored;
    d->pending_kick = 0;
    msg("dem: read %ld particles from %s (t = %g s)\n", n, path, t);
}
