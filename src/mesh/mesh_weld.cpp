#include "clod/mesh_weld.h"

#include <cmath>
#include <unordered_map>

#include "clod/error.h"

namespace clod {

namespace {

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};

struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const noexcept {
    // Large odd multipliers spread neighbouring cells over the table (Teschner et al. 2003 style).
    std::uint64_t h = std::uint64_t(k.x) * 73856093ULL ^ std::uint64_t(k.y) * 19349663ULL ^
                      std::uint64_t(k.z) * 83492791ULL;
    h ^= h >> 29;
    return static_cast<std::size_t>(h * 0xbf58476d1ce4e5b9ULL);
  }
};

constexpr std::uint32_t kNone = 0xffffffffu;

}  // namespace

WeldResult weldVertices(TriangleMesh& mesh, double toleranceAbs) {
  CLOD_ASSERT(toleranceAbs >= 0.0);
  const std::uint32_t n = mesh.vertexCount();
  WeldResult result;
  result.remap.assign(n, kNone);
  std::vector<Vec3> kept;
  kept.reserve(n);

  // Cells of side >= tolerance: any point within tolerance of p lies in p's cell or one of its
  // 26 neighbours. With tolerance 0 the cell side is irrelevant (only equal points match, and
  // they share a cell), so pick one that keeps cell coordinates in range.
  const Aabb box = mesh.bounds();
  const double diagonal = box.diagonal();
  double cell = toleranceAbs;
  // Keep cell indices well inside int64 even for tiny tolerances on huge meshes.
  if (cell < diagonal * 1e-12 || cell == 0.0) cell = diagonal > 0.0 ? diagonal * 1e-12 : 1.0;
  const double tol2 = toleranceAbs * toleranceAbs;

  // Each cell holds the head of a singly linked list (through `next`) of output vertices.
  std::unordered_map<CellKey, std::uint32_t, CellKeyHash> heads;
  heads.reserve(n);
  std::vector<std::uint32_t> next;
  next.reserve(n);

  auto keyOf = [&](const Vec3& p) {
    const Vec3 q = (p - box.min) / cell;
    return CellKey{std::int64_t(std::floor(q.x())), std::int64_t(std::floor(q.y())),
                   std::int64_t(std::floor(q.z()))};
  };

  for (std::uint32_t i = 0; i < n; ++i) {
    const Vec3& p = mesh.vertices[i];
    CLOD_ASSERT(p.allFinite());
    const CellKey key = keyOf(p);
    std::uint32_t match = kNone;
    // Scan all 27 cells and keep the smallest index in range, so the result depends on the
    // input order only, never on hash order.
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = heads.find({key.x + dx, key.y + dy, key.z + dz});
          if (it == heads.end()) continue;
          for (std::uint32_t j = it->second; j != kNone; j = next[j])
            if (j < match && (kept[j] - p).squaredNorm() <= tol2) match = j;
        }
    if (match != kNone) {
      result.remap[i] = match;
      continue;
    }
    const std::uint32_t id = static_cast<std::uint32_t>(kept.size());
    kept.push_back(p);
    auto [it, inserted] = heads.try_emplace(key, id);
    next.push_back(inserted ? kNone : it->second);
    if (!inserted) it->second = id;
    result.remap[i] = id;
  }

  result.mergedCount = n - static_cast<std::uint32_t>(kept.size());
  mesh.vertices = std::move(kept);
  for (Triangle& t : mesh.triangles) {
    for (std::uint32_t& index : t) {
      CLOD_ASSERT(index < n);
      index = result.remap[index];
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) ++result.collapsedTriangles;
  }
  return result;
}

}  // namespace clod
