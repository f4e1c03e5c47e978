#include "medial_reduction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <span>
#include <unordered_map>
#include <utility>

#include "min_sphere.h"

namespace clod::detail {

VertexTriangles::VertexTriangles(const TriangleMesh& mesh) {
  offsets.assign(static_cast<std::size_t>(mesh.vertexCount()) + 1, 0);
  for (const auto& tri : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++offsets[tri[k] + 1];
  for (std::size_t v = 0; v + 1 < offsets.size(); ++v) offsets[v + 1] += offsets[v];
  triangles.resize(offsets.back());
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) triangles[fill[mesh.triangles[t][k]]++] = t;
}

namespace {

constexpr int kAxes = 7;
constexpr int kExtremes = 2 * kAxes;
constexpr int kMaxInterior = 16;
constexpr int kSummaryPoints = kExtremes + kMaxInterior;
constexpr int kFitDirections = 16;
// A node needs this many starting spheres per child for the reduction to have a choice.
constexpr std::uint32_t kMinInitialPerChild = 2;
constexpr std::uint32_t kBurst = 0xffffffffu;

// Directions of the extreme points: the 3 axes and the 4 cube diagonals, both ways. Extremes in
// these 14 directions bound a 14-DOP, whose corners are within a few per cent of the points'
// hull for the smallest enclosing sphere.
const std::array<Vec3, kExtremes>& extremeDirections() {
  static const std::array<Vec3, kExtremes> dirs = [] {
    const double s = 1.0 / std::sqrt(3.0);
    const Vec3 axes[kAxes] = {Vec3::UnitX(),     Vec3::UnitY(),      Vec3::UnitZ(),     Vec3(s, s, s),
                              Vec3(s, s, -s), Vec3(s, -s, s), Vec3(-s, s, s)};
    std::array<Vec3, kExtremes> d;
    for (int i = 0; i < kAxes; ++i) {
      d[2 * i] = axes[i];
      d[2 * i + 1] = -axes[i];
    }
    return d;
  }();
  return dirs;
}

const std::array<Vec3, kFitDirections>& fitDirections() {
  static const std::array<Vec3, kFitDirections> dirs = [] {
    std::array<Vec3, kFitDirections> d;
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < kFitDirections; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / kFitDirections;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      d[i] = Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    return d;
  }();
  return dirs;
}

// Bounded stand-in for the surface a sphere is responsible for (see the header).
struct Summary {
  std::array<Vec3, kExtremes> extreme;
  std::array<double, kExtremes> extremeValue;
  std::array<Vec3, kMaxInterior> interior;
  int interiorCount = 0;
  Vec3 medialSum = Vec3::Zero();  // sum of weight * medial point
  double weight = 0.0;            // area (plus a floor, so zero-area pieces count)

  Summary() { extremeValue.fill(-std::numeric_limits<double>::infinity()); }

  void addExtremeCandidate(const Vec3& p) {
    const auto& dirs = extremeDirections();
    for (int i = 0; i < kExtremes; ++i) {
      const double v = dirs[i].dot(p);
      if (v > extremeValue[i]) {
        extremeValue[i] = v;
        extreme[i] = p;
      }
    }
  }
  Vec3 medialCenter() const { return medialSum / weight; }
  int points(std::array<Vec3, kSummaryPoints>& out) const {
    int n = 0;
    for (int i = 0; i < kExtremes; ++i)
      if (std::isfinite(extremeValue[i])) out[n++] = extreme[i];
    for (int i = 0; i < interiorCount; ++i) out[n++] = interior[i];
    return n;
  }
};

double pieceWeight(const SurfacePiece& piece) { return piece.area + 1e-300; }

// Up to kMaxInterior of `candidates`, evenly spread over the list.
void takeSpread(std::span<const Vec3> candidates, int count, Summary& out) {
  const int n = static_cast<int>(candidates.size());
  for (int i = 0; i < count && out.interiorCount < kMaxInterior; ++i)
    out.interior[out.interiorCount++] = candidates[static_cast<std::size_t>((static_cast<long>(i) * n) / count)];
}

Summary summarizePieces(std::span<const SurfacePiece> all, std::span<const std::uint32_t> ids) {
  Summary s;
  std::vector<Vec3> centroids;
  centroids.reserve(ids.size() * 4);
  for (std::uint32_t id : ids) {
    const SurfacePiece& piece = all[id];
    for (const Vec3& p : piece.points()) s.addExtremeCandidate(p);
    const Vec3 c = piece.centroid();
    // The centroid and the points half-way to the corners stand for the piece's interior, so
    // a large flat piece does not look like a few distant corners to the fit estimate.
    centroids.push_back(c);
    for (const Vec3& p : piece.points()) centroids.push_back(0.5 * (c + p));
    const double w = pieceWeight(piece);
    s.medialSum += w * (c + piece.poleOffset);
    s.weight += w;
  }
  takeSpread(centroids, std::min<int>(kMaxInterior, static_cast<int>(centroids.size())), s);
  return s;
}

Summary mergeSummaries(const Summary& a, const Summary& b) {
  Summary m;
  for (int i = 0; i < kExtremes; ++i) {
    const bool fromA = a.extremeValue[i] >= b.extremeValue[i];
    m.extremeValue[i] = fromA ? a.extremeValue[i] : b.extremeValue[i];
    m.extreme[i] = fromA ? a.extreme[i] : b.extreme[i];
  }
  m.medialSum = a.medialSum + b.medialSum;
  m.weight = a.weight + b.weight;
  const int na = a.interiorCount, nb = b.interiorCount;
  if (na + nb <= kMaxInterior) {
    takeSpread({a.interior.data(), static_cast<std::size_t>(na)}, na, m);
    takeSpread({b.interior.data(), static_cast<std::size_t>(nb)}, nb, m);
  } else {
    // Keep interior points in proportion to the two surfaces' areas.
    int qa = static_cast<int>(std::lround(kMaxInterior * a.weight / m.weight));
    qa = std::clamp(qa, std::max(0, kMaxInterior - nb), std::min(na, kMaxInterior));
    takeSpread({a.interior.data(), static_cast<std::size_t>(na)}, qa, m);
    takeSpread({b.interior.data(), static_cast<std::size_t>(nb)}, kMaxInterior - qa, m);
  }
  return m;
}

struct Fitted {
  Sphere sphere;
  double fit = 0.0;
};

// Bradshaw's overshoot estimate against the summary points, at the best of three centres.
Fitted fitSummary(const Summary& s, std::vector<Vec3>& scratch) {
  std::array<Vec3, kSummaryPoints> pts;
  const int n = s.points(pts);
  const std::span<const Vec3> points(pts.data(), static_cast<std::size_t>(n));
  const Sphere smallest = minimumEnclosingSphere(points, scratch);
  const Vec3 medial = s.medialCenter();
  Fitted best;
  best.fit = std::numeric_limits<double>::infinity();
  double bestWorst = std::numeric_limits<double>::infinity();  // best.fit squared
  for (int c = 0; c < 3; ++c) {
    Sphere sphere;
    sphere.center = smallest.center + 0.5 * c * (medial - smallest.center);
    sphere.radius = c == 0 ? smallest.radius : farthestDistance(sphere.center, points);
    // max over directions of min over points; both loops stop once the answer cannot change:
    // a point nearer than the worst so far settles a direction, a worst beyond the best centre's
    // rules this centre out (the same spheres and fits as the full loops, at a fraction of the cost).
    double worst = 0.0;
    for (const Vec3& d : fitDirections()) {
      const Vec3 q = sphere.center + sphere.radius * d;
      double nearest = std::numeric_limits<double>::infinity();
      for (const Vec3& p : points) {
        nearest = std::min(nearest, (p - q).squaredNorm());
        if (nearest <= worst) break;
      }
      worst = std::max(worst, nearest);
      if (worst >= bestWorst) break;
    }
    if (worst >= bestWorst) continue;
    bestWorst = worst;
    best = {sphere, std::sqrt(worst)};
  }
  return best;
}

struct Cluster {
  Summary summary;
  Fitted fitted;
  std::vector<std::uint32_t> pieces;
  std::vector<std::uint32_t> neighbours;  // sorted, unique, never itself
  std::uint32_t version = 0;              // bumped when the sphere changes
  std::uint32_t stamp = 0;                // bumped when the sphere or a neighbour changes
  bool alive = true;
};

struct Operation {
  double cost;
  std::uint32_t a, b;    // b == kBurst: burst a
  std::uint32_t va, vb;  // versions (merge) or stamp of a (burst) when queued
  bool operator>(const Operation& o) const {
    if (cost != o.cost) return cost > o.cost;
    if (a != o.a) return a > o.a;
    return b > o.b;
  }
};

void insertSorted(std::vector<std::uint32_t>& list, std::uint32_t value) {
  const auto it = std::lower_bound(list.begin(), list.end(), value);
  if (it == list.end() || *it != value) list.insert(it, value);
}
void eraseSorted(std::vector<std::uint32_t>& list, std::uint32_t value) {
  const auto it = std::lower_bound(list.begin(), list.end(), value);
  if (it != list.end() && *it == value) list.erase(it);
}

class Reducer {
public:
  Reducer(std::span<const SurfacePiece> pieces, std::uint32_t k) : pieces_(pieces), k_(k) {}

  std::vector<std::uint32_t> run(const TriangleMesh& mesh, const VertexTriangles& adjacency) {
    mesh_ = &mesh;
    adjacency_ = &adjacency;
    const std::uint32_t n = static_cast<std::uint32_t>(pieces_.size());
    linkByMeshAdjacency(startingSpheres());
    for (std::uint32_t c = 0; c < clusters_.size(); ++c) {
      for (std::uint32_t m : clusters_[c].neighbours)
        if (m > c) queueMerge(c, m);
      queueBurst(c);
    }
    std::uint32_t alive = static_cast<std::uint32_t>(clusters_.size());
    bool linkedLeftovers = false;
    while (alive > k_) {
      if (queue_.empty()) {
        if (linkedLeftovers) break;
        linkLeftovers();
        linkedLeftovers = true;
        continue;
      }
      const Operation op = queue_.top();
      queue_.pop();
      Cluster& a = clusters_[op.a];
      if (op.b == kBurst) {
        if (!a.alive) continue;
        if (a.stamp != op.va) {
          queueBurst(op.a);  // lazy update: re-evaluate in the changed neighbourhood
          continue;
        }
        burst(op.a);
      } else {
        const std::uint32_t x = representative(op.a), y = representative(op.b);
        if (x == kBurst || y == kBurst || x == y) continue;
        if (x != op.a || y != op.b || clusters_[x].version != op.va || clusters_[y].version != op.vb) {
          // Lazy update: the pair changed since it was queued; queue it afresh unless that
          // has been done already.
          const std::uint64_t key = pairKey(x, y);
          const std::uint64_t versions = pairKey(clusters_[std::min(x, y)].version, clusters_[std::max(x, y)].version);
          const auto [it, inserted] = queuedVersions_.try_emplace(key, versions);
          if (!inserted && it->second == versions) continue;
          it->second = versions;
          queueMerge(x, y);
          continue;
        }
        merge(op.a, op.b);
      }
      --alive;
      linkedLeftovers = false;
    }
    std::vector<std::uint32_t> label(n, 0);
    std::uint32_t next = 0;
    for (const Cluster& c : clusters_) {
      if (!c.alive) continue;
      for (std::uint32_t p : c.pieces) label[p] = next;
      ++next;
    }
    return label;
  }

private:
  // One cluster per distinct inner pole, or per piece when the node touches too few poles.
  std::vector<std::uint32_t> startingSpheres() {
    const std::uint32_t n = static_cast<std::uint32_t>(pieces_.size());
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t x, std::uint32_t y) { return pieces_[x].pole < pieces_[y].pole; });
    std::uint32_t groups = 0;
    for (std::uint32_t i = 0; i < n; ++i)
      if (i == 0 || pieces_[order[i]].pole != pieces_[order[i - 1]].pole) ++groups;
    const bool perPiece = groups < kMinInitialPerChild * k_;
    std::vector<std::uint32_t> clusterOf(n);
    if (perPiece) {
      clusters_.resize(n);
      for (std::uint32_t i = 0; i < n; ++i) {
        clusterOf[i] = i;
        clusters_[i].pieces.push_back(i);
      }
    } else {
      clusters_.resize(groups);
      std::uint32_t c = 0;
      for (std::uint32_t i = 0; i < n; ++i) {
        if (i > 0 && pieces_[order[i]].pole != pieces_[order[i - 1]].pole) ++c;
        clusterOf[order[i]] = c;
        clusters_[c].pieces.push_back(order[i]);
      }
    }
    mergedInto_.resize(clusters_.size());
    for (std::uint32_t c = 0; c < clusters_.size(); ++c) mergedInto_[c] = c;
    for (Cluster& c : clusters_) {
      c.summary = summarizePieces(pieces_, c.pieces);
      c.fitted = fitSummary(c.summary, scratch_);
    }
    return clusterOf;
  }

  // Spheres are neighbours when pieces of theirs lie on triangles that share a vertex.
  // Calls f(j) for every piece j on a triangle that shares a vertex with piece i's triangle.
  template <class F>
  void forAdjacentPieces(std::uint32_t i, F&& f) const {
    for (int k = 0; k < 3; ++k)
      for (std::uint32_t u : adjacency_->around(mesh_->triangles[pieces_[i].triangle][k])) {
        auto it = std::lower_bound(byTriangle_.begin(), byTriangle_.end(), std::make_pair(u, std::uint32_t{0}));
        for (; it != byTriangle_.end() && it->first == u; ++it) f(it->second);
      }
  }

  void linkByMeshAdjacency(const std::vector<std::uint32_t>& clusterOf) {
    const std::uint32_t n = static_cast<std::uint32_t>(pieces_.size());
    byTriangle_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) byTriangle_[i] = {pieces_[i].triangle, i};
    std::sort(byTriangle_.begin(), byTriangle_.end());
    pieceCluster_ = clusterOf;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t ci = clusterOf[i];
      forAdjacentPieces(i, [&](std::uint32_t j) {
        const std::uint32_t cj = clusterOf[j];
        if (cj != ci) edges.emplace_back(std::min(ci, cj), std::max(ci, cj));
      });
    }
    linkComponents(edges);
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (const auto& [x, y] : edges) {
      clusters_[x].neighbours.push_back(y);
      clusters_[y].neighbours.push_back(x);
    }
    for (Cluster& c : clusters_) std::sort(c.neighbours.begin(), c.neighbours.end());
  }

  // Parts of the node's surface that do not touch the rest through the mesh (scan debris,
  // separate shells, pieces a parent's clipping cut off) would otherwise stay separate spheres
  // to the end and take child slots from the main surface: link every sphere of each smaller
  // component to its two nearest spheres (by gap) outside that component.
  void linkComponents(std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges) {
    const std::uint32_t n = static_cast<std::uint32_t>(clusters_.size());
    std::vector<std::uint32_t> root(n);
    for (std::uint32_t i = 0; i < n; ++i) root[i] = i;
    auto find = [&](std::uint32_t x) {
      while (root[x] != x) x = root[x] = root[root[x]];
      return x;
    };
    for (const auto& [x, y] : edges) root[find(x)] = find(y);
    std::vector<std::uint32_t> size(n, 0);
    for (std::uint32_t i = 0; i < n; ++i) ++size[find(i)];
    std::uint32_t largest = 0;
    for (std::uint32_t i = 0; i < n; ++i)
      if (size[i] > size[largest]) largest = i;
    if (size[largest] == n) return;
    std::vector<std::uint32_t> component(n);
    for (std::uint32_t i = 0; i < n; ++i) component[i] = find(i);
    for (std::uint32_t c = 0; c < n; ++c) {
      if (component[c] == largest) continue;
      const Sphere& s = clusters_[c].fitted.sphere;
      std::pair<double, std::uint32_t> nearest[2] = {{std::numeric_limits<double>::infinity(), kBurst},
                                                     {std::numeric_limits<double>::infinity(), kBurst}};
      for (std::uint32_t o = 0; o < n; ++o) {
        if (component[o] == component[c]) continue;
        const Sphere& t = clusters_[o].fitted.sphere;
        const std::pair<double, std::uint32_t> cand{(s.center - t.center).norm() - s.radius - t.radius, o};
        if (cand < nearest[0]) {
          nearest[1] = nearest[0];
          nearest[0] = cand;
        } else if (cand < nearest[1]) {
          nearest[1] = cand;
        }
      }
      for (const auto& [gap, o] : nearest)
        if (o != kBurst) edges.emplace_back(std::min(c, o), std::max(c, o));
    }
  }

  // Separate surface components never meet through the mesh: link every remaining sphere to
  // its two nearest (by gap between the spheres).
  void linkLeftovers() {
    std::vector<std::uint32_t> alive;
    for (std::uint32_t c = 0; c < clusters_.size(); ++c)
      if (clusters_[c].alive) alive.push_back(c);
    for (std::uint32_t c : alive) {
      const Sphere& s = clusters_[c].fitted.sphere;
      std::pair<double, std::uint32_t> nearest[2] = {{std::numeric_limits<double>::infinity(), kBurst},
                                                     {std::numeric_limits<double>::infinity(), kBurst}};
      for (std::uint32_t o : alive) {
        if (o == c) continue;
        const Sphere& t = clusters_[o].fitted.sphere;
        const std::pair<double, std::uint32_t> cand{(s.center - t.center).norm() - s.radius - t.radius, o};
        if (cand < nearest[0]) {
          nearest[1] = nearest[0];
          nearest[0] = cand;
        } else if (cand < nearest[1]) {
          nearest[1] = cand;
        }
      }
      for (const auto& [gap, o] : nearest) {
        if (o == kBurst) continue;
        insertSorted(clusters_[c].neighbours, o);
        insertSorted(clusters_[o].neighbours, c);
        queueMerge(c, o);
      }
    }
  }

  static std::uint64_t pairKey(std::uint32_t x, std::uint32_t y) {
    return (static_cast<std::uint64_t>(std::min(x, y)) << 32) | std::max(x, y);
  }

  // The live cluster that `c` has been merged into (kBurst if that one burst).
  std::uint32_t representative(std::uint32_t c) {
    std::uint32_t r = c;
    while (r != kBurst && mergedInto_[r] != r) r = mergedInto_[r];
    while (c != kBurst && mergedInto_[c] != c) {  // path compression
      const std::uint32_t next = mergedInto_[c];
      mergedInto_[c] = r;
      c = next;
    }
    return r;
  }

  void queueMerge(std::uint32_t a, std::uint32_t b) {
    const Cluster& ca = clusters_[a];
    const Cluster& cb = clusters_[b];
    const Fitted merged = fitSummary(mergeSummaries(ca.summary, cb.summary), scratch_);
    queue_.push({merged.fit, a, b, ca.version, cb.version});
  }

  // Which neighbour of the bursting sphere takes point p: the one p sticks out of least.
  std::uint32_t receiverOf(const Cluster& bursting, const Vec3& p) const {
    std::uint32_t best = bursting.neighbours.front();
    double bestOut = std::numeric_limits<double>::infinity();
    for (std::uint32_t m : bursting.neighbours) {
      const Sphere& s = clusters_[m].fitted.sphere;
      const double out = (p - s.center).norm() - s.radius;
      if (out < bestOut) {
        bestOut = out;
        best = m;
      }
    }
    return best;
  }

  void queueBurst(std::uint32_t c) {
    const Cluster& cluster = clusters_[c];
    if (cluster.neighbours.empty()) return;
    // Hand the summary points to the neighbours, as the burst would hand the pieces.
    std::array<Vec3, kSummaryPoints> pts;
    const int n = cluster.summary.points(pts);
    // (receiver, point) grouped by receiver, in point order within a group: an insertion sort
    // on the stack (at most kSummaryPoints entries; this runs for every cluster change).
    std::array<std::pair<std::uint32_t, Vec3>, kSummaryPoints> handedStore;
    const std::span<std::pair<std::uint32_t, Vec3>> handed(handedStore.data(), static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const std::pair<std::uint32_t, Vec3> entry(receiverOf(cluster, pts[i]), pts[i]);
      int k = i;
      for (; k > 0 && handedStore[k - 1].first > entry.first; --k) handedStore[k] = handedStore[k - 1];
      handedStore[k] = entry;
    }
    double cost = 0.0;
    for (std::size_t i = 0; i < handed.size();) {
      std::size_t j = i;
      Summary extra;
      std::array<Vec3, kSummaryPoints> interior;
      int interiorCount = 0;
      for (; j < handed.size() && handed[j].first == handed[i].first; ++j) {
        extra.addExtremeCandidate(handed[j].second);
        interior[interiorCount++] = handed[j].second;
      }
      const double share = static_cast<double>(j - i) / handed.size();
      takeSpread({interior.data(), static_cast<std::size_t>(interiorCount)},
                 std::min(kMaxInterior, interiorCount), extra);
      extra.weight = share * cluster.summary.weight;
      extra.medialSum = share * cluster.summary.medialSum;
      const Cluster& receiver = clusters_[handed[i].first];
      const Fitted grown = fitSummary(mergeSummaries(receiver.summary, extra), scratch_);
      cost = std::max(cost, grown.fit);
      i = j;
    }
    queue_.push({cost, c, kBurst, cluster.stamp, 0});
  }

  void changed(std::uint32_t c) {
    Cluster& cluster = clusters_[c];
    ++cluster.version;
    ++cluster.stamp;
    for (std::uint32_t m : cluster.neighbours) ++clusters_[m].stamp;
  }

  void merge(std::uint32_t a, std::uint32_t b) {
    Cluster& ca = clusters_[a];
    Cluster& cb = clusters_[b];
    ca.summary = mergeSummaries(ca.summary, cb.summary);
    ca.fitted = fitSummary(ca.summary, scratch_);
    ca.pieces.insert(ca.pieces.end(), cb.pieces.begin(), cb.pieces.end());
    for (std::uint32_t m : cb.neighbours) {
      if (m == a) continue;
      eraseSorted(clusters_[m].neighbours, b);
      insertSorted(clusters_[m].neighbours, a);
      insertSorted(ca.neighbours, m);
    }
    eraseSorted(ca.neighbours, b);
    cb.alive = false;
    cb.neighbours.clear();
    cb.pieces.clear();
    mergedInto_[b] = a;
    // No re-evaluation here: the queued pairs of a and b are re-evaluated when they come up.
    changed(a);
  }

  void burst(std::uint32_t c) {
    Cluster& bursting = clusters_[c];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> handed;  // (receiver, piece)
    handed.reserve(bursting.pieces.size());
    for (std::uint32_t p : bursting.pieces) handed.emplace_back(receiverOf(bursting, pieces_[p].centroid()), p);
    std::stable_sort(handed.begin(), handed.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    const std::vector<std::uint32_t> around = bursting.neighbours;
    for (std::uint32_t m : around) eraseSorted(clusters_[m].neighbours, c);
    bursting.alive = false;
    mergedInto_[c] = kBurst;
    bursting.neighbours.clear();
    bursting.pieces.clear();
    std::vector<std::uint32_t> receivers;
    for (std::size_t i = 0; i < handed.size();) {
      const std::uint32_t r = handed[i].first;
      std::vector<std::uint32_t> given;
      for (; i < handed.size() && handed[i].first == r; ++i) given.push_back(handed[i].second);
      Cluster& receiver = clusters_[r];
      receiver.summary = mergeSummaries(receiver.summary, summarizePieces(pieces_, given));
      receiver.fitted = fitSummary(receiver.summary, scratch_);
      receiver.pieces.insert(receiver.pieces.end(), given.begin(), given.end());
      for (std::uint32_t p : given) pieceCluster_[p] = r;
      receivers.push_back(r);
    }
    // The receivers now border whatever their new pieces border.
    for (const auto& [r, p] : handed)
      forAdjacentPieces(p, [&](std::uint32_t q) {
        const std::uint32_t m = representative(pieceCluster_[q]);
        if (m == r || m == kBurst) return;
        const auto it = std::lower_bound(clusters_[r].neighbours.begin(), clusters_[r].neighbours.end(), m);
        if (it != clusters_[r].neighbours.end() && *it == m) return;
        clusters_[r].neighbours.insert(it, m);
        insertSorted(clusters_[m].neighbours, r);
        // A new pair, queued unevaluated at a cost below its true one (merging never fits
        // better than the worse of the two); it is evaluated when it comes up.
        queue_.push({std::max(clusters_[r].fitted.fit, clusters_[m].fitted.fit), r, m, kBurst, kBurst});
      });
    for (std::uint32_t r : receivers) changed(r);
  }

  std::span<const SurfacePiece> pieces_;
  std::uint32_t k_;
  const TriangleMesh* mesh_ = nullptr;
  const VertexTriangles* adjacency_ = nullptr;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> byTriangle_;  // (triangle, piece), sorted
  std::vector<std::uint32_t> pieceCluster_;  // cluster a piece was last given to (follow merges)
  std::vector<Cluster> clusters_;
  std::vector<std::uint32_t> mergedInto_;  // itself while alive, kBurst once burst
  std::unordered_map<std::uint64_t, std::uint64_t> queuedVersions_;  // pair -> versions last queued
  std::priority_queue<Operation, std::vector<Operation>, std::greater<Operation>> queue_;
  std::vector<Vec3> scratch_;
};

}  // namespace

std::vector<std::uint32_t> reduceByMergeAndBurst(const TriangleMesh& mesh, const VertexTriangles& adjacency,
                                                 std::span<const SurfacePiece> pieces, std::uint32_t k) {
  const std::uint32_t n = static_cast<std::uint32_t>(pieces.size());
  if (n <= k) {
    std::vector<std::uint32_t> label(n);
    for (std::uint32_t i = 0; i < n; ++i) label[i] = i;
    return label;
  }
  Reducer reducer(pieces, k);
  return reducer.run(mesh, adjacency);
}

}  // namespace clod::detail
