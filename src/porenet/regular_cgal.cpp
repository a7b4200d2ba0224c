// regular_cgal.cpp — the regular (weighted Delaunay) triangulation of the
// extended point set by CGAL's Regular_triangulation_3 (exact predicates,
// inexact constructions; the triangulation YADE's FlowEngine uses), behind the
// C interface of porenet_internal.h (pn_cgal_regular).  Points are inserted
// at once (spatial sort); a hidden point (a sphere whose power cell is empty)
// is no vertex.  Every finite cell is a tetrahedron of positive volume:
// co-spherical sets (lattices, the mirror-symmetric sets at a wall) are split
// by CGAL's symbolic perturbation, and network.c merges the tetrahedra that
// share a power centre, as it does qhull's split.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <utility>
#include <vector>

extern "C" {
#include "porenet_internal.h"
}

namespace {
typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Regular_triangulation_vertex_base_3<K> Vb0;
typedef CGAL::Triangulation_vertex_base_with_info_3<int, K, Vb0> Vb;
/* hidden points are not kept (nothing asks for them) */
typedef CGAL::Regular_triangulation_cell_base_3<K, CGAL::Triangulation_cell_base_3<K>,
                                                CGAL::Hidden_points_memory_policy<CGAL::Tag_false>>
    Cb0;
typedef CGAL::Triangulation_cell_base_with_info_3<int, K, Cb0> Cb;
typedef CGAL::Triangulation_data_structure_3<Vb, Cb> Tds;
typedef CGAL::Regular_triangulation_3<K, Tds> Rt;
typedef K::Weighted_point_3 Wp;
} // namespace

extern "C" int pn_cgal_regular(int np, const double *x, const double *r, int *ntet, int **tet, int **nbr, double **P,
                               char *err, size_t nerr)
{
    *ntet = 0;
    *tet = *nbr = NULL;
    *P = NULL;
    try {
        std::vector<std::pair<Wp, int>> pts;
        pts.reserve((size_t)np);
        for (int i = 0; i < np; i++)
            pts.emplace_back(Wp(K::Point_3(x[3 * i], x[3 * i + 1], x[3 * i + 2]), r[i] * r[i]), i);
        Rt rt(pts.begin(), pts.end());
        int nt = 0;
        for (Rt::Finite_cells_iterator c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) c->info() = nt++;
        int *T = (int *)malloc(4 * (size_t)(nt + 1) * sizeof *T), *N = (int *)malloc(4 * (size_t)(nt + 1) * sizeof *N);
        double *C = (double *)malloc(3 * (size_t)(nt + 1) * sizeof *C);
        if (!T || !N || !C) {
            free(T), free(N), free(C);
            return pn_fail(err, nerr, "CGAL: out of memory for %d tetrahedra", nt);
        }
        Rt::Geom_traits::Construct_weighted_circumcenter_3 centre =
            rt.geom_traits().construct_weighted_circumcenter_3_object();
        for (Rt::Finite_cells_iterator c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
            const int k = c->info();
            for (int v = 0; v < 4; v++) {
                T[4 * k + v] = c->vertex(v)->info();
                Rt::Cell_handle nb = c->neighbor(v); // opposite vertex v
                N[4 * k + v] = rt.is_infinite(nb) ? -1 : nb->info();
            }
            const K::Point_3 p = centre(c->vertex(0)->point(), c->vertex(1)->point(), c->vertex(2)->point(),
                                        c->vertex(3)->point());
            C[3 * k] = p.x(), C[3 * k + 1] = p.y(), C[3 * k + 2] = p.z();
        }
        *ntet = nt;
        *tet = T;
        *nbr = N;
        *P = C;
        return 0;
    } catch (const std::exception &e) {
        return pn_fail(err, nerr, "CGAL regular triangulation: %s", e.what());
    }
}
