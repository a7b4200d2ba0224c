/* network_internal.h — shared by network.c and network_yade.c: small vector
 * geometry and the YADE wall throats. */
#ifndef IBMDEM_NETWORK_INTERNAL_H
#define IBMDEM_NETWORK_INTERNAL_H

#include <math.h>

#include "porenet.h"

static inline void sub3(const double *a, const double *b, double *c)
{
    for (int k = 0; k < 3; k++) c[k] = a[k] - b[k];
}
static inline double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static inline double norm3(const double *a) { return sqrt(dot3(a, a)); }

/* Angle at o of the triangle (o, a, b): the sector ½ r² θ of a sphere centred at o. */
static inline double angle_at(const double *o, const double *a, const double *b)
{
    double u[3], v[3];
    sub3(a, o, u);
    sub3(b, o, v);
    const double den = norm3(u) * norm3(v);
    return den > 0 ? acos(fmax(-1.0, fmin(1.0, dot3(u, v) / den))) : 0.5 * M_PI;
}

/* Solid angle of triangle (a, b, c) seen from o (Van Oosterom & Strackee 1983). */
static inline double solid_angle(const double *o, const double *a, const double *b, const double *c)
{
    double A[3], B[3], C[3], bc[3];
    sub3(a, o, A);
    sub3(b, o, B);
    sub3(c, o, C);
    double na = norm3(A), nb = norm3(B), nc = norm3(C);
    cross3(B, C, bc);
    double det = dot3(A, bc);
    double den = na * nb * nc + dot3(A, B) * nc + dot3(A, C) * nb + dot3(B, C) * na;
    return fabs(2.0 * atan2(det, den));
}

/* Signed volume of a tetrahedron. */
static inline double tet_volume(const double *a, const double *b, const double *c, const double *d)
{
    double u[3], v[3], w[3], x[3];
    sub3(b, a, u);
    sub3(c, a, v);
    sub3(d, a, w);
    cross3(v, w, x);
    return dot3(u, x) / 6.0;
}

/* porenet.wall_throats = yade: the wall throats' conductances replaced by YADE's
 * (network_yade.c); tplane[f] < 0 marks a throat on a slip plane. */
void pn_wall_throats_yade(const pn_domain_t *dom, const pn_params_t *prm, const pn_tri_t *t, pn_net_t *net,
                          const int *tplane);

#endif
