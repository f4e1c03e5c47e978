#pragma once
// A body's precomputed collision data, bundled for the narrow phase (query.h): the mesh, its
// sphere-tree, and optionally its closest feature map (needed by the cfm and average models) and
// its contact tree (needed by the contact-tree model). Everything is in the body's own (mesh)
// coordinates; a query places two bodies in the world with a Pose each.
//
// Build once (from a bake file or from parts), then share: a CollisionBody is immutable after
// construction and any number of threads may query it at once.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/contact_tree.h"
#include "clod/mesh.h"
#include "clod/proximity.h"
#include "clod/sphere_tree.h"

namespace clod {

struct BakeContents;
namespace detail {
class TriangleBvh;
}

class CollisionBody {
public:
  /// A body from its mesh and the sphere-tree built for it. Checks that the tree fits the mesh
  /// and throws clod::Error(kInvalidArgument) naming the culprit otherwise: an empty tree,
  /// arrays of inconsistent length, a child range outside the next level, a triangle index >=
  /// the mesh's triangle count. O(spheres + triangle references).
  CollisionBody(TriangleMesh mesh, SphereTree tree);

  /// Everything a bake holds (mesh, sphere-tree, and closest feature map and contact tree where
  /// the bake has those sections). Same checks as above.
  static CollisionBody fromBake(const BakeContents& bake);

  /// Adds the closest feature map (built for this body's sphere-tree). Throws
  /// clod::Error(kInvalidArgument) if its sphere or level count differs from the tree's.
  void setClosestFeatureMap(ClosestFeatureMap map);
  /// Adds the contact tree (built for this body's mesh). Throws clod::Error(kInvalidArgument)
  /// if it has no nodes.
  void setContactTree(ContactTree tree);

  const TriangleMesh& mesh() const noexcept { return mesh_; }
  const SphereTree& sphereTree() const noexcept { return tree_; }
  bool hasClosestFeatureMap() const noexcept { return map_.has_value(); }
  bool hasContactTree() const noexcept { return contactTree_.has_value(); }
  /// Precondition (CLOD_ASSERT): hasClosestFeatureMap().
  const ClosestFeatureMap& closestFeatureMap() const noexcept;
  /// Precondition (CLOD_ASSERT): hasContactTree().
  const ContactTree& contactTree() const noexcept;

  /// Level of each sphere (0 = root), precomputed.
  std::uint32_t sphereLevel(std::uint32_t sphere) const noexcept { return sphereLevel_[sphere]; }
  /// The distinct face normals of the triangles sphere `sphere` is responsible for, when there
  /// are at most kMaxSphereFaceNormals of them (a faceted patch: a box corner, a CAD part's
  /// flat faces); empty otherwise (a curved patch). Normals closer than 1e-6 rad count as one.
  /// The cfm model uses them to tell a face normal from an edge or vertex pseudonormal.
  std::span<const Vec3f> sphereFaceNormals(std::uint32_t sphere) const noexcept {
    return {faceNormals_.data() + faceNormalOffsets_[sphere], faceNormalOffsets_[sphere + 1] - faceNormalOffsets_[sphere]};
  }
  static constexpr std::uint32_t kMaxSphereFaceNormals = 8;
  /// The distinct vertex indices (into mesh().vertices, ascending) of the triangles sphere
  /// `sphere` is responsible for and of their edge neighbours with the same face normal (a face
  /// split into triangles counts whole up to one ring), when the sphere is a faceted patch (sphereFaceNormals non-empty)
  /// with at most kMaxSpherePatchVertices of them; empty otherwise. The cfm model uses them as a
  /// support function of the patch (max of n . v over them), together with the sphere itself, to
  /// pick the normal along which two faceted patches overlap least (docs/narrow-phase.md).
  std::span<const std::uint32_t> spherePatchVertices(std::uint32_t sphere) const noexcept {
    return {patchVertices_.data() + patchVertexOffsets_[sphere], patchVertexOffsets_[sphere + 1] - patchVertexOffsets_[sphere]};
  }
  static constexpr std::uint32_t kMaxSpherePatchVertices = 32;
  /// For a sphere without patch vertices (a curved patch, or a faceted one with more than
  /// kMaxSpherePatchVertices): mesh vertices of its triangles whose max of n . v is the patch's
  /// support in direction n to within sphereSupportSlack (all of them for small patches, the
  /// extreme vertices of 256 directions for larger ones); empty for faceted patches. The cfm
  /// model uses them as a curved patch's support function and as the points it rests on
  /// (docs/narrow-phase.md, "Curved patches").
  std::span<const std::uint32_t> sphereSupportVertices(std::uint32_t sphere) const noexcept {
    return {supportVertices_.data() + supportVertexOffsets_[sphere],
            supportVertexOffsets_[sphere + 1] - supportVertexOffsets_[sphere]};
  }
  double sphereSupportSlack(std::uint32_t sphere) const noexcept { return supportSlack_[sphere]; }
  /// For a sphere with support vertices: the vertices of its triangles that the support set
  /// leaves out (they lie inside the patch's convex hull, so, but for vertices on the rim of a
  /// flat hull face that qhull's joggle may drop, only a non-convex patch has them)
  /// and that do not lie inside a flat region of the mesh (a vertex all of whose triangles share
  /// one normal and none of whose edges is a border), ascending, when there are at most
  /// kMaxSphereInnerVertices of them; empty otherwise. A non-convex patch can rest on them while
  /// its hull's vertices are outside the other body: the flank of a bump under a box's edge,
  /// before the bump's top reaches the box. The cfm model presses them into convex bodies with
  /// the support vertices (docs/narrow-phase.md, "Curved patches"); a flat region's inner
  /// vertices are left out because its border vertices, which are kept, give the same plane.
  std::span<const std::uint32_t> sphereInnerVertices(std::uint32_t sphere) const noexcept {
    return {innerVertices_.data() + innerVertexOffsets_[sphere], innerVertexOffsets_[sphere + 1] - innerVertexOffsets_[sphere]};
  }
  static constexpr std::uint32_t kMaxSphereInnerVertices = 1024;
  /// Outward unit normal at a mesh vertex: the angle-weighted mean of its triangles' normals
  /// (zero for an unused vertex). A curved patch's vertex pressed into a convex body leaves it
  /// through the face this normal faces (docs/narrow-phase.md, "Curved patches").
  Vec3 vertexNormal(std::uint32_t vertex) const noexcept { return vertexNormals_[vertex].cast<double>(); }
  /// For a sphere with patch vertices: the distinct directions (unit, sign arbitrary) of the body
  /// edges among its triangles' edges (sharp: the neighbour's normal differs; or a border), when
  /// there are at most kMaxSphereEdgeDirections; empty otherwise. The cfm model crosses them with
  /// the other patch's to get edge-edge separating axes.
  std::span<const Vec3f> sphereEdgeDirections(std::uint32_t sphere) const noexcept {
    return {edgeDirections_.data() + edgeDirectionOffsets_[sphere], edgeDirectionOffsets_[sphere + 1] - edgeDirectionOffsets_[sphere]};
  }
  static constexpr std::uint32_t kMaxSphereEdgeDirections = 6;

  /// True when sphere `sphere`'s faceted patch is the whole body and the body is a closed convex
  /// polyhedron whose edge directions the patch lists (a box, a wedge, a prism): then the
  /// separating-axis test over the patch's face normals and edge-edge axes gives the true
  /// penetration depth, and the cfm model's contacts from such a pair carry no error from this
  /// side (docs/narrow-phase.md, "Faceted pairs").
  /// A tessellated convex polyhedron (a box whose faces are split into many triangles) counts:
  /// such a patch lists only the body's corners (vertices on three or more face planes), since
  /// vertices inside a face or along an edge are never extreme along any axis.
  bool patchIsWholeConvexBody(std::uint32_t sphere) const noexcept {
    return convexPolyhedron_ && wholeBodyPatch_[sphere] != 0 && !sphereEdgeDirections(sphere).empty();
  }
  /// True when the mesh is a closed convex polyhedron (every vertex behind every triangle's
  /// plane; checked for meshes of at most kMaxConvexCheckTriangles triangles, false above). Then
  /// every face a patch holds is a face of the body, and the depths of face-on-face contacts
  /// between patches are exact.
  bool isConvexPolyhedron() const noexcept { return convexPolyhedron_; }
  /// True when every edge of the mesh is shared by exactly two triangles (MeshTopology::closed):
  /// the body has an inside (the containment answer, docs/narrow-phase.md).
  bool isClosed() const noexcept { return closed_; }
  static constexpr std::uint32_t kMaxConvexCheckTriangles = 4096;

  /// The triangle across edge k (corners k and k + 1 mod 3) of triangle t, or kNoNeighbour where
  /// that edge is a border or shared by more than two triangles. O(1).
  std::uint32_t triangleNeighbour(std::uint32_t t, int k) const noexcept { return neighbours_[3 * std::size_t{t} + k]; }
  static constexpr std::uint32_t kNoNeighbour = 0xffffffffu;

  /// The closest point on triangle t to p (closestPointOnTriangle), with the triangle's needle /
  /// sliver test made once at construction instead of per call: the exact field queries of the
  /// narrow phase (vertex depths, containment) spent as long on that test as on the point.
  TrianglePoint closestPointOnTriangle(const Vec3& p, std::uint32_t t) const noexcept;

  /// A box hierarchy over the mesh's triangles (the proximity layer's), built on first use --
  /// O(T log T), thread-safe -- and shared by copies of the body: the exact closest-distance
  /// queries (World::separation, QuerySettings::marginAbs) descend it.
  const detail::TriangleBvh& triangleBvh() const;

  /// Bounding-box diagonal of the mesh: the unit of this body's relative tolerances.
  double diagonal() const noexcept { return diagonal_; }
  /// Where the body came from (a bake's source name), for messages; may be empty.
  const std::string& name() const noexcept { return name_; }
  void setName(std::string name) { name_ = std::move(name); }

private:
  struct EdgeRef {  // an undirected edge (v0 < v1) and one triangle holding it
    std::uint32_t v0, v1, triangle;
  };
  void classifyConvexPolyhedron(std::span<const EdgeRef> sortedEdges);
  void computeVertexNormals();
  void findNeighbours(std::span<const EdgeRef> sortedEdges);

  TriangleMesh mesh_;
  SphereTree tree_;
  std::optional<ClosestFeatureMap> map_;
  std::optional<ContactTree> contactTree_;
  std::vector<std::uint32_t> sphereLevel_;
  std::vector<std::uint32_t> faceNormalOffsets_;
  std::vector<Vec3f> faceNormals_;
  std::vector<std::uint32_t> patchVertexOffsets_;
  std::vector<std::uint32_t> patchVertices_;
  std::vector<std::uint32_t> edgeDirectionOffsets_;
  std::vector<Vec3f> edgeDirections_;
  std::vector<std::uint32_t> supportVertexOffsets_;
  std::vector<std::uint32_t> supportVertices_;
  std::vector<double> supportSlack_;
  std::vector<std::uint32_t> innerVertexOffsets_;
  std::vector<std::uint32_t> innerVertices_;
  std::vector<Vec3f> vertexNormals_;
  std::vector<std::uint32_t> neighbours_;  // 3 per triangle (triangleNeighbour)
  std::vector<std::uint8_t> thinTriangle_;  // per triangle: detail::isThinTriangle (closestPointOnTriangle)
  double diagonal_ = 0.0;
  bool convexPolyhedron_ = false;     // closed and convex (isConvexPolyhedron)
  bool closed_ = false;               // every edge shared by exactly two triangles (isClosed)
  std::size_t usedVertexCount_ = 0;   // distinct vertices referenced by triangles
  std::vector<std::uint8_t> wholeBodyPatch_;  // per sphere: its patch holds every vertex (patchIsWholeConvexBody)
  std::string name_;
  struct LazyTriangleBvh;  // triangleBvh(): built once, on first use
  std::shared_ptr<LazyTriangleBvh> triangleBvh_;
};

}  // namespace clod
