#include "clod/contact_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "clod/error.h"

namespace clod {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A half-space fits its cell "flat" when its fit error is below this fraction of the cell size
// (exactly 0 on a face, ~0.3 of the size for a cell holding a right-angled edge).
constexpr double kFlatFitRel = 0.1;

void checkSettings(const ContactSamplingSettings& s) {
  auto bad = [](const std::string& what) { throw Error(ErrorCode::kInvalidArgument, "contact sampling settings: " + what); };
  if (!(std::isfinite(s.marginAbs) && s.marginAbs >= 0.0)) bad("marginAbs must be finite and >= 0");
  if (s.samplesPerCellAxis < 1 || s.samplesPerCellAxis > 16) bad("samplesPerCellAxis must be in 1..16");
  if (!(s.offSurfaceDepthRel >= 0.0 && s.offSurfaceDepthRel <= 1.0)) bad("offSurfaceDepthRel must be in 0..1");
  if (!(s.normalConflictDeg >= 0.0 && s.normalConflictDeg <= 180.0)) bad("normalConflictDeg must be in 0..180");
  if (!(s.patchAngleDeg >= 0.0 && s.patchAngleDeg <= 180.0)) bad("patchAngleDeg must be in 0..180");
  if (s.maxContactsPerPatch < 1) bad("maxContactsPerPatch must be >= 1");
}

bool insideCell(const ContactTree& tree, const ContactCell& cell, const Vec3& p) {
  const Vec3 t = (p - tree.cellMin(cell)) / tree.cellSize(cell.depth);
  return (t.array() >= 0.0).all() && (t.array() < 1.0).all();
}

void sampleUnchecked(const ContactTree& treeS, const ContactCell& cellS, const Pose& xfWorldFromS,
                     const ContactTree& treeO, const ContactCell& cellO, const Pose& xfWorldFromO,
                     const ContactSamplingSettings& settings, std::vector<ContactPoint>& out) {
  const ContactHalfSpace* hs = treeS.halfSpace(cellS.node);
  if (!hs) return;
  const double h = treeS.cellSize(cellS.depth);
  const Vec3 n(hs->normal[0], hs->normal[1], hs->normal[2]);
  const Vec3 onPlane = treeS.cellCenter(cellS) + double(hs->offset) * n;
  const Vec3 u = n.cross(std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).normalized();
  const Vec3 v = n.cross(u);
  // No two samples closer than 4 eps_s: the field cannot tell such points apart.
  const double perAxis = std::clamp(std::floor(h / (4.0 * treeS.errorAbs)), 1.0, double(settings.samplesPerCellAxis));
  const double spacing = h / perAxis;
  // The plane meets the cube within a disc of radius half the diagonal around onPlane.
  const int reach = static_cast<int>(std::ceil(0.8660254037844386 * h / spacing));
  const Vec3 normalWorldS = xfWorldFromS.rotation * n;
  const double conflictCos = std::cos(settings.normalConflictDeg * kPi / 180.0);
  const bool flatS = double(hs->fitError) <= kFlatFitRel * h;
  const int layers = settings.offSurfaceDepthRel > 0.0 ? 2 : 1;
  for (int layer = 0; layer < layers; ++layer) {
    const Vec3 layerOrigin = onPlane - (layer * settings.offSurfaceDepthRel * h) * n;
    for (int i = -reach; i <= reach; ++i) {
      for (int j = -reach; j <= reach; ++j) {
        const Vec3 pS = layerOrigin + (i * spacing) * u + (j * spacing) * v;
        if (!insideCell(treeS, cellS, pS)) continue;
        const Vec3 pWorld = xfWorldFromS.apply(pS);
        const Vec3 pO = xfWorldFromO.applyInverse(pWorld);
        if (!insideCell(treeO, cellO, pO)) continue;
        const ContactFieldSample f = treeO.sample(pO, settings.maxDepth);
        if (f.distance > settings.marginAbs) continue;
        const double gradientLength = f.gradient.norm();
        if (!(gradientLength > 1e-12)) continue;  // flat interpolant: no direction to push
        Vec3 normal = xfWorldFromO.rotation * (f.gradient / gradientLength);
        if (normal.dot(-normalWorldS) < conflictCos && flatS) {
          // The other body shows an edge or corner here while our cell is a flat face: an edge
          // or vertex on a face pushes along the face normal, not along the rounded field.
          const ContactHalfSpace* ho = treeO.halfSpace(f.node);
          if (ho && double(ho->fitError) > kFlatFitRel * treeO.cellSize(f.depth)) normal = -normalWorldS;
        }
        out.push_back({pWorld, normal, -f.distance, f.errorBound, 0});
      }
    }
  }
}

struct Traversal {
  const ContactTree& a;
  const ContactTree& b;
  const Pose& xfA;
  const Pose& xfB;
  const ContactSamplingSettings& settings;
  std::vector<ContactPoint>& out;
  ContactQueryStats& stats;

  bool leafA(const ContactCell& c) const { return a.isLeaf(c.node) || c.depth >= settings.maxDepth; }
  bool leafB(const ContactCell& c) const { return b.isLeaf(c.node) || c.depth >= settings.maxDepth; }

  void visit(const ContactCell& ca, const ContactCell& cb) {
    ++stats.cellPairsVisited;
    // Every sample lies in one cell of each tree, so only sphere pairs that touch can share one.
    const Vec3 centreA = xfA.apply(a.cellCenter(ca));
    const Vec3 centreB = xfB.apply(b.cellCenter(cb));
    const double radii = a.cellRadius(ca.depth) + b.cellRadius(cb.depth);
    if ((centreA - centreB).squaredNorm() > radii * radii) return;
    const bool la = leafA(ca), lb = leafB(cb);
    if (la && lb) {
      if (a.halfSpace(ca.node)) {
        ++stats.cellPairsSampled;
        sampleUnchecked(a, ca, xfA, b, cb, xfB, settings, out);
      }
      if (b.halfSpace(cb.node)) {
        ++stats.cellPairsSampled;
        const std::size_t first = out.size();
        sampleUnchecked(b, cb, xfB, a, ca, xfA, settings, out);
        for (std::size_t i = first; i < out.size(); ++i) {
          out[i].normal = -out[i].normal;  // the convention is "out of B toward A"
          out[i].sampledBody = 1;
        }
      }
      return;
    }
    const bool splitA = !la && (lb || a.cellRadius(ca.depth) >= b.cellRadius(cb.depth));
    for (std::uint32_t o = 0; o < 8; ++o) {
      if (splitA) {
        const ContactCell child = a.childCell(ca, o);
        if (a.minDistance(child) <= settings.marginAbs) visit(child, cb);
      } else {
        const ContactCell child = b.childCell(cb, o);
        if (b.minDistance(child) <= settings.marginAbs) visit(ca, child);
      }
    }
  }
};

// Area of triangle (p1, p2, p) projected along n, signed: which side of line p1-p2 p lies on.
double signedArea(const Vec3& p1, const Vec3& p2, const Vec3& p, const Vec3& n) { return (p2 - p1).cross(p - p1).dot(n); }

}  // namespace

void sampleCellPair(const ContactTree& treeS, const ContactCell& cellS, const Pose& xfWorldFromS,
                    const ContactTree& treeO, const ContactCell& cellO, const Pose& xfWorldFromO,
                    const ContactSamplingSettings& settings, std::vector<ContactPoint>& out) {
  checkSettings(settings);
  sampleUnchecked(treeS, cellS, xfWorldFromS, treeO, cellO, xfWorldFromO, settings, out);
}

void findContacts(const ContactTree& treeA, const Pose& xfWorldFromA, const ContactTree& treeB,
                  const Pose& xfWorldFromB, const ContactSamplingSettings& settings,
                  std::vector<ContactPoint>& out, ContactQueryStats* stats) {
  checkSettings(settings);
  out.clear();
  ContactQueryStats local;
  Traversal traversal{treeA, treeB, xfWorldFromA, xfWorldFromB, settings, out, local};
  const ContactCell rootA = treeA.rootCell(), rootB = treeB.rootCell();
  if (treeA.minDistance(rootA) <= settings.marginAbs && treeB.minDistance(rootB) <= settings.marginAbs)
    traversal.visit(rootA, rootB);
  local.rawContacts = out.size();
  reduceContacts(out, settings);
  if (stats) *stats = local;
}

void reduceContacts(std::vector<ContactPoint>& contacts, const ContactSamplingSettings& settings) {
  checkSettings(settings);
  std::sort(contacts.begin(), contacts.end(), [](const ContactPoint& x, const ContactPoint& y) { return x.depth > y.depth; });
  const double patchCos = std::cos(settings.patchAngleDeg * kPi / 180.0);
  const std::size_t keep = settings.maxContactsPerPatch;
  std::size_t write = 0;
  std::size_t begin = 0;
  while (begin < contacts.size()) {
    // The deepest remaining contact founds a patch; gather its members at [begin, end).
    const Vec3 n = contacts[begin].normal;
    const auto endIt = std::partition(contacts.begin() + begin + 1, contacts.end(),
                                      [&](const ContactPoint& c) { return c.normal.dot(n) >= patchCos; });
    const std::size_t end = static_cast<std::size_t>(endIt - contacts.begin());
    std::size_t chosen = begin;  // [begin, chosen) are kept
    auto pick = [&](auto score) {
      if (chosen >= end) return;
      std::size_t best = chosen;
      double bestScore = score(contacts[chosen].point);
      for (std::size_t i = chosen + 1; i < end; ++i) {
        const double s = score(contacts[i].point);
        if (s > bestScore) bestScore = s, best = i;
      }
      std::swap(contacts[chosen], contacts[best]);
      ++chosen;
    };
    if (end - begin <= keep) {
      chosen = end;
    } else {
      Vec3 centroid = Vec3::Zero();
      for (std::size_t i = begin; i < end; ++i) centroid += contacts[i].point;
      centroid /= double(end - begin);
      pick([&](const Vec3& p) { return (p - centroid).squaredNorm(); });
      const Vec3 p1 = contacts[begin].point;
      if (keep >= 2) pick([&](const Vec3& p) { return (p - p1).squaredNorm(); });
      const Vec3 p2 = contacts[begin + 1].point;
      if (keep >= 3) pick([&](const Vec3& p) { return signedArea(p1, p2, p, n); });
      if (keep >= 4) pick([&](const Vec3& p) { return -signedArea(p1, p2, p, n); });
      if (keep >= 5) {
        // Beyond the four that span the patch: the deepest remaining, then farthest-point picks.
        std::size_t deepest = chosen;
        for (std::size_t i = chosen; i < end; ++i)
          if (contacts[i].depth > contacts[deepest].depth) deepest = i;
        std::swap(contacts[chosen], contacts[deepest]);
        ++chosen;
        while (chosen - begin < keep && chosen < end) {
          pick([&](const Vec3& p) {
            double nearest = std::numeric_limits<double>::infinity();
            for (std::size_t k = begin; k < chosen; ++k) nearest = std::min(nearest, (p - contacts[k].point).squaredNorm());
            return nearest;
          });
        }
      }
    }
    for (std::size_t i = begin; i < chosen; ++i) contacts[write++] = contacts[i];
    begin = end;
  }
  contacts.resize(write);
}

}  // namespace clod
