#include <cmath>
#include <unordered_map>

#include "clod/error.h"
#include "clod/simulation_recorder.h"

namespace clod {

SimulationRecorder::SimulationRecorder(const World& world, std::vector<std::string> names, double dt, std::uint32_t steps)
    : world_(world), names_(std::move(names)), dt_(dt), steps_(steps) {
  if (names_.size() != world.bodyCount())
    throw Error(ErrorCode::kInvalidArgument, "simulation recorder: " + std::to_string(names_.size()) + " names for " +
                                                 std::to_string(world.bodyCount()) + " bodies");
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw Error(ErrorCode::kInvalidArgument, "simulation recorder: dt must be positive and finite");
  // The 1e-9 keeps dt = 1/60 (not exactly representable) at stride 1 instead of 2.
  stride_ = static_cast<std::uint32_t>(std::max(1.0, std::ceil(1.0 / (kMaxFramesPerSecond * dt) - 1e-9)));
  poses_.resize(world.bodyCount());
  frames_.contactOffsets = {0};
  recordFrame(0, 0.0, nullptr);
}

void SimulationRecorder::recordStep(std::uint32_t step, const StepReport& report) {
  CLOD_ASSERT(step == lastStep_ + 1);
  lastStep_ = step;
  if (step % stride_ == 0 || step == steps_) recordFrame(step, step * dt_, &report);
}

void SimulationRecorder::recordFrame(std::uint32_t step, double time, const StepReport* report) {
  frames_.time.push_back(time);
  frames_.step.push_back(step);
  frames_.kineticEnergy.push_back(world_.kineticEnergy());
  frames_.potentialEnergy.push_back(world_.potentialEnergy());
  frames_.testsSpent.push_back(report ? report->testsSpent : 0);
  frames_.testsBudget.push_back(report ? report->testsBudget : 0);
  const std::size_t contacts = report ? report->contacts.size() : 0;
  frames_.contacts.push_back(static_cast<std::uint32_t>(contacts));
  for (std::size_t c = 0; c < contacts; ++c) {
    const Contact& k = report->contacts[c];
    frames_.contactData.insert(frames_.contactData.end(),
                               {float(k.point.x()), float(k.point.y()), float(k.point.z()), float(k.normal.x()),
                                float(k.normal.y()), float(k.normal.z()), float(k.depth)});
  }
  frames_.contactOffsets.push_back(frames_.contactOffsets.back() + static_cast<std::uint32_t>(contacts));
  for (BodyId i = 0; i < world_.bodyCount(); ++i) {
    const RigidBodyState s = world_.state(i);
    Pose p;
    p.translation = s.position;
    p.rotation = s.orientation;
    poses_[i].push_back(p);
  }
}

GltfScene SimulationRecorder::gltfScene() const {
  GltfScene scene;
  scene.keyTimes = frames_.time;
  for (BodyId i = 0; i < world_.bodyCount(); ++i) {
    const RigidBodyDesc& d = world_.desc(i);
    GltfBody b;
    b.name = names_[i];
    b.mesh = &d.shape->mesh();
    b.isStatic = d.type == BodyType::kStatic;
    b.initialPose = poses_[i].front();
    if (!b.isStatic) b.keyframes = poses_[i];
    scene.bodies.push_back(std::move(b));
  }
  return scene;
}

DebugLayers SimulationRecorder::debugLayers(const BodyLayerOptions& options) const {
  DebugLayers layers;
  if (options.frames) layers.frames = frames_;
  // Bodies of a scene often share a shape (bin_200: 200 bodies, a handful of shapes): build each
  // shape's layers once and copy them.
  std::unordered_map<const CollisionBody*, BodyDebugLayers> byShape;
  std::uint64_t floats = 0;
  bool capReached = false;
  for (BodyId i = 0; i < world_.bodyCount(); ++i) {
    const CollisionBody& shape = *world_.desc(i).shape;
    auto it = byShape.find(&shape);
    if (it == byShape.end()) {
      BodyDebugLayers l;
      if (options.sphereTree) l.sphereTree = makeSphereTreeLayer(shape.sphereTree());
      if (options.cfmSamples && shape.hasClosestFeatureMap())
        l.cfmSamples = makeCfmSampleLayer(shape.closestFeatureMap(), shape.sphereTree(), options.maxCfmSamplesPerBody);
      if (options.contactTree && shape.hasContactTree())
        l.contactTree = makeContactTreeLayer(shape.contactTree(), options.maxContactTreeCellsPerBody);
      it = byShape.emplace(&shape, std::move(l)).first;
    }
    std::uint64_t size = 0;
    const BodyDebugLayers& l = it->second;
    if (l.sphereTree)
      for (const auto& level : l.sphereTree->levels) size += level.size();
    if (l.cfmSamples)
      for (const auto& level : *l.cfmSamples) size += level.points.size() + level.normals.size();
    if (l.contactTree) size += l.contactTree->cells.size() + l.contactTree->halfSpaces.size();
    BodyDebugLayers body;
    if (!capReached && (options.maxBodyLayerFloats == 0 || floats + size <= options.maxBodyLayerFloats)) {
      body = l;
      floats += size;
    } else {
      capReached = true;  // strictly in scene order, so the viewer sees a prefix of the bodies
    }
    body.name = names_[i];
    body.node = i;
    layers.bodies.push_back(std::move(body));
  }
  return layers;
}

}  // namespace clod
