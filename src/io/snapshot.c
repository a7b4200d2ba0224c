/* snapshot.c — field snapshots for viewing: one HDF5 file per snapshot
 * (DIR/fields_NNNNN.h5) holding the mesh and cell-centred fields, and one
 * XDMF file (DIR/fields.xmf, XDMF 2) that indexes them as a temporal
 * collection, which ParaView and VisIt open directly.
 *
 * Mesh: a rectilinear 3DRectMesh whose nodes are the cell faces (the real,
 * possibly stretched, x faces), with Geometry VXVYVZ; the data are cell
 * centred (Center="Cell"), so every value sits in its own control volume.
 * A 2-D grid is written as one layer of cells in z: the same reader then
 * handles every geometry (for axisymmetric runs, x = r and y = axial).
 * Arrays are stored x fastest, [nz][ny][nx], the order XDMF expects. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "util.h"

struct io_snapshots {
    const grid_t *g;
    char dir[IO_PATH_MAX];
    int count;          /* snapshots written, including those of earlier runs */
    char **block;       /* XDMF <Grid> block of each snapshot (NULL if unknown) */
    int nblock, capblock;
    /* snapshot being written */
    hid_t file;
    char cur[8192];     /* its attributes, XML */
    double time;
    long step;
    double *buf;        /* nxl*ny*nz*3 */
};

static void fields_name(int index, char *buf, size_t n) { snprintf(buf, n, "fields_%05d.h5", index); }

static void set_block(io_snapshots_t *s, int index, char *text)
{
    while (index >= s->capblock) {
        s->capblock = s->capblock ? 2 * s->capblock : 64;
        s->block = realloc(s->block, (size_t)s->capblock * sizeof *s->block);
    }
    for (int i = s->nblock; i <= index; i++) s->block[i] = NULL;
    if (index >= s->nblock) s->nblock = index + 1;
    free(s->block[index]);
    s->block[index] = text;
}

/* On a restart, keep the <Grid> blocks of the snapshots before `first` from
 * the existing index (rank 0 only, which alone writes it). */
static void read_old_blocks(io_snapshots_t *s, int first)
{
    char path[IO_PATH_MAX + 16];
    snprintf(path, sizeof path, "%s/fields.xmf", s->dir);
    FILE *f = fopen(path, "r");
    if (!f) return;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = calloc((size_t)len + 1, 1);
    if (fread(text, 1, (size_t)len, f) != (size_t)len) len = 0;
    text[len] = 0;
    fclose(f);
    const char *open = "    <Grid Name=\"fields_", *close = "    </Grid>\n";
    for (char *p = strstr(text, open); p; p = strstr(p, open)) {
        int index;
        char *end = strstr(p, close);
        if (!end || sscanf(p + strlen(open), "%d", &index) != 1) break;
        end += strlen(close);
        if (index < first) {
            char *b = malloc((size_t)(end - p) + 1);
            memcpy(b, p, (size_t)(end - p));
            b[end - p] = 0;
            set_block(s, index, b);
        }
        p = end;
    }
    free(text);
}

io_snapshots_t *io_snapshots_create(const grid_t *g, const char *dir, int first)
{
    io_snapshots_t *s = calloc(1, sizeof *s);
    s->g = g;
    snprintf(s->dir, sizeof s->dir, "%s", dir);
    s->count = first;
    s->file = -1;
    s->buf = xcalloc((size_t)g->ncell_local * 3, sizeof(double));
    if (first > 0 && g->rank == 0) read_old_blocks(s, first);
    return s;
}

int io_snapshots_count(const io_snapshots_t *s) { return s->count; }

void io_snapshot_begin(io_snapshots_t *s, double time, long step)
{
    const grid_t *g = s->g;
    char name[64], path[IO_PATH_MAX + 80];
    fields_name(s->count, name, sizeof name);
    snprintf(path, sizeof path, "%s/%s", s->dir, name);
    s->file = io_h5_create(path, g->comm);
    s->time = time;
    s->step = step;
    s->cur[0] = 0;
    io_h5_attr_double(s->file, "time", time);
    io_h5_attr_long(s->file, "step", step);

    /* Cell faces (mesh nodes) and centres of every direction. */
    int nx = g->n[0], ny = g->n[1], nz = g->n[2];
    double *xf = malloc((size_t)(nx + 1) * sizeof *xf), *yf = malloc((size_t)(ny + 1) * sizeof *yf);
    double *zf = malloc((size_t)(nz + 1) * sizeof *zf);
    for (int i = 0; i <= nx; i++) xf[i] = g->gxf[i - 1];
    for (int j = 0; j <= ny; j++) yf[j] = g->x0[1] + j * g->dy;
    if (g->dim == 3) {
        for (int k = 0; k <= nz; k++) zf[k] = g->x0[2] + k * g->dz;
    } else {
        /* one layer of cells, as thin as the smallest in-plane cell */
        double w = g->dy;
        for (int i = 0; i < nx; i++) w = fmin(w, g->gdxf[i]);
        zf[0] = 0.0;
        zf[1] = w;
    }
    io_h5_write_array(s->file, "x", nx + 1, xf);
    io_h5_write_array(s->file, "y", ny + 1, yf);
    io_h5_write_array(s->file, "z", nz + 1, zf);
    for (int i = 0; i < nx; i++) xf[i] = g->gxc[i];
    for (int j = 0; j < ny; j++) yf[j] = grid_yc(g, j);
    for (int k = 0; k < nz; k++) zf[k] = 0.5 * (zf[k] + zf[k + 1]);
    io_h5_write_array(s->file, "xc", nx, xf);
    io_h5_write_array(s->file, "yc", ny, yf);
    io_h5_write_array(s->file, "zc", nz, zf);
    free(xf);
    free(yf);
    free(zf);
}

static void add_attribute_xml(io_snapshots_t *s, const char *name, int ncomp)
{
    const grid_t *g = s->g;
    char file[64], dims[96], line[1024];
    fields_name(s->count, file, sizeof file);
    if (ncomp > 1)
        snprintf(dims, sizeof dims, "%d %d %d %d", g->n[2], g->n[1], g->n[0], ncomp);
    else
        snprintf(dims, sizeof dims, "%d %d %d", g->n[2], g->n[1], g->n[0]);
    snprintf(line, sizeof line,
             "      <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Cell\">\n"
             "        <DataItem Dimensions=\"%s\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/%s</DataItem>\n"
             "      </Attribute>\n",
             name, ncomp == 3 ? "Vector" : "Scalar", dims, file, name);
    strncat(s->cur, line, sizeof s->cur - strlen(s->cur) - 1);
}

void io_snapshot_cell_scalar(io_snapshots_t *s, const char *name, const double *f)
{
    const grid_t *g = s->g;
    long n = 0;
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->nxl; i++) s->buf[n++] = f[G_IDX(g, i, j, k)];
    io_h5_write_cells_xfast(s->file, name, g, 1, s->buf);
    add_attribute_xml(s, name, 1);
}

void io_snapshot_face_vector(io_snapshots_t *s, const char *name, double *const u[3])
{
    const grid_t *g = s->g;
    long n = 0;
    /* face d of cell (i,j,k) on the low side is the face index one below */
    long off[3] = {g->sx, g->sy, 1};
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++)
            for (int i = 0; i < g->nxl; i++) {
                long c = G_IDX(g, i, j, k);
                for (int d = 0; d < 3; d++)
                    s->buf[n++] = u[d] && (d < 2 || g->dim == 3) ? 0.5 * (u[d][c] + u[d][c - off[d]]) : 0.0;
            }
    io_h5_write_cells_xfast(s->file, name, g, 3, s->buf);
    add_attribute_xml(s, name, 3);
}

static void write_xdmf(const io_snapshots_t *s)
{
    char path[IO_PATH_MAX + 16], tmp[IO_PATH_MAX + 24];
    snprintf(path, sizeof path, "%s/fields.xmf", s->dir);
    FILE *f = atomic_open(path, tmp, sizeof tmp);
    if (!f) return;
    fprintf(f, "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n"
               "  <Domain>\n  <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (int i = 0; i < s->nblock; i++)
        if (s->block[i]) fputs(s->block[i], f);
    fprintf(f, "  </Grid>\n  </Domain>\n</Xdmf>\n");
    atomic_commit(f, tmp, path);
}

void io_snapshots_write_index(const io_snapshots_t *s)
{
    if (s->g->rank == 0) write_xdmf(s);
}

void io_snapshot_end(io_snapshots_t *s)
{
    const grid_t *g = s->g;
    io_h5_close(s->file);
    s->file = -1;
    if (g->rank == 0) {
        char file[64], geo[2048];
        fields_name(s->count, file, sizeof file);
        int nn[3] = {g->n[0] + 1, g->n[1] + 1, g->n[2] + 1};
        snprintf(geo, sizeof geo,
                 "    <Grid Name=\"fields_%05d\" GridType=\"Uniform\">\n"
                 "      <Time Value=\"%.17g\"/>\n"
                 "      <Topology TopologyType=\"3DRectMesh\" Dimensions=\"%d %d %d\"/>\n"
                 "      <Geometry GeometryType=\"VXVYVZ\">\n"
                 "        <DataItem Dimensions=\"%d\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/x</DataItem>\n"
                 "        <DataItem Dimensions=\"%d\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/y</DataItem>\n"
                 "        <DataItem Dimensions=\"%d\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/z</DataItem>\n"
                 "      </Geometry>\n",
                 s->count, s->time, nn[2], nn[1], nn[0], nn[0], file, nn[1], file, nn[2], file);
        size_t len = strlen(geo) + strlen(s->cur) + 32;
        char *b = malloc(len);
        snprintf(b, len, "%s%s    </Grid>\n", geo, s->cur);
        set_block((io_snapshots_t *)s, s->count, b);
        write_xdmf(s);
    }
    s->count++;
}

void io_snapshots_free(io_snapshots_t *s)
{
    if (!s) return;
    for (int i = 0; i < s->nblock; i++) free(s->block[i]);
    free(s->block);
    free(s->buf);
    free(s);
}
