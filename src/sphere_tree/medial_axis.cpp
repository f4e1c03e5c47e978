#include "medial_axis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <unordered_map>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}


namespace clod::detail {

SurfaceSamples sampleSurface(const TriangleMesh& mesh, std::uint32_t target, std::uint32_t seed) {
  SurfaceSamples s;
  double totalArea = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) totalArea += mesh.triangleArea(t);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  if (mesh.vertexCount() <= target) {
    // Vertex normals: area-weighted average of the incident faces (only used for the
    // interior vote, so a rough normal at sharp corners is fine).
    std::vector<Vec3> vertexNormal(mesh.vertexCount(), Vec3::Zero());
    for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t)
      for (int k = 0; k < 3; ++k) vertexNormal[mesh.triangles[t][k]] += mesh.triangleCross(t);
    for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
      const double len = vertexNormal[v].norm();
      if (len <= 0.0) continue;  // unreferenced or only in degenerate triangles
      s.position.push_back(mesh.vertices[v]);
      s.normal.push_back(vertexNormal[v] / len);
    }
  }
  if (totalArea > 0.0) {
    const double perArea = target / totalArea;
    for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) {
      const double expected = mesh.triangleArea(t) * perArea;
      // Stochastic rounding keeps the expected count exact for meshes with tiny triangles.
      const auto count = static_cast<std::uint32_t>(expected + uniform(rng));
      const Vec3 n = mesh.triangleNormal(t);
      for (std::uint32_t i = 0; i < count; ++i) {
        double u = uniform(rng), v = uniform(rng);
        if (u + v > 1.0) {
          u = 1.0 - u;
          v = 1.0 - v;
        }
        s.position.push_back(mesh.corner(t, 0) + u * (mesh.corner(t, 1) - mesh.corner(t, 0)) +
                             v * (mesh.corner(t, 2) - mesh.corner(t, 0)));
        s.normal.push_back(n);
      }
    }
  }
  s.poleCenter = s.position;
  s.poleRadius.assign(s.position.size(), 0.0);
  s.poleId.resize(s.position.size());
  for (std::uint32_t i = 0; i < s.size(); ++i) s.poleId[i] = i;
  return s;
}

namespace {

constexpr unsigned kNoFacet = ~0u;

// Circumcentre of a tetrahedron; false when it is (nearly) flat.
bool circumcenter(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, Vec3& center) {
  Mat3 m;
  m.row(0) = (b - a).transpose();
  m.row(1) = (c - a).transpose();
  m.row(2) = (d - a).transpose();
  const Vec3 rhs(0.5 * (b - a).squaredNorm(), 0.5 * (c - a).squaredNorm(), 0.5 * (d - a).squaredNorm());
  const double det = m.determinant();
  const double scale = m.row(0).norm() * m.row(1).norm() * m.row(2).norm();
  if (!(std::abs(det) > 1e-10 * scale)) return false;
  center = a + m.partialPivLu().solve(rhs);
  return center.allFinite();
}

}  // namespace

void computeInnerPoles(SurfaceSamples& samples, const Aabb& bounds) {
  const std::uint32_t n = samples.size();
  if (n < 5) return;
  std::vector<coordT> coords(static_cast<std::size_t>(n) * 3);
  for (std::uint32_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) coords[3 * static_cast<std::size_t>(i) + a] = samples.position[i][a];

  // qhull reports errors on a FILE*; capture them in memory so the library never prints.
  char* errorText = nullptr;
  std::size_t errorSize = 0;
  FILE* errorStream = open_memstream(&errorText, &errorSize);
  if (errorStream == nullptr) errorStream = std::fopen("/dev/null", "w");
  if (errorStream == nullptr) return;  // no stream to silence qhull with: go without poles
  qhT qhStorage;
  qhT* qh = &qhStorage;
  qh_zero(qh, errorStream);
  // d: Delaunay; Qbb: scale the lifted coordinate for precision; QJ: joggle the input so every
  // facet is a tetrahedron. Without QJ, the co-planar and co-spherical samples of CAD parts and
  // primitives make qhull merge facets, which took over a minute on fandisk; the joggle is tiny
  // and circumcentres are computed from the exact sample positions anyway.
  char flags[] = "qhull d Qbb QJ";
  const int exitCode = qh_new_qhull(qh, 3, static_cast<int>(n), coords.data(), False, flags, nullptr, errorStream);
  std::vector<unsigned> poleFacet(n, kNoFacet);
  if (exitCode == 0) {
    const double diagonal = bounds.diagonal();
    const Vec3 lo = bounds.min, hi = bounds.max;
    facetT* facet;
    FORALLfacets {
      if (facet->upperdelaunay) continue;
      std::uint32_t ids[4];
      int count = 0;
      vertexT* vertex;
      vertexT** vertexp;
      FOREACHvertex_(facet->vertices) {
        if (count < 4) ids[count] = static_cast<std::uint32_t>(qh_pointid(qh, vertex->point));
        ++count;
      }
      if (count != 4) continue;
      bool valid = true;
      for (std::uint32_t id : ids) valid = valid && id < n;
      if (!valid) continue;
      Vec3 c;
      if (!circumcenter(samples.position[ids[0]], samples.position[ids[1]], samples.position[ids[2]],
                        samples.position[ids[3]], c))
        continue;
      // An interior medial ball lies inside the bounding box.
      if ((c.array() < lo.array()).any() || (c.array() > hi.array()).any()) continue;
      const double r = (c - samples.position[ids[0]]).norm();
      if (!(r < 0.5 * diagonal)) continue;
      int vote = 0;
      for (std::uint32_t id : ids) vote += (c - samples.position[id]).dot(samples.normal[id]) < 0.0 ? 1 : -1;
      if (vote <= 0) continue;
      for (std::uint32_t id : ids)
        if (r > samples.poleRadius[id]) {
          samples.poleRadius[id] = r;
          samples.poleCenter[id] = c;
          poleFacet[id] = facet->id;
        }
    }
  }
  // Compact ids: samples without a pole keep their own index, poles are numbered from n on.
  std::unordered_map<unsigned, std::uint32_t> poleIndex;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (poleFacet[i] == kNoFacet) continue;
    const auto inserted = poleIndex.emplace(poleFacet[i], n + static_cast<std::uint32_t>(poleIndex.size()));
    samples.poleId[i] = inserted.first->second;
  }
  int curlong = 0, totlong = 0;
  qh_freeqhull(qh, !qh_ALL);
  qh_memfreeshort(qh, &curlong, &totlong);
  std::fclose(errorStream);
  std::free(errorText);
  // qhull fails on input without volume (all samples in one plane: a flat mesh). Such a surface
  // has no interior medial axis; the samples keep no pole and the builder clusters the surface.
  }

SampleGrid::SampleGrid(const std::vector<Vec3>& positions, double cellSize) : positions_(&positions) {
  Aabb box;
  for (const Vec3& p : positions) box.extend(p);
  origin_ = box.min;
  const Vec3 extent = box.extent();
  double size = std::max(cellSize, 1e-300);
  // Keep the grid small: at most 256 cells per axis.
  size = std::max(size, extent.maxCoeff() / 256.0);
  if (!(size > 0.0)) size = 1.0;
  cellSize_ = size;
  for (int a = 0; a < 3; ++a) dims_[a] = std::max(1, static_cast<std::int32_t>(std::floor(extent[a] / size)) + 1);
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  cellStart_.assign(cells + 1, 0);
  std::vector<std::uint32_t> cellOf(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    std::int32_t c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(static_cast<std::int32_t>((positions[i][a] - origin_[a]) / size), 0, dims_[a] - 1);
    cellOf[i] = static_cast<std::uint32_t>((static_cast<std::size_t>(c[2]) * dims_[1] + c[1]) * dims_[0] + c[0]);
    ++cellStart_[cellOf[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
  items_.resize(positions.size());
  std::vector<std::uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
  for (std::size_t i = 0; i < positions.size(); ++i) items_[fill[cellOf[i]]++] = static_cast<std::uint32_t>(i);
}

std::uint32_t SampleGrid::nearest(const Vec3& p) const {
  std::int32_t c[3];
  for (int a = 0; a < 3; ++a)
    c[a] = std::clamp(static_cast<std::int32_t>(std::floor((p[a] - origin_[a]) / cellSize_)), 0, dims_[a] - 1);
  const std::int32_t maxRing = std::max({dims_[0], dims_[1], dims_[2]});
  std::uint32_t best = 0;
  double bestD2 = std::numeric_limits<double>::infinity();
  for (std::int32_t ring = 0; ring <= maxRing; ++ring) {
    // Every sample in a cell of ring `ring` is at least (ring - 1) cells away from p.
    const double reach = (ring - 1) * cellSize_;
    if (ring > 0 && reach > 0.0 && reach * reach > bestD2) break;
    for (std::int32_t z = c[2] - ring; z <= c[2] + ring; ++z) {
      if (z < 0 || z >= dims_[2]) continue;
      for (std::int32_t y = c[1] - ring; y <= c[1] + ring; ++y) {
        if (y < 0 || y >= dims_[1]) continue;
        for (std::int32_t x = c[0] - ring; x <= c[0] + ring; ++x) {
          if (x < 0 || x >= dims_[0]) continue;
          if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != ring) continue;
          const std::size_t cell = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
          for (std::uint32_t k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
            const double d2 = ((*positions_)[items_[k]] - p).squaredNorm();
            if (d2 < bestD2) {
              bestD2 = d2;
              best = items_[k];
            }
          }
        }
      }
    }
  }
  return best;
}

}  // namespace clod::detail
