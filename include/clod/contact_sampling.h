#pragma once
// Contact sampling between two contact trees (paper B, "contact generation"): for a pair of
// cells whose bounding spheres intersect, distribute sample points on the half-plane of the
// surface cell, keep those inside the other body's cell and inside (or within a margin of)
// the other body's distance field, and turn each into a contact point whose normal is the
// normalised trilinear gradient of the other field and whose depth is minus its value.
// Then thin them to a handful of well-spread contacts per contact patch, because redundant
// contacts make the solver's constraint system ill-conditioned.
//
// Conventions (same as the rest of clod): every output is in the world frame; the contact
// normal points out of body B toward body A; depth is positive when penetrating (the point
// is that far inside the other body) and negative for a separation within the margin.
//
// Choices the paper leaves open (sample density, off-surface samples, which normal wins at an
// edge, the thinning rule) are explained in docs/contact-tree.md.

#include <cstdint>
#include <vector>

#include "clod/contact_tree.h"
#include "clod/math.h"

namespace clod {

/// One contact between bodies A and B (world frame).
struct ContactPoint {
  Vec3 point = Vec3::Zero();   ///< the sample point: on (or, off-surface, just inside) the sampled body
  Vec3 normal = Vec3::UnitZ(); ///< unit, out of B toward A
  double depth = 0.0;          ///< > 0 penetrating, < 0 separated (within the margin)
  double errorBound = 0.0;     ///< error bound of the distance value the depth came from
  std::uint8_t sampledBody = 0;///< 0: sampled on A's surface, tested against B's field; 1: the reverse
};

struct ContactSamplingSettings {
  /// Keep samples whose distance to the other body is <= marginAbs (body units, >= 0):
  /// speculative contacts for bodies about to touch. 0 keeps touching and penetrating ones.
  double marginAbs = 0.0;
  /// Upper limit of samples per axis of a cell's half-plane: spacing = h / n, where h is the
  /// smaller of the two cells' sizes (samples only count inside both, so a large cell against a
  /// small one still puts about n x n samples into the small one) and
  /// n = clamp(h / (4 eps_s), 1, samplesPerCellAxis) -- no two samples closer than the
  /// field can tell apart. 1..16.
  std::uint32_t samplesPerCellAxis = 4;
  /// Also sample a layer offSurfaceDepthRel * h (h as above) below the half-plane (inside the
  /// sampled body), so bodies whose surfaces have passed through each other still get
  /// contacts. 0 disables it. 0..1.
  double offSurfaceDepthRel = 0.5;
  /// When the other field's gradient and the sampled face's normal disagree by more than this
  /// angle, and the sampled cell is flat while the other body's cell at the sample holds an
  /// edge or corner (half-space fit error > 10 % of its size), the face normal wins: an edge or
  /// vertex touching a face pushes along the face normal. Degrees, 0..180.
  double normalConflictDeg = 30.0;
  /// Thinning: contacts whose normals are within patchAngleDeg of a patch's first (deepest)
  /// contact form one patch; each patch keeps at most maxContactsPerPatch (>= 1) contacts.
  double patchAngleDeg = 20.0;
  std::uint32_t maxContactsPerPatch = 4;
  /// Paper B's leaf half-space test: where the traversal has reached a leaf of one tree (or
  /// maxDepth), the other tree's cells are also tested against that leaf's half-space, and a
  /// cell whose bounding sphere lies entirely on the outer side of the plane, farther than
  /// marginAbs + the plane's fitError, is pruned. Rigorous: the leaf's trilinear field is never
  /// below plane distance - fitError in its cell (it interpolates corner values that are, see
  /// ContactHalfSpace::fitError), and its samples lie on the plane, so a pruned pair could not
  /// produce a contact. Saves cell pairs where leaf spheres are loose over flat regions; the
  /// contacts are the same with it off.
  bool leafHalfSpacePruning = true;
  /// Edge-edge contacts: where the sampled cell holds an edge (half-space fit error > 10 % of
  /// the cell size) or the other field's gradient conflicts with the sampled plane (see
  /// normalConflictDeg), and both fields show an edge around the sample (their gradients,
  /// probed at 7 points within twice the larger cell size, span a plane), the normal is taken
  /// perpendicular to both edges (docs/contact-tree.md); this takes precedence over the face
  /// rule of normalConflictDeg. Edges within 15 degrees of parallel have no common
  /// perpendicular (and a face overhanging an edge, its own parallel edge within the probe
  /// radius, looks the same), so those samples are left to the face rule. The gradient of one
  /// field alone is "rounded" at crossing edges and tilts up to 45 degrees toward one of the
  /// faces. Costs 16 extra field queries per such sample.
  bool edgeEdgeNormals = true;
  /// Also test the support points of coarse cells (cell_support.h) where a pair has an inner
  /// cell: for an interrupted query's frontier, whose lattice misses contact regions smaller
  /// than its spacing. The query sets it when its traversal stopped at the budget; a finished
  /// traversal's final cells keep the lattice (but see flatPartnerSupports).
  bool supportPoints = false;
  /// Where O's cell is flat (ContactTree::isFlatSurface) and S's cell has support points, those
  /// inside O are the pair's samples: a flat partner is met first where S reaches farthest
  /// toward it. A finished query's pair takes them instead of the lattice; an interrupted
  /// query's coarse pair (supportPoints) takes the lattice too, since 386 directions can miss
  /// the lowest part of a nearly flat face.
  bool flatPartnerSupports = true;
  /// Depth limit for field queries and traversal (kContactTreeLeafDepth: full resolution).
  /// A time-budgeted caller passes a smaller value to stop higher in both trees.
  std::uint32_t maxDepth = kContactTreeLeafDepth;
};

/// Samples the half-plane of `cellS` of tree S against cell `cellO` of tree O and appends the
/// contacts to `out`, with normals out of O toward S and sampledBody = 0. Does nothing when
/// cellS has no half-space. Only samples inside both cells count, so calling this for every
/// intersecting pair of leaf cells generates each sample at most once. No allocation beyond
/// growing `out`. Throws clod::Error(kInvalidArgument) for out-of-range settings.
void sampleCellPair(const ContactTree& treeS, const ContactCell& cellS, const Pose& xfWorldFromS,
                    const ContactTree& treeO, const ContactCell& cellO, const Pose& xfWorldFromO,
                    const ContactSamplingSettings& settings, std::vector<ContactPoint>& out);

/// Statistics of findContacts.
struct ContactQueryStats {
  std::uint64_t cellPairsVisited = 0;  ///< sphere-sphere tests
  std::uint64_t cellPairsSampled = 0;  ///< leaf pairs handed to sampleCellPair (each direction)
  std::uint64_t rawContacts = 0;       ///< contacts before thinning
  std::uint64_t halfSpacePrunes = 0;   ///< cell pairs pruned by a leaf's half-space
  std::uint64_t edgeEdgeNormals = 0;   ///< raw contacts whose normal came from two edge directions
};

/// Full narrow phase between A and B for tests, tools and as the reference the budgeted
/// narrow phase is compared with: traverses both trees depth-first (descending the larger
/// sphere; pruning cells whose field proves them farther than the margin from their body and
/// sphere pairs farther apart than the margin), samples every intersecting leaf pair in both
/// directions, then thins with reduceContacts. Clears `out` first. Recursion depth is at most
/// the sum of the trees' depths; no allocation beyond `out`.
void findContacts(const ContactTree& treeA, const Pose& xfWorldFromA, const ContactTree& treeB,
                  const Pose& xfWorldFromB, const ContactSamplingSettings& settings,
                  std::vector<ContactPoint>& out, ContactQueryStats* stats = nullptr);

/// Thins contacts in place: groups them into patches by normal (greedy, deepest first) and
/// keeps per patch the contacts that span it best -- the one farthest from the patch centroid,
/// the one farthest from that, and the two that add the largest triangle areas on either side
/// (the corners of a rectangular overlap); then, if maxContactsPerPatch > 4, the deepest and
/// farthest-point picks. O(n * patches + n * maxContactsPerPatch).
void reduceContacts(std::vector<ContactPoint>& contacts, const ContactSamplingSettings& settings);

}  // namespace clod
