#include "clod/thread_meshes.h"

#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

#include "clod/error.h"
#include "generator_arguments.h"

namespace clod {

namespace {

using detail::requireCount;
using detail::requirePositive;

// One row of a helical surface: its axial phase within a pitch and its radius at angle theta.
struct Row {
  double phase;
  double radius;
};

// The four corners of the basic profile within one pitch (root start, root end, crest start,
// crest end), radially offset.
std::array<Row, 4> profileRows(const IsoThread& thread, double offset) {
  const double p = thread.pitch;
  const double rMinor = 0.5 * thread.minorDiameter() + offset, rMajor = 0.5 * thread.majorDiameter + offset;
  return {Row{0.0, rMinor}, Row{0.25 * p, rMinor}, Row{9.0 / 16.0 * p, rMajor}, Row{11.0 / 16.0 * p, rMajor}};
}

// Builds a solid between an inner and an outer helical surface (or the axis) with helicoidal
// ends. A surface has K rows per pitch; row l (0..L, L = K turns) at sample m (0..n) lies at
// angle 2 pi m / n and height phase(l mod K) + (l / K) pitch + pitch m / n. Sample n of row l is
// sample 0 of row l + K, one pitch up, wherever that row exists, so each surface is one strip
// winding up; the rows l > L - K keep a separate sample n (the top step).
class ThreadedSolid {
public:
  ThreadedSolid(double pitch, std::uint32_t turns, std::uint32_t n) : pitch_(pitch), turns_(turns), n_(n) {}

  // radiusAt(row, m): the row's radius at sample m (a hexagon's varies with the angle).
  template <class RadiusAt>
  std::uint32_t addSurface(std::span<const Row> rows, RadiusAt radiusAt) {
    Surface s;
    s.base = std::uint32_t(mesh_.vertices.size());
    s.k = std::uint32_t(rows.size());
    s.rows = s.k * turns_;
    for (std::uint32_t l = 0; l <= s.rows; ++l)
      for (std::uint32_t m = 0; m < n_; ++m) mesh_.vertices.push_back(point(rows, radiusAt, l, m));
    for (std::uint32_t l = s.rows - s.k + 1; l <= s.rows; ++l) mesh_.vertices.push_back(point(rows, radiusAt, l, n_));
    surfaces_.push_back(s);
    return std::uint32_t(surfaces_.size() - 1);
  }

  // The axis points of the two ramps when the solid has no inner surface (a rod).
  void addAxis() {
    axisBase_ = std::uint32_t(mesh_.vertices.size());
    for (const double z0 : {0.0, double(turns_) * pitch_})
      for (std::uint32_t m = 0; m <= n_; ++m) mesh_.vertices.emplace_back(0.0, 0.0, z0 + pitch_ * m / n_);
  }

  std::uint32_t id(std::uint32_t surface, std::uint32_t l, std::uint32_t m) const {
    const Surface& s = surfaces_[surface];
    if (m < n_) return s.base + l * n_ + m;
    if (l + s.k <= s.rows) return s.base + (l + s.k) * n_;
    return s.base + (s.rows + 1) * n_ + (l - (s.rows - s.k + 1));
  }
  std::uint32_t rowsOf(std::uint32_t surface) const { return surfaces_[surface].rows; }
  std::uint32_t rowsPerPitch(std::uint32_t surface) const { return surfaces_[surface].k; }
  std::uint32_t axis(bool top, std::uint32_t m) const { return axisBase_ + (top ? n_ + 1 : 0) + m; }

  // The strip's quads; `outward` = the surface faces away from the axis.
  void addStrip(std::uint32_t surface, bool outward) {
    for (std::uint32_t l = 0; l < rowsOf(surface); ++l)
      for (std::uint32_t m = 0; m < n_; ++m) {
        // a, b along row l (the helix), d, c along row l + 1; split along a-c. A flank quad is not
        // quite flat (its rows lie at different radii): its two triangles fold by under a degree.
        const std::uint32_t a = id(surface, l, m), b = id(surface, l, m + 1), c = id(surface, l + 1, m + 1),
                            d = id(surface, l + 1, m);
        if (outward)
          quad(a, b, c, d);
        else
          quad(a, d, c, b);
      }
  }

  // The two ramps between inner (ids given per sample) and outer (row 0 / last row).
  template <class Inner>
  void addRamps(Inner inner, std::uint32_t outer) {
    for (std::uint32_t m = 0; m < n_; ++m) {
      quad(inner(false, m), inner(false, m + 1), id(outer, 0, m + 1), id(outer, 0, m));  // bottom faces -z
      const std::uint32_t top = rowsOf(outer);
      quad(inner(true, m), id(outer, top, m), id(outer, top, m + 1), inner(true, m + 1));  // top faces +z
    }
  }

  // A step face in the half-plane y = 0: the polygon between two chains rising in z (inner
  // nearer the axis), triangulated by merging them by height, each triangle facing `normalY`.
  void addStep(std::span<const std::uint32_t> inner, std::span<const std::uint32_t> outer, double normalY) {
    std::size_t i = 0, j = 0;
    while (i + 1 < inner.size() || j + 1 < outer.size()) {
      std::uint32_t a, b, c;
      if (j + 1 == outer.size() ||
          (i + 1 < inner.size() && mesh_.vertices[inner[i + 1]].z() <= mesh_.vertices[outer[j + 1]].z())) {
        a = inner[i], b = outer[j], c = inner[i + 1];
        ++i;
      } else {
        a = inner[i], b = outer[j], c = outer[j + 1];
        ++j;
      }
      const Vec3 normal = (mesh_.vertices[b] - mesh_.vertices[a]).cross(mesh_.vertices[c] - mesh_.vertices[a]);
      if (normal.y() * normalY > 0.0)
        mesh_.triangles.push_back({a, b, c});
      else
        mesh_.triangles.push_back({a, c, b});
    }
  }

  // The chain of surface `s` at angle 0 on the bottom step (rows 0..K at sample 0) and on the
  // top step (row L at sample 0, then rows L - K + 1 .. L at sample n).
  std::vector<std::uint32_t> bottomChain(std::uint32_t s) const {
    std::vector<std::uint32_t> chain;
    for (std::uint32_t l = 0; l <= rowsPerPitch(s); ++l) chain.push_back(id(s, l, 0));
    return chain;
  }
  std::vector<std::uint32_t> topChain(std::uint32_t s) const {
    std::vector<std::uint32_t> chain{id(s, rowsOf(s), 0)};
    for (std::uint32_t l = rowsOf(s) - rowsPerPitch(s) + 1; l <= rowsOf(s); ++l) chain.push_back(id(s, l, n_));
    return chain;
  }
  std::vector<std::uint32_t> axisChain(bool top) const {
    std::vector<std::uint32_t> chain;
    for (std::uint32_t m = 0; m <= n_; ++m) chain.push_back(axis(top, m));
    return chain;
  }

  TriangleMesh take() { return std::move(mesh_); }

private:
  struct Surface {
    std::uint32_t base = 0, k = 0, rows = 0;
  };

  template <class RadiusAt>
  Vec3 point(std::span<const Row> rows, RadiusAt radiusAt, std::uint32_t l, std::uint32_t m) const {
    const std::uint32_t k = std::uint32_t(rows.size());
    // Sample n is angle 0 again (exactly: the step faces lie in the plane y = 0).
    const std::uint32_t angleIndex = m % n_;
    const double theta = 2.0 * std::numbers::pi * double(angleIndex) / double(n_);
    const double radius = radiusAt(rows[l % k], angleIndex);
    const double z = rows[l % k].phase + double(l / k) * pitch_ + pitch_ * double(m) / double(n_);
    return Vec3(radius * std::cos(theta), radius * std::sin(theta), z);
  }

  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    mesh_.triangles.push_back({a, b, c});
    mesh_.triangles.push_back({a, c, d});
  }

  double pitch_;
  std::uint32_t turns_, n_;
  std::uint32_t axisBase_ = 0;
  std::vector<Surface> surfaces_;
  TriangleMesh mesh_;
};

}  // namespace

double IsoThread::fundamentalHeight() const { return 0.5 * std::sqrt(3.0) * pitch; }
double IsoThread::minorDiameter() const { return majorDiameter - 2.0 * 5.0 / 8.0 * fundamentalHeight(); }
double IsoThread::pitchDiameter() const { return majorDiameter - 2.0 * 3.0 / 8.0 * fundamentalHeight(); }

double IsoThread::profileRadius(double phase) const {
  const double p = pitch, rMinor = 0.5 * minorDiameter(), rMajor = 0.5 * majorDiameter;
  const double u = phase - std::floor(phase / p) * p;
  if (u < 0.25 * p) return rMinor;
  if (u < 9.0 / 16.0 * p) return rMinor + (rMajor - rMinor) * (u - 0.25 * p) / (5.0 / 16.0 * p);
  if (u < 11.0 / 16.0 * p) return rMajor;
  return rMajor - (rMajor - rMinor) * (u - 11.0 / 16.0 * p) / (5.0 / 16.0 * p);
}

double IsoThread::solidVolumePerPitch(double radialOffset) const {
  const double p = pitch, a = 0.5 * minorDiameter() + radialOffset, b = 0.5 * majorDiameter + radialOffset;
  // Flats: r^2 x width; each flank (linear r from a to b over 5P/16): width (a^2 + ab + b^2) / 3.
  const double integral = a * a * 0.25 * p + b * b * 0.125 * p + 2.0 * (5.0 / 16.0 * p) * (a * a + a * b + b * b) / 3.0;
  return std::numbers::pi * integral;
}

void validateIsoThread(const IsoThread& thread) {
  requirePositive(thread.majorDiameter, "thread major diameter");
  requirePositive(thread.pitch, "thread pitch");
  if (!(thread.minorDiameter() > 0.0))
    throw Error(ErrorCode::kInvalidArgument, "thread pitch " + std::to_string(thread.pitch) +
                                                 " is too coarse for major diameter " +
                                                 std::to_string(thread.majorDiameter) + " (no minor diameter left)");
}

TriangleMesh makeThreadedRod(const IsoThread& thread, std::uint32_t turns, std::uint32_t segmentsPerTurn) {
  validateIsoThread(thread);
  requireCount(turns, 1, 4096, "threaded rod turns");
  requireCount(segmentsPerTurn, 6, 4096, "threaded rod segments per turn");
  ThreadedSolid solid(thread.pitch, turns, segmentsPerTurn);
  const std::array<Row, 4> rows = profileRows(thread, 0.0);
  const std::uint32_t outer = solid.addSurface(rows, [](const Row& row, std::uint32_t) { return row.radius; });
  solid.addAxis();
  solid.addStrip(outer, true);
  solid.addRamps([&](bool top, std::uint32_t m) { return solid.axis(top, m); }, outer);
  // Bottom step: the solid lies on the +theta side (+y), so the face looks toward -y; the top
  // step's solid lies at theta just below 2 pi (-y), so it looks toward +y.
  solid.addStep(solid.axisChain(false), solid.bottomChain(outer), -1.0);
  solid.addStep(solid.axisChain(true), solid.topChain(outer), 1.0);
  return solid.take();
}

TriangleMesh makeHexNut(const IsoThread& thread, double radialClearance, double acrossFlats, std::uint32_t turns,
                        std::uint32_t segmentsPerTurn) {
  validateIsoThread(thread);
  if (!(radialClearance >= 0.0) || !std::isfinite(radialClearance))
    throw Error(ErrorCode::kInvalidArgument,
                "nut radial clearance " + std::to_string(radialClearance) + " is not a finite number >= 0");
  requirePositive(acrossFlats, "nut across flats");
  requireCount(turns, 1, 4096, "nut turns");
  requireCount(segmentsPerTurn, 6, 4096, "nut segments per turn");
  if (segmentsPerTurn % 6 != 0)
    throw Error(ErrorCode::kInvalidArgument,
                "nut segments per turn " + std::to_string(segmentsPerTurn) + " is not a multiple of 6");
  if (!(0.5 * acrossFlats > 0.5 * thread.majorDiameter + radialClearance))
    throw Error(ErrorCode::kInvalidArgument, "nut across flats " + std::to_string(acrossFlats) +
                                                 " does not enclose the thread's major diameter " +
                                                 std::to_string(thread.majorDiameter) + " + clearance");
  ThreadedSolid solid(thread.pitch, turns, segmentsPerTurn);
  const std::array<Row, 4> rows = profileRows(thread, radialClearance);
  const std::uint32_t inner = solid.addSurface(rows, [](const Row& row, std::uint32_t) { return row.radius; });
  // The hexagon: corners at multiples of 60 degrees (every segmentsPerTurn / 6 samples); a
  // sample at angle theta lies at apothem / cos(theta - the middle of its side).
  const std::array<Row, 1> hexRow{Row{0.0, 0.5 * acrossFlats}};
  const std::uint32_t perSide = segmentsPerTurn / 6;
  const std::uint32_t outer = solid.addSurface(hexRow, [&](const Row& row, std::uint32_t m) {
    const double fromMiddle = 2.0 * std::numbers::pi * (double(m % perSide) - 0.5 * perSide) / segmentsPerTurn;
    return row.radius / std::cos(fromMiddle);
  });
  solid.addStrip(inner, false);
  solid.addStrip(outer, true);
  solid.addRamps(
      [&](bool top, std::uint32_t m) { return solid.id(inner, top ? solid.rowsOf(inner) : 0, m); }, outer);
  solid.addStep(solid.bottomChain(inner), solid.bottomChain(outer), -1.0);
  solid.addStep(solid.topChain(inner), solid.topChain(outer), 1.0);
  return solid.take();
}

std::vector<NamedMesh> nutBoltMeshes(const NutBoltParts& parts) {
  std::vector<NamedMesh> meshes;
  meshes.push_back({"bolt", makeThreadedRod(parts.thread, parts.boltTurns, parts.segmentsPerTurn)});
  meshes.push_back({"nut", makeHexNut(parts.thread, parts.radialClearance, parts.acrossFlats, parts.nutTurns,
                                      parts.segmentsPerTurn)});
  return meshes;
}

}  // namespace clod
