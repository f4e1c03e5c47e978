#include "clod/mesh_validation.h"

#include <algorithm>
#include <numeric>
#include <sstream>
#include <string>

#include "clod/mesh_topology.h"

namespace clod {

namespace {

class UnionFind {
public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];  // path halving
      x = parent_[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

private:
  std::vector<std::uint32_t> parent_;
};

std::string plural(std::uint32_t n, const char* singular, const char* pluralForm) {
  return std::to_string(n) + " " + (n == 1 ? singular : pluralForm);
}

std::string formatVec(const Vec3& v) {
  return std::string("(").append(std::to_string(v.x())).append(", ").append(std::to_string(v.y())).append(", ").append(std::to_string(v.z())).append(")");
}

// Index of the corner of triangle t that holds vertex v (t must contain v).
int cornerOf(const Triangle& t, std::uint32_t v) { return t[0] == v ? 0 : (t[1] == v ? 1 : 2); }

}  // namespace

MeshReport validateMesh(const TriangleMesh& mesh) {
  MeshReport r;
  r.vertexCount = mesh.vertexCount();
  r.triangleCount = mesh.triangleCount();
  auto fatal = [&](ErrorCode code, std::string message) { r.issues.push_back({code, std::move(message)}); };
  auto warn = [&](std::string message) { r.issues.push_back({std::nullopt, std::move(message)}); };

  // --- fatal: coordinates ---
  for (std::uint32_t v = 0; v < r.vertexCount; ++v) {
    const Vec3& p = mesh.vertices[v];
    if (p.allFinite()) {
      r.bounds.extend(p);
      continue;
    }
    if (++r.nonFiniteVertices <= kMaxListedIssues)
      fatal(ErrorCode::kNonFiniteVertex, "vertex " + std::to_string(v) + ": non-finite coordinate " + formatVec(p));
  }
  if (r.nonFiniteVertices > kMaxListedIssues)
    fatal(ErrorCode::kNonFiniteVertex, plural(r.nonFiniteVertices, "vertex", "vertices") + " with non-finite coordinates in all");

  // --- fatal: indices ---
  for (std::uint32_t t = 0; t < r.triangleCount; ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < r.vertexCount) continue;
      if (++r.outOfRangeTriangles <= kMaxListedIssues)
        fatal(ErrorCode::kIndexOutOfRange, "triangle " + std::to_string(t) + ": vertex index " + std::to_string(tri[k]) +
                                               " >= vertex count " + std::to_string(r.vertexCount));
      break;
    }
  }
  if (r.outOfRangeTriangles > kMaxListedIssues)
    fatal(ErrorCode::kIndexOutOfRange, plural(r.outOfRangeTriangles, "triangle", "triangles") + " with out-of-range indices in all");

  if (r.triangleCount == 0) {
    fatal(ErrorCode::kNoTriangles, "the mesh has no triangles (" + plural(r.vertexCount, "vertex", "vertices") + ")");
    return r;
  }
  if (r.outOfRangeTriangles > 0) return r;  // topology needs valid indices

  // --- size: the range clod computes with (kMinMeshDiagonal, mesh_validation.h) ---
  const double diagonal = r.bounds.diagonal();
  if (r.nonFiniteVertices == 0 && !(diagonal >= kMinMeshDiagonal && diagonal <= kMaxMeshDiagonal)) {
    std::ostringstream text;
    text << "bounding-box diagonal " << diagonal << " is outside the supported range [" << kMinMeshDiagonal << ", "
         << kMaxMeshDiagonal << "] (mesh units): scale the mesh";
    fatal(ErrorCode::kUnsupportedMesh, text.str());
    return r;
  }

  // --- degenerate triangles ---
  const double crossLimit = kDegenerateCrossRel * diagonal * diagonal;
  std::uint32_t firstDegenerate = 0;
  for (std::uint32_t t = 0; t < r.triangleCount; ++t) {
    const Triangle& tri = mesh.triangles[t];
    const bool repeated = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
    // A NaN cross product compares false, so triangles touching a non-finite vertex are not
    // called degenerate here: the non-finite vertex is already the fatal finding.
    if (repeated || mesh.triangleCross(t).norm() <= crossLimit) {
      if (r.degenerateTriangles++ == 0) firstDegenerate = t;
    }
  }
  if (r.degenerateTriangles == r.triangleCount)
    fatal(ErrorCode::kAllTrianglesDegenerate,
          "all " + plural(r.triangleCount, "triangle has", "triangles have") + " zero area (bounding-box diagonal " +
              std::to_string(diagonal) + ")");
  else if (r.degenerateTriangles > 0)
    warn(plural(r.degenerateTriangles, "degenerate (zero-area) triangle", "degenerate (zero-area) triangles") +
         ", first: triangle " + std::to_string(firstDegenerate));

  // --- flat: all vertices in an axis-aligned plane (or line); the mesh encloses nothing ---
  if (diagonal > 0.0) {
    const Vec3 extent = r.bounds.extent();
    for (int axis = 0; axis < 3; ++axis)
      if (extent[axis] == 0.0) {
        warn(std::string("the mesh is flat: zero extent along ") + "xyz"[axis]);
        break;
      }
  }

  // --- duplicates: sort each triangle's corner set, then the list ---
  {
    std::vector<std::pair<Triangle, std::uint32_t>> sorted(r.triangleCount);
    for (std::uint32_t t = 0; t < r.triangleCount; ++t) {
      Triangle key = mesh.triangles[t];
      std::sort(key.begin(), key.end());
      sorted[t] = {key, t};
    }
    std::sort(sorted.begin(), sorted.end());
    std::uint32_t firstDuplicate = 0;
    for (std::size_t i = 1; i < sorted.size(); ++i)
      if (sorted[i].first == sorted[i - 1].first && r.duplicateTriangles++ == 0) firstDuplicate = sorted[i].second;
    if (r.duplicateTriangles > 0)
      warn(plural(r.duplicateTriangles, "duplicate triangle", "duplicate triangles") + ", e.g. triangle " +
           std::to_string(firstDuplicate));
  }

  // --- edges ---
  const MeshTopology topology(mesh);
  r.edgeCount = topology.edgeCount();
  r.boundaryEdges = topology.boundaryEdgeCount();
  r.nonManifoldEdges = topology.nonManifoldEdgeCount();
  r.closed = topology.closed();
  if (r.boundaryEdges > 0) warn(plural(r.boundaryEdges, "boundary edge", "boundary edges") + ": the mesh is open");
  if (r.nonManifoldEdges > 0)
    warn(plural(r.nonManifoldEdges, "non-manifold edge", "non-manifold edges") + " (shared by 3 or more triangles)");

  // --- orientation and non-manifold vertices ---
  // Corners 3t+k are glued across every edge their triangles share; the groups of corners of one
  // vertex are its fans. A manifold vertex has one fan.
  UnionFind corners(std::size_t(r.triangleCount) * 3);
  for (std::uint32_t e = 0; e < r.edgeCount; ++e) {
    const auto tris = topology.edgeTriangles(e);
    const Edge edge = topology.edges()[e];
    if (edge.v0 == edge.v1) continue;  // a collapsed triangle's self-loop joins nothing
    for (std::size_t i = 1; i < tris.size(); ++i) {
      const Triangle& a = mesh.triangles[tris[0]];
      const Triangle& b = mesh.triangles[tris[i]];
      corners.unite(3 * tris[0] + cornerOf(a, edge.v0), 3 * tris[i] + cornerOf(b, edge.v0));
      corners.unite(3 * tris[0] + cornerOf(a, edge.v1), 3 * tris[i] + cornerOf(b, edge.v1));
    }
    if (tris.size() == 2) {
      // Opposite traversal: in one triangle v0 -> v1 follows the winding, in the other v1 -> v0.
      const Triangle& a = mesh.triangles[tris[0]];
      const Triangle& b = mesh.triangles[tris[1]];
      const bool aForward = a[(cornerOf(a, edge.v0) + 1) % 3] == edge.v1;
      const bool bForward = b[(cornerOf(b, edge.v0) + 1) % 3] == edge.v1;
      if (aForward == bForward) ++r.inconsistentEdges;
    }
  }
  r.consistentlyOriented = r.inconsistentEdges == 0;
  if (!r.consistentlyOriented)
    warn(plural(r.inconsistentEdges, "edge is", "edges are") +
         " traversed in the same direction by both triangles: orientation is inconsistent");

  std::vector<std::uint32_t> fans(r.vertexCount, 0);
  for (std::uint32_t t = 0; t < r.triangleCount; ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      // Repeated corners of a collapsed triangle are one corner of that vertex.
      if ((k == 1 && tri[1] == tri[0]) || (k == 2 && (tri[2] == tri[0] || tri[2] == tri[1]))) continue;
      const std::uint32_t c = 3 * t + std::uint32_t(k);
      if (corners.find(c) == c) ++fans[tri[k]];
    }
  }
  std::uint32_t firstNonManifoldVertex = 0;
  for (std::uint32_t v = 0; v < r.vertexCount; ++v) {
    if (fans[v] == 0) ++r.unreferencedVertices;
    if (fans[v] > 1 && r.nonManifoldVertices++ == 0) firstNonManifoldVertex = v;
  }
  if (r.nonManifoldVertices > 0)
    warn(plural(r.nonManifoldVertices, "non-manifold vertex", "non-manifold vertices") +
         " (the triangles around each form several fans), first: vertex " + std::to_string(firstNonManifoldVertex));
  if (r.unreferencedVertices > 0)
    warn(plural(r.unreferencedVertices, "vertex is", "vertices are") + " used by no triangle");

  // --- components: union-find over vertices ---
  {
    UnionFind vertices(r.vertexCount);
    for (const Triangle& tri : mesh.triangles) {
      vertices.unite(tri[0], tri[1]);
      vertices.unite(tri[0], tri[2]);
    }
    for (std::uint32_t v = 0; v < r.vertexCount; ++v)
      if (fans[v] > 0 && vertices.find(v) == v) ++r.components;
    if (r.components > 1) warn(plural(r.components, "connected component", "connected components"));
  }

  // --- volume ---
  if (r.closed && r.consistentlyOriented && r.nonFiniteVertices == 0) {
    // Relative to the box centre so the rounding error scales with the mesh size, not its offset.
    const Vec3 o = r.bounds.center();
    double sum = 0.0;
    for (std::uint32_t t = 0; t < r.triangleCount; ++t)
      sum += (mesh.corner(t, 0) - o).dot((mesh.corner(t, 1) - o).cross(mesh.corner(t, 2) - o));
    r.signedVolume = sum / 6.0;
    if (*r.signedVolume < 0.0) warn("the mesh is inside-out (signed volume " + std::to_string(*r.signedVolume) + " < 0)");
    if (*r.signedVolume == 0.0) warn("the closed mesh encloses zero volume (flat)");
  } else if (r.closed && !r.consistentlyOriented) {
    warn("the mesh is closed but inconsistently oriented: no volume");
  }

  // Fatal findings first, in the order throwIfUnusable reports them.
  std::stable_partition(r.issues.begin(), r.issues.end(), [](const MeshIssue& i) { return i.fatal.has_value(); });
  return r;
}

void throwIfUnusable(const MeshReport& report) {
  const MeshIssue* first = nullptr;
  std::uint32_t fatalCount = 0;
  for (const MeshIssue& issue : report.issues) {
    if (!issue.fatal) continue;
    if (!first) first = &issue;
    ++fatalCount;
  }
  if (!first) return;
  std::string message = first->message;
  if (fatalCount > 1) message += " (and " + std::to_string(fatalCount - 1) + " more fatal issues)";
  throw Error(*first->fatal, message);
}

MeshReport requireValidMesh(const TriangleMesh& mesh) {
  MeshReport report = validateMesh(mesh);
  throwIfUnusable(report);
  return report;
}

void flipOrientation(TriangleMesh& mesh) {
  for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
}

}  // namespace clod
