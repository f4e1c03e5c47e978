#pragma once
// clod as MuJoCo's collider for non-convex meshes (clod_mujoco; built when Debian's
// libmujoco-dev 2.2.2 is found). docs/engines-mujoco.md explains the design and its limits.
//
// MuJoCo collides a mesh geom through its convex hull. MuJoCo 2.2.2 calls the collision
// function of a pair of geom types through the table mjCOLLISIONFUNC[type1][type2] (mujoco.h),
// which a program may overwrite. A Collider bakes every mesh geom of the models it is given
// (sphere-tree + closest feature maps, and the contact tree when its model needs one; one bake
// per distinct mesh, keyed by meshContentHash) and, once installed, answers the mesh-mesh (and,
// by default, box-mesh) entries of that table with clod's anytime narrow phase (query.h):
//
//   clod::mujoco::ColliderSettings settings;
//   settings.model = clod::ContactModel::kExact;
//   settings.budgetTests = 4096;                      // per mj_step, all pairs together
//   clod::mujoco::Collider collider(settings);
//   collider.addModel(model);                         // bakes (once per distinct mesh)
//   collider.install();                               // one call installs ...
//   for (...) mj_step(model, data);
//   collider.uninstall();                             // ... one call restores MuJoCo's functions
//
// Conventions (MuJoCo's, mjContact in mjdata.h; checked by tests/mujoco): for geoms g1, g2 as
// MuJoCo passes them (type of g1 <= type of g2), every contact has
//   * frame[0..2] = the unit normal pointing FROM geom1 TOWARD geom2 (clod's normal points from
//     B toward A, contact.h; here A = g1 and B = g2, so it is negated), frame[3..5] and
//     frame[6..8] two unit tangents completing a right-handed orthonormal frame;
//   * dist = minus clod's depth: negative when the geoms penetrate (metres, MuJoCo's length unit);
//   * pos = clod's contact point (world frame, between the two surfaces).
// At most min(ColliderSettings::maxContacts, mjMAXCONPAIR) contacts per pair, deepest first;
// contacts with dist > margin (MuJoCo's per-pair margin) are dropped.
//
// Budget (the time-critical part): budgetTests / budgetMicros are per mj_step, shared by every
// pair clod answers in that step, divided the way clod's World divides a frame's budget
// (world.h): each pair may spend ceil(what the step has left / pairs still expected), the pairs
// expected being as many as the previous step had; what a pair leaves rolls over to the next.
// Every pair keeps a CoherenceCache across steps, so an interrupted pair resumes from the level
// it reached. A pair reached after the budget is gone is not queried: it keeps its previous
// contacts, anchored in both geoms and moved with them (its dist re-measured from the anchors),
// and counts as skipped. A step is recognised by mjData::time: calls for the same mjData at the
// same time belong to one step (mj_forward followed by mj_step at the same instant share one
// budget; a pair skipped in the second call reuses the contacts the first computed at that very
// pose). Time going backwards (mj_resetData) forgets that mjData's caches.
//
// Threads and global state: mjCOLLISIONFUNC is one process-wide table of plain function
// pointers, so at most one Collider is installed at a time (installing another uninstalls the
// first), and a Collider, like MuJoCo's own mj_step on one mjData, is used by one thread at a
// time: it keeps its caches and scratch memory inside, keyed by mjModel pointer (a model that
// was not added, or a geom it could not bake, goes to MuJoCo's own function) and by mjData
// pointer. Delete a Collider (it uninstalls itself) or call removeModel / forgetData before
// freeing a model or data whose address may be reused.
//
// Errors: addModel throws clod::Error naming the geom and mesh (a mesh clod cannot bake, bad
// settings). Inside mj_step nothing throws through MuJoCo's C code: an exception in a pair's
// query sends that pair to MuJoCo's own function and is kept in lastError().
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "clod/contact.h"
#include "clod/sphere_tree_builder.h"

namespace clod::mujoco {

/// How a contact's dist is reported.
enum class DepthReport : std::uint8_t {
  /// dist = -depth as the narrow phase gives it.
  kDepth = 0,
  /// dist = -max(0, depth - errorBound): only the certain part of the penetration (a coarse
  /// sphere pair's depth is known only within its spheres' radii), as clod's World corrects
  /// penetration (docs/dynamics.md). Exact contacts (errorBound 0) are unchanged.
  kCertainDepth = 1,
};

struct ColliderSettings {
  /// Contact model of every pair (contact.h).
  ContactModel model = ContactModel::kExact;
  /// Tests per mj_step for all pairs together (budget.h counts them); 0 = unlimited.
  std::uint64_t budgetTests = 0;
  /// Narrow-phase microseconds per mj_step for all pairs together (finite, >= 0; 0 = none).
  /// Converted to tests at the measured time per test (as WorldSettings::budgetMicros); with both
  /// set the smaller applies; pairs reached after the time is gone are skipped.
  double budgetMicros = 0.0;
  /// Budget units charged per frontier pair a query answers (WorldSettings::frontierPairCost),
  /// 0..1024; dos and average are never charged.
  std::uint32_t frontierPairCost = 2;
  /// Contacts per pair, 1..mjMAXCONPAIR.
  std::uint32_t maxContacts = 8;
  /// Also answer box-mesh pairs (the box as a 12-triangle mesh). Plane-mesh pairs stay MuJoCo's:
  /// a half-space touches a mesh only on its convex hull, so MuJoCo's answer is already right.
  bool boxMesh = true;
  /// Keep a CoherenceCache per pair across steps (query.h).
  bool coherence = true;
  DepthReport depthReport = DepthReport::kDepth;
  /// Sphere-tree of every baked geom. Octree, 3 levels below the root by default: the demos'
  /// meshes bake in milliseconds each; the medial builder fits tighter and takes longer.
  SphereTreeSettings sphereTree = [] {
    SphereTreeSettings s;
    s.method = SphereTreeMethod::kOctree;
    s.depth = 3;
    return s;
  }();
  /// Contact-tree depth (used only when model == kContactTree).
  std::uint32_t contactTreeDepth = 6;
};

/// What the collider did in one mj_step for one mjData.
struct StepStats {
  double time = 0.0;                  ///< mjData::time of the step
  std::uint32_t pairs = 0;            ///< pair calls clod answered (queried or skipped)
  std::uint32_t pairsSkipped = 0;     ///< budget gone: previous contacts reused
  std::uint32_t pairsInterrupted = 0; ///< queries that stopped before the leaves
  std::uint32_t pairsFallback = 0;    ///< pairs sent to MuJoCo's own function (error, unknown geom)
  std::uint64_t testsSpent = 0;       ///< narrow-phase tests, all pairs
  std::uint64_t budgetSpent = 0;      ///< tests + frontierPairCost x frontier pairs (charged models)
  std::uint64_t testsBudget = 0;      ///< the step's budget in units (0 = unlimited)
  std::uint32_t contacts = 0;         ///< contacts handed to MuJoCo
  double seconds = 0.0;               ///< wall time inside clod's collision functions
};

class Collider {
public:
  /// Throws clod::Error(kInvalidArgument) naming the setting when one is out of range.
  explicit Collider(const ColliderSettings& settings = {});
  /// Uninstalls itself if installed.
  ~Collider();
  Collider(const Collider&) = delete;
  Collider& operator=(const Collider&) = delete;

  /// Bakes every mesh geom (and box geom, with boxMesh) of `model` that is not baked yet (bakes
  /// are shared by content hash across geoms and models). Call before stepping the model with
  /// the collider installed. Throws clod::Error naming the geom and mesh when a mesh cannot be
  /// baked (e.g. kUnsupportedMesh, mesh validation errors). The model must outlive its use here.
  void addModel(const mjModel* model);
  /// Forgets a model and every pair state of it (its bakes stay cached).
  void removeModel(const mjModel* model);
  /// Forgets the per-pair caches and step statistics of one mjData.
  void forgetData(const mjData* data);

  /// Points mjCOLLISIONFUNC's mesh-mesh entry (and box-mesh entries, with boxMesh) at clod,
  /// after saving the current entries. Uninstalls another Collider first.
  void install();
  /// Restores the entries install() saved. No effect when not installed.
  void uninstall();
  bool installed() const noexcept;

  /// The last finished step of `data` (a step finishes when the next one starts), or the step
  /// in progress when none has finished; zeros for an unknown mjData.
  StepStats lastStep(const mjData* data) const;
  /// Sums over every step seen for `data`.
  StepStats totals(const mjData* data) const;
  /// The message of the last exception a pair's query threw (empty when none).
  const std::string& lastError() const noexcept;
  /// Distinct bakes held.
  std::size_t bakedShapes() const noexcept;
  const ColliderSettings& settings() const noexcept;

  struct Impl;

private:
  std::unique_ptr<Impl> impl_;
};

/// Owning pointers to MuJoCo's model and data.
struct ModelDeleter {
  void operator()(mjModel* m) const noexcept { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const noexcept { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

/// Loads an MJCF (or MuJoCo binary .mjb) model. Throws clod::Error: kFileNotFound,
/// kFileUnreadable (a directory), kParseError with MuJoCo's message (bad XML, a missing mesh
/// file, an invalid model), each naming the path.
ModelPtr loadModel(const std::filesystem::path& path);

}  // namespace clod::mujoco
