#pragma once
// Debug layers: what the web viewer overlays on the bodies of a scene.glb (gltf_export.h) --
// per output frame the energies, contact counts, budget and the contacts themselves, and per
// body its sphere-tree levels, closest-feature-map samples and contact-tree surface cells with
// their half-spaces. Encoded as layers.json, the JSON document of docs/viewer-format.md:
//
//   { "format": "clod-layers", "version": 1,
//     "frames":   { "time", "step", "kinetic_energy", "potential_energy", "total_energy",
//                   "contacts", "tests_spent", "tests_budget" },            (absent: no simulation)
//     "contacts": { "frame_offsets": [F+1], "data": [px,py,pz,nx,ny,nz,depth, ...] },
//     "bodies":   [ { "name", "node", "sphere_tree": {"levels": [[cx,cy,cz,r,...], ...]},
//                     "cfm_samples": [ {"level", "points", "normals"} ],
//                     "contact_tree": {"cells": [cx,cy,cz,half,depth,...],
//                                      "halfspaces": [nx,ny,nz,offset,...]} } ] }
//
// Frames: the contacts are in the world frame, the normal pointing from the second body of the
// pair toward the first (contact.h), depth positive when penetrating. Bodies: everything is in
// the body's own (mesh) frame and units. A half-space is {x : n.x = offset} in that frame (the
// absolute offset, not ContactHalfSpace's cell-relative one); the body is on the side n.x < offset.
//
// Size caps (so a file stays loadable in a browser): the builders below take whole sphere-tree
// levels for CFM samples and whole octree depths for contact-tree cells, from the root down,
// while the running total stays within the cap (the first level/depth is always taken). The
// caps and the sizes they give for the shipped scenes are in docs/viewer-format.md.
//
// Numbers are written as the shortest decimal that reads back to the same float (std::to_chars),
// times and energies as doubles.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "clod/closest_feature_map.h"
#include "clod/contact_tree.h"
#include "clod/sphere_tree.h"

namespace clod {

/// Default caps of the builders (per body).
inline constexpr std::uint32_t kDefaultMaxCfmSamples = 20000;
inline constexpr std::uint32_t kDefaultMaxContactTreeCells = 20000;

/// Per output frame of a simulation (all vectors have one entry per frame).
struct FrameSeries {
  std::vector<double> time;             ///< seconds, strictly increasing
  std::vector<std::uint32_t> step;      ///< simulation step shown by the frame (0 = initial state)
  std::vector<double> kineticEnergy;    ///< World::kineticEnergy() at the frame
  std::vector<double> potentialEnergy;  ///< World::potentialEnergy() at the frame
  std::vector<std::uint32_t> contacts;  ///< contacts of the frame's step (0 for step 0)
  std::vector<std::uint64_t> testsSpent;   ///< StepReport::testsSpent of the frame's step
  std::vector<std::uint64_t> testsBudget;  ///< StepReport::testsBudget (0 = unlimited)
  /// CSR over frames: frame f's contacts are contactData[7*contactOffsets[f] .. 7*contactOffsets[f+1])
  /// as px py pz nx ny nz depth; contactOffsets has frames + 1 entries, starting at 0.
  std::vector<std::uint32_t> contactOffsets{0};
  std::vector<float> contactData;

  std::size_t frameCount() const noexcept { return time.size(); }
};

/// Sphere-tree levels: levels[l] holds cx cy cz r for every sphere of level l (root = level 0).
struct SphereTreeLayer {
  std::vector<std::vector<float>> levels;
};

/// CFM samples of one tree level: for every sphere of the level, every sample point
/// c + r * u_k of the level's sampling, and the normal the map stores for it (the sphere's one
/// normal for a single-normal sphere). points and normals: x y z per sample.
struct CfmSampleLevel {
  std::uint32_t level = 0;
  std::vector<float> points;
  std::vector<float> normals;
};

/// Contact-tree surface cells (those with a half-space: the surface comes within half a cell
/// diagonal of the centre, docs/contact-tree.md): cx cy cz half depth per cell (centre, half the
/// side length, octree depth), and the cell's half-space nx ny nz offset.
struct ContactTreeLayer {
  std::vector<float> cells;
  std::vector<float> halfSpaces;
  std::uint32_t depthsIncluded = 0;  ///< cells of depths [0, depthsIncluded) are present
  std::uint32_t cellCount() const noexcept { return static_cast<std::uint32_t>(cells.size() / 5); }
};

/// One body's layers; an absent member is omitted from the file.
struct BodyDebugLayers {
  std::string name;
  std::uint32_t node = 0;  ///< index of the body's node in scene.glb
  std::optional<SphereTreeLayer> sphereTree;
  std::optional<std::vector<CfmSampleLevel>> cfmSamples;
  std::optional<ContactTreeLayer> contactTree;
};

/// The whole layers.json document.
struct DebugLayers {
  std::optional<FrameSeries> frames;  ///< frames + contacts; absent for a bake export
  std::vector<BodyDebugLayers> bodies;
};

/// Every level of the tree. O(spheres).
SphereTreeLayer makeSphereTreeLayer(const SphereTree& tree);

/// CFM samples of whole levels from the root down while the total sample count stays <=
/// maxSamples (level 0 is always included). `tree` must be the tree the map was built for
/// (CLOD_ASSERT on the sphere counts). O(samples written).
std::vector<CfmSampleLevel> makeCfmSampleLayer(const ClosestFeatureMap& map, const SphereTree& tree,
                                               std::uint32_t maxSamples = kDefaultMaxCfmSamples);

/// Surface cells of whole depths from the root down while the total stays <= maxCells (the
/// shallowest depth that has surface cells is always included). O(nodes visited).
ContactTreeLayer makeContactTreeLayer(const ContactTree& tree,
                                      std::uint32_t maxCells = kDefaultMaxContactTreeCells);

/// The layers.json text. Throws clod::Error(kInvalidArgument) naming the array when the frame
/// series is inconsistent (vectors of different lengths, offsets not monotone from 0 to the
/// contact count, data not 7 per contact) or a value is non-finite. O(size of the output).
std::string encodeDebugLayers(const DebugLayers& layers);

}  // namespace clod
