#include "geometry/convex_hull.h"

#include <cstdio>
#include <cstdlib>

#include <libqhull_r/qhull_ra.h>

namespace clod::detail {

bool convexHullVertices(std::span<const Vec3> points, std::size_t maxVertices, std::vector<std::uint32_t>& out) {
  if (points.size() < 4) return false;
  std::vector<coordT> coords(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a) coords[3 * i + a] = points[i][a];
  // qhull reports errors on a FILE*: capture them in memory so the library never prints.
  char* errorText = nullptr;
  std::size_t errorSize = 0;
  FILE* errorStream = open_memstream(&errorText, &errorSize);
  if (errorStream == nullptr) return false;
  qhT qhStorage;
  qhT* qh = &qhStorage;
  qh_zero(qh, errorStream);
  char flags[] = "qhull QJ";
  const int exitCode = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False, flags, nullptr, errorStream);
  bool ok = exitCode == 0 && std::size_t(qh->num_vertices) <= maxVertices;
  if (ok) {
    out.clear();
    vertexT* vertex;
    FORALLvertices {
      const int id = qh_pointid(qh, vertex->point);
      if (id < 0 || std::size_t(id) >= points.size()) {
        ok = false;
        break;
      }
      out.push_back(static_cast<std::uint32_t>(id));
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  std::fclose(errorStream);
  std::free(errorText);
  return ok;
}

}  // namespace clod::detail
