#pragma once
// Records a running World (world.h) at output frames, for export as scene.glb + layers.json
// (gltf_export.h, debug_layers.h, docs/viewer-format.md).
//
// Output frames: the initial state (step 0) and then every `frameStride()`-th step, plus the
// last step when the step count is not a multiple of the stride, where
//   stride = max(1, ceil(1 / (kMaxFramesPerSecond * dt)))
// so a scene stepped at dt <= 1/60 s keeps every step, and a finer dt is decimated to at most
// kMaxFramesPerSecond frames per simulated second. A frame holds every body's pose, the
// energies, and the step's contacts, contact count and budget figures (those of the one step the
// frame shows; decimated steps in between are not summed in).
//
// Use:
//   SimulationRecorder rec(world, names, dt, steps);   // records frame 0 from the world's state
//   for (step = 1..steps) { const StepReport& r = world.step(dt); rec.recordStep(step, r); }
//   saveGlb(out / "scene.glb", rec.gltfScene());
//   writeFileAtomically(out / "layers.json", encodeDebugLayers(rec.debugLayers(options)));
//
// The recorder keeps a reference to the world, whose bodies (and shapes) must not change while
// it is in use. Memory: bodies x frames poses + the contacts of the recorded frames.
#include <cstdint>
#include <string>
#include <vector>

#include "clod/debug_layers.h"
#include "clod/gltf_export.h"
#include "clod/world.h"

namespace clod {

/// Output frames per simulated second, at most.
inline constexpr double kMaxFramesPerSecond = 60.0;

/// Which per-body layers SimulationRecorder::debugLayers adds, and their caps.
struct BodyLayerOptions {
  bool frames = true;       ///< "frames" and "contacts" keys
  bool sphereTree = true;   ///< every body's sphere-tree levels
  bool cfmSamples = true;   ///< CFM samples (bodies whose shape has a closest feature map)
  bool contactTree = true;  ///< contact-tree cells (bodies whose shape has a contact tree)
  std::uint32_t maxCfmSamplesPerBody = kDefaultMaxCfmSamples;
  std::uint32_t maxContactTreeCellsPerBody = kDefaultMaxContactTreeCells;
  /// Cap on all per-body floats together (sphere, sample and cell numbers): bodies, in scene
  /// order, get their layers while the running total stays within it; later bodies get none
  /// (their entries keep name and node). 0 = no cap.
  std::uint64_t maxBodyLayerFloats = 1'000'000;
};

class SimulationRecorder {
public:
  /// Records frame 0 (time 0, the world's current state). `names` has one entry per body;
  /// dt > 0 and finite, steps = the number of steps the caller will record (so the last one is
  /// always kept). Throws clod::Error(kInvalidArgument) for a names count != bodyCount() or a
  /// bad dt.
  SimulationRecorder(const World& world, std::vector<std::string> names, double dt, std::uint32_t steps);

  /// Call after World::step for step = 1, 2, ..., steps; records the frame if the step is an
  /// output step. `report` is what that World::step returned. CLOD_ASSERT(step == last + 1).
  void recordStep(std::uint32_t step, const StepReport& report);

  /// Steps per output frame (see the top of the file).
  std::uint32_t frameStride() const noexcept { return stride_; }
  std::size_t frameCount() const noexcept { return frames_.frameCount(); }

  /// Bodies with their meshes (the world's shapes, which must outlive the returned scene's use)
  /// and keyframes at the recorded frames. A body that is static when added gets no channels;
  /// one frozen later (left the bounds) keeps its channels, standing still.
  GltfScene gltfScene() const;

  /// The frames (when options.frames) and the per-body layers the options ask for, with node
  /// = body index. Bodies sharing a shape share the work (each shape's layers are built once).
  DebugLayers debugLayers(const BodyLayerOptions& options = {}) const;

private:
  const World& world_;
  std::vector<std::string> names_;
  double dt_;
  std::uint32_t steps_;
  std::uint32_t stride_ = 1;
  std::uint32_t lastStep_ = 0;
  FrameSeries frames_;
  std::vector<std::vector<Pose>> poses_;  // per body, per frame

  void recordFrame(std::uint32_t step, double time, const StepReport* report);
};

}  // namespace clod
