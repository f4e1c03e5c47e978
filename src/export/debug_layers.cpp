#include <charconv>
#include <cmath>

#include <nlohmann/json.hpp>

#include "clod/debug_layers.h"
#include "clod/error.h"

namespace clod {
namespace {

// A minimal streaming JSON writer: nlohmann::json stores numbers as double and would print a
// float such as 0.1f as 0.10000000149011612; std::to_chars gives the shortest text that reads
// back to the same float, which keeps layers.json about half the size.
class JsonText {
public:
  void raw(std::string_view s) { out_.append(s); }
  void key(std::string_view k) {
    out_ += nlohmann::json(std::string(k)).dump();
    out_ += ':';
  }
  void string(const std::string& s) { out_ += nlohmann::json(s).dump(); }
  template <class T>
  void number(T v) {
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out_.append(buf, r.ptr);
  }
  template <class T>
  void array(const std::vector<T>& values) {
    out_ += '[';
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i) out_ += ',';
      number(values[i]);
    }
    out_ += ']';
  }
  // ,\n"k":[values] -- a member after the first of an object.
  template <class T>
  void nextArray(std::string_view k, const std::vector<T>& values) {
    raw(",\n");
    key(k);
    array(values);
  }
  std::string take() { return std::move(out_); }

private:
  std::string out_;
};

template <class T>
void checkFinite(const std::vector<T>& values, const std::string& what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(double(values[i])))
      throw Error(ErrorCode::kInvalidArgument, "debug layers: " + what + "[" + std::to_string(i) + "] is not finite");
}

void checkFrames(const FrameSeries& f) {
  const std::size_t n = f.time.size();
  const auto same = [&](std::size_t size, const char* name) {
    if (size != n)
      throw Error(ErrorCode::kInvalidArgument, std::string("debug layers: frames.") + name + " has " + std::to_string(size) +
                                                   " entries for " + std::to_string(n) + " frames");
  };
  same(f.step.size(), "step");
  same(f.kineticEnergy.size(), "kinetic_energy");
  same(f.potentialEnergy.size(), "potential_energy");
  same(f.contacts.size(), "contacts");
  same(f.testsSpent.size(), "tests_spent");
  same(f.testsBudget.size(), "tests_budget");
  if (f.contactOffsets.size() != n + 1 || f.contactOffsets.front() != 0)
    throw Error(ErrorCode::kInvalidArgument, "debug layers: contacts.frame_offsets must have frames + 1 entries starting at 0");
  for (std::size_t i = 0; i < n; ++i)
    if (f.contactOffsets[i + 1] < f.contactOffsets[i])
      throw Error(ErrorCode::kInvalidArgument, "debug layers: contacts.frame_offsets[" + std::to_string(i + 1) + "] decreases");
  if (f.contactData.size() != 7 * std::size_t(f.contactOffsets.back()))
    throw Error(ErrorCode::kInvalidArgument, "debug layers: contacts.data has " + std::to_string(f.contactData.size()) +
                                                 " values for " + std::to_string(f.contactOffsets.back()) + " contacts (7 each)");
  checkFinite(f.time, "frames.time");
  checkFinite(f.kineticEnergy, "frames.kinetic_energy");
  checkFinite(f.potentialEnergy, "frames.potential_energy");
  checkFinite(f.contactData, "contacts.data");
}

void appendVec(std::vector<float>& out, const Vec3& v) {
  out.insert(out.end(), {float(v.x()), float(v.y()), float(v.z())});
}

}  // namespace

SphereTreeLayer makeSphereTreeLayer(const SphereTree& tree) {
  SphereTreeLayer layer;
  layer.levels.resize(tree.levelCount());
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    std::vector<float>& out = layer.levels[l];
    out.reserve(4 * std::size_t(tree.levelEnd(l) - tree.levelBegin(l)));
    for (std::uint32_t s = tree.levelBegin(l); s < tree.levelEnd(l); ++s)
      out.insert(out.end(), {float(tree.centerX[s]), float(tree.centerY[s]), float(tree.centerZ[s]), float(tree.radius[s])});
  }
  return layer;
}

std::vector<CfmSampleLevel> makeCfmSampleLayer(const ClosestFeatureMap& map, const SphereTree& tree,
                                               std::uint32_t maxSamples) {
  CLOD_ASSERT(map.sphereCount() == tree.sphereCount() && map.levelCount() == tree.levelCount());
  std::vector<CfmSampleLevel> levels;
  std::uint64_t total = 0;
  for (std::uint32_t l = 0; l < tree.levelCount(); ++l) {
    const SphereSampling& sampling = map.levelSampling(l);
    const std::uint64_t count = std::uint64_t(sampling.size()) * (tree.levelEnd(l) - tree.levelBegin(l));
    if (l > 0 && total + count > maxSamples) break;  // whole levels only: a level is what the viewer picks
    total += count;
    CfmSampleLevel level;
    level.level = l;
    level.points.reserve(3 * count);
    level.normals.reserve(3 * count);
    for (std::uint32_t s = tree.levelBegin(l); s < tree.levelEnd(l); ++s) {
      const Vec3 c = tree.center(s);
      const double r = tree.radius[s];
      for (std::uint32_t k = 0; k < sampling.size(); ++k) {
        appendVec(level.points, c + r * sampling.direction(k));
        appendVec(level.normals, map.storedNormal(s, map.isSingleNormal(s) ? 0u : k));
      }
    }
    levels.push_back(std::move(level));
  }
  return levels;
}

ContactTreeLayer makeContactTreeLayer(const ContactTree& tree, std::uint32_t maxCells) {
  ContactTreeLayer layer;
  if (tree.nodeCount() == 0) return layer;
  // Breadth-first over depths: cells of one depth come out together, so whole depths can be cut.
  std::vector<ContactCell> current{tree.rootCell()}, next;
  for (std::uint32_t depth = 0; !current.empty(); ++depth) {
    std::uint32_t surfaceCells = 0;
    for (const ContactCell& c : current)
      if (tree.halfSpace(c.node)) ++surfaceCells;
    if (layer.cellCount() > 0 && std::uint64_t(layer.cellCount()) + surfaceCells > maxCells) break;
    const double half = 0.5 * tree.cellSize(depth);
    next.clear();
    for (const ContactCell& c : current) {
      if (const ContactHalfSpace* h = tree.halfSpace(c.node)) {
        const Vec3 centre = tree.cellCenter(c);
        const Vec3 n(h->normal[0], h->normal[1], h->normal[2]);
        appendVec(layer.cells, centre);
        layer.cells.insert(layer.cells.end(), {float(half), float(depth)});
        appendVec(layer.halfSpaces, n);
        // ContactHalfSpace: n.(x - c) = offset  <=>  n.x = offset + n.c (absolute, as the file wants).
        layer.halfSpaces.push_back(float(double(h->offset) + n.dot(centre)));
      }
      if (!tree.isLeaf(c.node))
        for (std::uint32_t k = 0; k < 8; ++k) next.push_back(tree.childCell(c, k));
    }
    layer.depthsIncluded = depth + 1;
    current.swap(next);
  }
  return layer;
}

std::string encodeDebugLayers(const DebugLayers& layers) {
  JsonText j;
  j.raw("{\"format\":\"clod-layers\",\"version\":1");
  if (layers.frames) {
    const FrameSeries& f = *layers.frames;
    checkFrames(f);
    std::vector<double> total(f.time.size());
    for (std::size_t i = 0; i < total.size(); ++i) total[i] = f.kineticEnergy[i] + f.potentialEnergy[i];
    j.raw(",\n");
    j.key("frames");
    j.raw("{");
    j.key("time");
    j.array(f.time);
    j.nextArray("step", f.step);
    j.nextArray("kinetic_energy", f.kineticEnergy);
    j.nextArray("potential_energy", f.potentialEnergy);
    j.nextArray("total_energy", total);
    j.nextArray("contacts", f.contacts);
    j.nextArray("tests_spent", f.testsSpent);
    j.nextArray("tests_budget", f.testsBudget);
    j.raw("},\n");
    j.key("contacts");
    j.raw("{");
    j.key("frame_offsets");
    j.array(f.contactOffsets);
    j.nextArray("data", f.contactData);
    j.raw("}");
  }
  j.raw(",\n");
  j.key("bodies");
  j.raw("[");
  for (std::size_t b = 0; b < layers.bodies.size(); ++b) {
    const BodyDebugLayers& body = layers.bodies[b];
    const std::string where = "bodies[" + std::to_string(b) + "]";
    j.raw(b ? ",\n{" : "\n{");
    j.key("name");
    j.string(body.name);
    j.raw(",");
    j.key("node");
    j.number(body.node);
    if (body.sphereTree) {
      j.raw(",\n");
      j.key("sphere_tree");
      j.raw("{");
      j.key("levels");
      j.raw("[");
      for (std::size_t l = 0; l < body.sphereTree->levels.size(); ++l) {
        checkFinite(body.sphereTree->levels[l], where + ".sphere_tree.levels[" + std::to_string(l) + "]");
        if (l) j.raw(",\n");
        j.array(body.sphereTree->levels[l]);
      }
      j.raw("]}");
    }
    if (body.cfmSamples) {
      j.raw(",\n");
      j.key("cfm_samples");
      j.raw("[");
      for (std::size_t l = 0; l < body.cfmSamples->size(); ++l) {
        const CfmSampleLevel& level = (*body.cfmSamples)[l];
        checkFinite(level.points, where + ".cfm_samples[" + std::to_string(l) + "].points");
        checkFinite(level.normals, where + ".cfm_samples[" + std::to_string(l) + "].normals");
        j.raw(l ? ",\n{" : "{");
        j.key("level");
        j.number(level.level);
        j.raw(",");
        j.key("points");
        j.array(level.points);
        j.nextArray("normals", level.normals);
        j.raw("}");
      }
      j.raw("]");
    }
    if (body.contactTree) {
      checkFinite(body.contactTree->cells, where + ".contact_tree.cells");
      checkFinite(body.contactTree->halfSpaces, where + ".contact_tree.halfspaces");
      j.raw(",\n");
      j.key("contact_tree");
      j.raw("{");
      j.key("cells");
      j.array(body.contactTree->cells);
      j.nextArray("halfspaces", body.contactTree->halfSpaces);
      j.raw("}");
    }
    j.raw("}");
  }
  j.raw("]}\n");
  return j.take();
}

}  // namespace clod
