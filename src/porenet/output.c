/* output.c — snapshots of the pore network for ParaView: one HDF5 file per
 * snapshot (written by rank 0: the network is replicated) and an XDMF 2
 * index with, at each time, three unstructured grids: the pore tetrahedra
 * (cell data: pore pressure, pore index), the throats as segments P_i P_j
 * (cell data: flux, conductance) and the spheres as points (fluid force and
 * its pressure and viscous parts, radius). */
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "porenet.h"
#include "util.h"

static void write_ds(hid_t f, const char *name, hid_t type, int rank, const hsize_t *dims, const void *buf)
{
    hid_t sp = H5Screate_simple(rank, dims, NULL);
    hid_t ds = H5Dcreate2(f, name, type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (ds < 0 || H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) {
        char file[4096] = "?";
        H5Fget_name(f, file, sizeof file);
        io_error("cannot write %s in the HDF5 file %s (HDF5 error, see above)", name, file);
    }
    H5Dclose(ds);
    H5Sclose(sp);
}

static void write_xmf(const pn_model_t *m, const char *dir, const long *cnt)
{
    if (mpi_rank() != 0) return;
    char path[4200], tmp[4216];
    snprintf(path, sizeof path, "%s/porenet.xmf", dir);
    FILE *x = atomic_open(path, tmp, sizeof tmp);
    if (!x) return;
    fprintf(x, "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"2.0\">\n<Domain>\n"
               "<Grid Name=\"porenet\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (int s = 0; s < m->nsnap; s++) {
        const long *c = cnt + 4 * s; /* points, tets, throats, spheres */
        char h5[64];
        snprintf(h5, sizeof h5, "porenet_%05d.h5", s);
        fprintf(x, "<Grid Name=\"t%d\" GridType=\"Collection\" CollectionType=\"Spatial\">\n<Time Value=\"%.17g\"/>\n", s,
                m->snap_time[s]);
        fprintf(x,
                "<Grid Name=\"pores\" GridType=\"Uniform\">\n"
                "<Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"%ld\">\n"
                "<DataItem Dimensions=\"%ld 4\" NumberType=\"Int\" Format=\"HDF\">%s:/pores/tets</DataItem>\n</Topology>\n"
                "<Geometry GeometryType=\"XYZ\">\n"
                "<DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/pores/points</DataItem>\n</Geometry>\n"
                "<Attribute Name=\"pressure\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                "<DataItem Dimensions=\"%ld\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/pores/pressure</DataItem>\n</Attribute>\n"
                "<Attribute Name=\"pore\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                "<DataItem Dimensions=\"%ld\" NumberType=\"Int\" Format=\"HDF\">%s:/pores/pore</DataItem>\n</Attribute>\n"
                "</Grid>\n",
                c[1], c[1], h5, c[0], h5, c[1], h5, c[1], h5);
        fprintf(x,
                "<Grid Name=\"throats\" GridType=\"Uniform\">\n"
                "<Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"%ld\">\n"
                "<DataItem Dimensions=\"%ld 2\" NumberType=\"Int\" Format=\"HDF\">%s:/throats/segments</DataItem>\n</Topology>\n"
                "<Geometry GeometryType=\"XYZ\">\n"
                "<DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/throats/points</DataItem>\n</Geometry>\n"
                "<Attribute Name=\"flux\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                "<DataItem Dimensions=\"%ld\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/throats/flux</DataItem>\n</Attribute>\n"
                "<Attribute Name=\"conductance\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                "<DataItem Dimensions=\"%ld\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/throats/conductance</DataItem>\n</Attribute>\n"
                "</Grid>\n",
                c[2], c[2], h5, 2 * c[2], h5, c[2], h5, c[2], h5);
        fprintf(x,
                "<Grid Name=\"spheres\" GridType=\"Uniform\">\n"
                "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%ld\"/>\n"
                "<Geometry GeometryType=\"XYZ\">\n"
                "<DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/spheres/position</DataItem>\n</Geometry>\n",
                c[3], c[3], h5);
        const char *vec[3] = {"force", "force_pressure", "force_viscous"};
        for (int v = 0; v < 3; v++)
            fprintf(x,
                    "<Attribute Name=\"%s\" AttributeType=\"Vector\" Center=\"Node\">\n"
                    "<DataItem Dimensions=\"%ld 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/spheres/%s</DataItem>\n</Attribute>\n",
                    vec[v], c[3], h5, vec[v]);
        fprintf(x,
                "<Attribute Name=\"radius\" AttributeType=\"Scalar\" Center=\"Node\">\n"
                "<DataItem Dimensions=\"%ld\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/spheres/radius</DataItem>\n</Attribute>\n"
                "</Grid>\n</Grid>\n",
                c[3], h5);
    }
    fprintf(x, "</Grid>\n</Domain>\n</Xdmf>\n");
    atomic_commit(x, tmp, path);
}

void pn_write_index(const pn_model_t *m, const char *dir) { write_xmf(m, dir, m->snap_counts); }

void pn_write_snapshot(pn_model_t *m, const double *x, const char *dir, double time)
{
    int s = m->nsnap++;
    m->snap_time = realloc(m->snap_time, (size_t)m->nsnap * sizeof *m->snap_time);
    m->snap_time[s] = time;
    m->snap_counts = realloc(m->snap_counts, 4 * (size_t)m->nsnap * sizeof *m->snap_counts);
    long *counts = m->snap_counts;
    if (mpi_rank() != 0) return;
    const pn_tri_t *t = &m->tri;
    const pn_net_t *net = &m->net;
    /* points used by the pore tetrahedra, renumbered */
    int ntt = net->ntets[net->npore];
    int *map = malloc((size_t)t->npts * sizeof *map);
    for (int i = 0; i < t->npts; i++) map[i] = -1;
    int nv = 0;
    int *tets = malloc(4 * (size_t)ntt * sizeof *tets), *pore = malloc((size_t)ntt * sizeof *pore);
    double *pt = malloc((size_t)ntt * sizeof *pt);
    for (int p = 0; p < net->npore; p++)
        for (int q = net->ntets[p]; q < net->ntets[p + 1]; q++) {
            for (int v = 0; v < 4; v++) {
                int g = t->tet[4 * net->tets[q] + v];
                if (map[g] < 0) map[g] = nv++;
                tets[4 * q + v] = map[g];
            }
            pore[q] = p;
            pt[q] = m->p[p];
        }
    double *xyz = malloc(3 * (size_t)(nv ? nv : 1) * sizeof *xyz);
    for (int i = 0; i < t->npts; i++)
        if (map[i] >= 0) pn_tri_point(&m->dom, t, x, i, xyz + 3 * map[i]);
    int nth = net->nthroat;
    double *seg = malloc(6 * (size_t)(nth ? nth : 1) * sizeof *seg), *flux = malloc((size_t)(nth ? nth : 1) * sizeof *flux);
    int *sidx = malloc(2 * (size_t)(nth ? nth : 1) * sizeof *sidx);
    for (int f = 0; f < nth; f++) {
        const double *Pi = net->P + 3 * net->tp[2 * f];
        for (int a = 0; a < 3; a++) {
            seg[6 * f + a] = Pi[a];
            seg[6 * f + 3 + a] = Pi[a] + net->dx[3 * f + a];
        }
        sidx[2 * f] = 2 * f;
        sidx[2 * f + 1] = 2 * f + 1;
        flux[f] = net->k[f] * pn_throat_dp(&m->dom, net, m->p, f);
    }
    char path[4200];
    snprintf(path, sizeof path, "%s/porenet_%05d.h5", dir, s);
    hid_t h = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (h < 0) {
        io_error("cannot create the HDF5 file %s (HDF5 error, see above)", path);
    } else {
        hid_t g1 = H5Gcreate2(h, "pores", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        hsize_t d2[2] = {(hsize_t)nv, 3}, d4[2] = {(hsize_t)ntt, 4}, d1 = (hsize_t)ntt;
        write_ds(g1, "points", H5T_NATIVE_DOUBLE, 2, d2, xyz);
        write_ds(g1, "tets", H5T_NATIVE_INT, 2, d4, tets);
        write_ds(g1, "pressure", H5T_NATIVE_DOUBLE, 1, &d1, pt);
        write_ds(g1, "pore", H5T_NATIVE_INT, 1, &d1, pore);
        H5Gclose(g1);
        hid_t g2 = H5Gcreate2(h, "throats", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        hsize_t e2[2] = {2 * (hsize_t)nth, 3}, e3[2] = {(hsize_t)nth, 2}, e1 = (hsize_t)nth;
        write_ds(g2, "points", H5T_NATIVE_DOUBLE, 2, e2, seg);
        write_ds(g2, "segments", H5T_NATIVE_INT, 2, e3, sidx);
        write_ds(g2, "flux", H5T_NATIVE_DOUBLE, 1, &e1, flux);
        write_ds(g2, "conductance", H5T_NATIVE_DOUBLE, 1, &e1, net->k);
        H5Gclose(g2);
        hid_t g3 = H5Gcreate2(h, "spheres", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        double *rad = malloc((size_t)m->n * sizeof *rad);
        for (int i = 0; i < t->npts; i++)
            if (t->img[3 * i] == 0 && t->img[3 * i + 1] == 0 && t->img[3 * i + 2] == 0) rad[t->id[i]] = t->r[i];
        hsize_t s2[2] = {(hsize_t)m->n, 3}, s1 = (hsize_t)m->n;
        write_ds(g3, "position", H5T_NATIVE_DOUBLE, 2, s2, x);
        write_ds(g3, "force", H5T_NATIVE_DOUBLE, 2, s2, m->f);
        {
            /* the two parts (the steps compute their sum only) */
            double *fs = malloc(3 * (size_t)m->n * sizeof *fs);
            pn_forces(&m->dom, t, net, m->p, m->n, fs, m->fp, m->fv);
            free(fs);
        }
        write_ds(g3, "force_pressure", H5T_NATIVE_DOUBLE, 2, s2, m->fp);
        write_ds(g3, "force_viscous", H5T_NATIVE_DOUBLE, 2, s2, m->fv);
        write_ds(g3, "radius", H5T_NATIVE_DOUBLE, 1, &s1, rad);
        free(rad);
        H5Gclose(g3);
        if (H5Fclose(h) < 0) {
            io_error("cannot write the HDF5 file %s (HDF5 error, see above)", path);
            mpi_finalize_unsafe(); /* the file is left half closed (HDF5 1.10) */
        }
        else fsync_path(path); /* on the disk before the next checkpoint */
    }
    counts[4 * s] = nv;
    counts[4 * s + 1] = ntt;
    counts[4 * s + 2] = nth;
    counts[4 * s + 3] = m->n;
    write_xmf(m, dir, counts);
    free(map), free(tets), free(pore), free(pt), free(xyz), free(seg), free(flux), free(sidx);
}
