/* state.c — the pore network's exact state in a checkpoint.
 *
 * Between two triangulations a coupled step depends on more than the
 * particles: on the triangulation (built for the positions of its last
 * rebuild, not the current ones), on the pore strain accumulated since
 * (which schedules the next rebuild), on the previous positions and pore
 * volumes (the volume rates of the next step), on the pressures (PCG's
 * starting guess) and on the fluid forces the DEM holds during its next
 * step.  All of them are saved; the triangulation itself is rebuilt from its
 * positions (qhull and the network are deterministic: the same tetrahedra,
 * throats and factorisation). */
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "porenet.h"
#include "porenet_internal.h"

int pn_model_state_write(const pn_model_t *m, hid_t g)
{
    io_h5_attr_long(g, "built", m->built);
    io_h5_attr_long(g, "snapshots", m->nsnap);
    if (m->nsnap > 0) {
        io_h5_write_array(g, "snapshot_time", m->nsnap, m->snap_time);
        double *c = malloc(4 * (size_t)m->nsnap * sizeof *c);
        for (int i = 0; i < 4 * m->nsnap; i++) c[i] = (double)m->snap_counts[i];
        io_h5_write_array(g, "snapshot_counts", 4L * m->nsnap, c);
        free(c);
    }
    if (!m->built) return 0;
    io_h5_attr_long(g, "spheres", m->n);
    io_h5_attr_long(g, "pores", m->net.npore);
    io_h5_attr_long(g, "triangulations", m->n_retri);
    io_h5_attr_long(g, "steps", m->n_steps);
    io_h5_attr_long(g, "volumes_current", m->vol_current);
    io_h5_attr_double(g, "strain_accumulated", m->eps_acc);
    io_h5_attr_double(g, "margin_used", m->margin_used);
    io_h5_write_array(g, "domain_lo", 3, m->dom.lo);
    io_h5_write_array(g, "domain_hi", 3, m->dom.hi);
    io_h5_write_matrix(g, "x_triangulation", m->n, 3, m->x_tri);
    io_h5_write_matrix(g, "x_previous", m->n, 3, m->x_prev);
    io_h5_write_matrix(g, "force", m->n, 3, m->f);
    io_h5_write_array(g, "pressure", m->net.npore, m->p);
    if (m->vol_current) io_h5_write_array(g, "volume", m->net.npore, m->vol);
    return 0;
}

/* Read dataset `name` of exactly n values into v. */
static int read_exact(pn_model_t *m, hid_t g, const char *name, long n, double *v)
{
    if (io_h5_read_array(g, name, n, v) != n)
        return pn_fail(m->err, sizeof m->err, "the checkpoint's /porenet/%s is missing or has not %ld values", name, n);
    return 0;
}

int pn_model_state_read(pn_model_t *m, hid_t g, int n, const double *r)
{
    long built = 0, nsnap = 0;
    if (io_h5_get_attr_long(g, "built", &built) || io_h5_get_attr_long(g, "snapshots", &nsnap))
        return pn_fail(m->err, sizeof m->err, "the checkpoint's /porenet group has no state (written by an older version)");
    m->nsnap = (int)nsnap;
    m->snap_time = realloc(m->snap_time, ((size_t)nsnap + 1) * sizeof *m->snap_time);
    m->snap_counts = realloc(m->snap_counts, (4 * (size_t)nsnap + 1) * sizeof *m->snap_counts);
    if (nsnap > 0) {
        double *c = malloc(4 * (size_t)nsnap * sizeof *c);
        int rc = read_exact(m, g, "snapshot_time", nsnap, m->snap_time) || read_exact(m, g, "snapshot_counts", 4 * nsnap, c);
        for (long i = 0; i < 4 * nsnap && !rc; i++) m->snap_counts[i] = (long)c[i];
        free(c);
        if (rc) return -1;
    }
    if (!built) return 0;
    long ns = 0, npore = 0, retri = 0, steps = 0, vcur = 0;
    double eps = 0;
    if (io_h5_get_attr_long(g, "spheres", &ns) || io_h5_get_attr_long(g, "pores", &npore) ||
        io_h5_get_attr_long(g, "triangulations", &retri) || io_h5_get_attr_long(g, "steps", &steps) ||
        io_h5_get_attr_long(g, "volumes_current", &vcur) || io_h5_get_attr_double(g, "strain_accumulated", &eps))
        return pn_fail(m->err, sizeof m->err, "the checkpoint's /porenet group lacks an attribute of the state");
    if (ns != n)
        return pn_fail(m->err, sizeof m->err, "the checkpoint's network has %ld spheres, the scene %d", ns, n);
    /* the network's box (a part may have moved a face, e.g. the oedometer's drained top) and the image
     * layer the last triangulation started from */
    if (read_exact(m, g, "domain_lo", 3, m->dom.lo) || read_exact(m, g, "domain_hi", 3, m->dom.hi) ||
        io_h5_get_attr_double(g, "margin_used", &m->margin_used))
        return pn_fail(m->err, sizeof m->err, "the checkpoint's /porenet group lacks the network's box");
    double *xt = malloc(3 * (size_t)n * sizeof *xt);
    if (read_exact(m, g, "x_triangulation", 3L * n, xt) || pn_model_rebuild(m, n, xt, r)) {
        free(xt);
        return -1;
    }
    free(xt);
    if (m->net.npore != npore)
        return pn_fail(m->err, sizeof m->err,
                       "the triangulation rebuilt from the checkpoint has %d pores, the run that wrote it had %ld",
                       m->net.npore, npore);
    if (read_exact(m, g, "x_previous", 3L * n, m->x_prev) || read_exact(m, g, "force", 3L * n, m->f) ||
        read_exact(m, g, "pressure", npore, m->p) || (vcur && read_exact(m, g, "volume", npore, m->vol)))
        return -1;
    pn_solver_set_solution(m->sol, m->p, m->net.npore);
    m->margin_warned = 3; /* warned by the run that wrote it */
    m->vol_current = (int)vcur;
    m->eps_acc = eps;
    m->n_retri = retri;
    m->n_steps = steps;
    return 0;
}
