#include "polygon_triangulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

namespace clod::detail {

namespace {

struct Point2 {
  double x, y;
};

// Twice the signed area of (a, b, c): positive when they turn left (counter-clockwise).
double orient(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// A turn a -> b -> c counts as a left turn only when orient() exceeds what rounding can do to
// it. The projected coordinates are off by a few ulps of `extent` (the largest distance from
// corner 0), so orient() is off by about eps * extent * (|b - a| + |c - a|); corners that are
// collinear in the file (common: vertices along a straight edge) must not look convex, or the
// triangulation would cut zero-area triangles off them.
struct TurnTest {
  double scale;  // 64 eps * extent
  bool isLeftTurn(const Point2& a, const Point2& b, const Point2& c) const {
    const double lengths = std::abs(b.x - a.x) + std::abs(b.y - a.y) + std::abs(c.x - a.x) + std::abs(c.y - a.y);
    return orient(a, b, c) > scale * lengths;
  }
};

TurnTest turnTestFor(const std::vector<Point2>& points) {
  double extent = 0.0;
  for (const Point2& p : points) extent = std::max({extent, std::abs(p.x), std::abs(p.y)});
  return {64.0 * std::numeric_limits<double>::epsilon() * extent};
}

// Sum of the cross products of consecutive corners: Newell's normal, twice the vector area.
// Taken relative to corner 0 so that a face far from the origin keeps its digits.
Vec3 newellNormal(std::span<const Vec3> corners) {
  Vec3 normal = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < corners.size(); ++i) normal += (corners[i] - corners[0]).cross(corners[i + 1] - corners[0]);
  return normal;
}

// Coordinates in the plane perpendicular to `normal`, in a basis (u, v) with u x v along the
// normal, so the polygon winds counter-clockwise. Empty when the plane is undefined or a
// coordinate is not finite.
std::vector<Point2> projectOntoPlane(std::span<const Vec3> corners, const Vec3& normal) {
  const double length = normal.norm();
  if (!(length > 0.0) || !std::isfinite(length)) return {};
  const Vec3 w = normal / length;
  const Vec3 u = w.unitOrthogonal();
  const Vec3 v = w.cross(u);
  std::vector<Point2> points(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Vec3 d = corners[i] - corners[0];
    points[i] = {d.dot(u), d.dot(v)};
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y)) return {};
  }
  return points;
}

// The sweep order: higher y first, ties broken by smaller x, then by index, so that it is a
// strict total order even with horizontal edges and repeated points.
struct SweepOrder {
  const std::vector<Point2>* points;
  bool above(std::uint32_t a, std::uint32_t b) const {
    const Point2& p = (*points)[a];
    const Point2& q = (*points)[b];
    if (p.y != q.y) return p.y > q.y;
    if (p.x != q.x) return p.x < q.x;
    return a < b;
  }
};

void appendFan(std::uint32_t n, std::vector<Triangle>& out) {
  for (std::uint32_t k = 1; k + 1 < n; ++k) out.push_back({0, k, k + 1});
}

// Strictly convex: every corner turns left and the boundary goes down and up once (a star
// polygon turns left everywhere too, but winds more than once).
bool isStrictlyConvex(const std::vector<Point2>& points, const SweepOrder& order, const TurnTest& turns) {
  const auto n = static_cast<std::uint32_t>(points.size());
  std::uint32_t peaks = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t prev = (i + n - 1) % n, next = (i + 1) % n;
    if (!turns.isLeftTurn(points[prev], points[i], points[next])) return false;
    if (order.above(i, prev) && order.above(i, next)) ++peaks;
  }
  return peaks == 1;
}

// Splits a counter-clockwise polygon into y-monotone pieces by adding diagonals at split and
// merge vertices (de Berg et al., ch. 3.2). The sweep status holds the edges with the interior
// on their right (edge i runs from corner i down to corner i+1), ordered by x on the sweep line.
// If the polygon is not simple that order can change while edges sit in the status; the tree
// then stays memory-safe (each edge is erased through the iterator its insertion returned, and
// a multiset never refuses an insertion), and the result is caught by the consistency checks
// here and in the face walk, which send the polygon to the fan fallback.
class MonotonePartition {
public:
  explicit MonotonePartition(const std::vector<Point2>& points)
      : points_(points), n_(static_cast<std::uint32_t>(points.size())), order_{&points},
        status_(EdgeLess{this}), whereInStatus_(n_), inStatus_(n_, false), helper_(n_), type_(n_) {}

  // The diagonals, or nothing when the sweep found the polygon inconsistent (not simple).
  bool run(std::vector<std::pair<std::uint32_t, std::uint32_t>>& diagonals) {
    std::vector<std::uint32_t> events(n_);
    std::iota(events.begin(), events.end(), 0u);
    std::sort(events.begin(), events.end(), [&](std::uint32_t a, std::uint32_t b) { return order_.above(a, b); });
    for (std::uint32_t v : events) {
      sweepVertex_ = v;
      type_[v] = classify(v);
      handle(v);
      if (!consistent_) return false;
    }
    diagonals = std::move(diagonals_);
    return true;
  }

private:
  enum class VertexType : std::uint8_t { kStart, kSplit, kEnd, kMerge, kRegularLeft, kRegularRight };
  static constexpr std::uint32_t kProbe = std::numeric_limits<std::uint32_t>::max();

  // Orders status edges by x where they cross the horizontal line through the current vertex;
  // kProbe stands for that vertex itself.
  struct EdgeLess {
    const MonotonePartition* self;
    bool operator()(std::uint32_t a, std::uint32_t b) const { return self->edgeLess(a, b); }
  };

  std::uint32_t next(std::uint32_t i) const { return i + 1 == n_ ? 0 : i + 1; }
  std::uint32_t prev(std::uint32_t i) const { return i == 0 ? n_ - 1 : i - 1; }

  VertexType classify(std::uint32_t v) const {
    const bool prevBelow = order_.above(v, prev(v)), nextBelow = order_.above(v, next(v));
    const bool convex = orient(points_[prev(v)], points_[v], points_[next(v)]) >= 0.0;
    if (prevBelow && nextBelow) return convex ? VertexType::kStart : VertexType::kSplit;
    if (!prevBelow && !nextBelow) return convex ? VertexType::kEnd : VertexType::kMerge;
    // Counter-clockwise, the boundary runs down the left side: interior to the right.
    return prevBelow ? VertexType::kRegularRight : VertexType::kRegularLeft;
  }

  double xOnSweepLine(std::uint32_t edge) const {
    const Point2& sweep = points_[sweepVertex_];
    if (edge == kProbe) return sweep.x;
    const Point2& a = points_[edge];
    const Point2& b = points_[next(edge)];
    if (a.y == b.y) return b.x;  // horizontal: leaves the status when the sweep reaches b
    const double t = std::clamp((sweep.y - a.y) / (b.y - a.y), 0.0, 1.0);
    return a.x + t * (b.x - a.x);
  }

  bool edgeLess(std::uint32_t a, std::uint32_t b) const {
    if (a == b) return false;
    const double xa = xOnSweepLine(a), xb = xOnSweepLine(b);
    if (xa != xb) return xa < xb;
    // A vertex on an edge counts as right of it, so "the edge directly left" finds the edge.
    if (a == kProbe || b == kProbe) return b == kProbe;
    // Edges meeting on the sweep line: the one heading further left below it comes first.
    const Point2 da{points_[next(a)].x - points_[a].x, points_[next(a)].y - points_[a].y};
    const Point2 db{points_[next(b)].x - points_[b].x, points_[next(b)].y - points_[b].y};
    const double cross = da.x * db.y - da.y * db.x;
    if (cross != 0.0) return cross > 0.0;
    return a < b;
  }

  void insertEdge(std::uint32_t edge, std::uint32_t helper) {
    whereInStatus_[edge] = status_.insert(edge);
    inStatus_[edge] = true;
    helper_[edge] = helper;
  }

  void eraseEdge(std::uint32_t edge) {
    if (!inStatus_[edge]) {
      consistent_ = false;
      return;
    }
    status_.erase(whereInStatus_[edge]);
    inStatus_[edge] = false;
  }

  // The status edge directly left of vertex v (the sweep vertex), if any.
  bool edgeLeftOf(std::uint32_t& edge) {
    auto it = status_.upper_bound(kProbe);
    if (it == status_.begin()) {
      consistent_ = false;
      return false;
    }
    edge = *std::prev(it);
    return true;
  }

  void addDiagonal(std::uint32_t a, std::uint32_t b) {
    if (a == b || next(a) == b || prev(a) == b) {
      consistent_ = false;  // a "diagonal" along the boundary: the sweep order is broken
      return;
    }
    diagonals_.emplace_back(a, b);
  }

  void connectIfHelperIsMerge(std::uint32_t v, std::uint32_t edge) {
    if (type_[helper_[edge]] == VertexType::kMerge) addDiagonal(v, helper_[edge]);
  }

  void handle(std::uint32_t v) {
    std::uint32_t left = 0;
    switch (type_[v]) {
      case VertexType::kStart:
        insertEdge(v, v);
        break;
      case VertexType::kEnd:
        if (!inStatus_[prev(v)]) { consistent_ = false; return; }
        connectIfHelperIsMerge(v, prev(v));
        eraseEdge(prev(v));
        break;
      case VertexType::kSplit:
        if (!edgeLeftOf(left)) return;
        addDiagonal(v, helper_[left]);
        helper_[left] = v;
        insertEdge(v, v);
        break;
      case VertexType::kMerge:
        if (!inStatus_[prev(v)]) { consistent_ = false; return; }
        connectIfHelperIsMerge(v, prev(v));
        eraseEdge(prev(v));
        if (!edgeLeftOf(left)) return;
        connectIfHelperIsMerge(v, left);
        helper_[left] = v;
        break;
      case VertexType::kRegularLeft:
        if (!inStatus_[prev(v)]) { consistent_ = false; return; }
        connectIfHelperIsMerge(v, prev(v));
        eraseEdge(prev(v));
        insertEdge(v, v);
        break;
      case VertexType::kRegularRight:
        if (!edgeLeftOf(left)) return;
        connectIfHelperIsMerge(v, left);
        helper_[left] = v;
        break;
    }
  }

  const std::vector<Point2>& points_;
  std::uint32_t n_;
  SweepOrder order_;
  std::uint32_t sweepVertex_ = 0;
  std::multiset<std::uint32_t, EdgeLess> status_;
  std::vector<std::multiset<std::uint32_t, EdgeLess>::iterator> whereInStatus_;
  std::vector<bool> inStatus_;
  std::vector<std::uint32_t> helper_;
  std::vector<VertexType> type_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> diagonals_;
  bool consistent_ = true;
};

// The faces of the polygon cut by the diagonals, each as its corners in counter-clockwise
// order. Every vertex has at most a handful of diagonals (de Berg: each adds at most two at a
// merge vertex and takes at most two as a helper), so the neighbour lists are short.
// Empty when the diagonals do not cut the polygon into proper faces.
std::vector<std::vector<std::uint32_t>> facesCutByDiagonals(
    const std::vector<Point2>& points, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& diagonals) {
  const auto n = static_cast<std::uint32_t>(points.size());
  // Neighbours of each vertex, in flat arrays: boundary neighbours then diagonal ends.
  std::vector<std::uint32_t> degree(n, 2);
  for (const auto& [a, b] : diagonals) ++degree[a], ++degree[b];
  std::vector<std::uint32_t> first(n + 1, 0);
  for (std::uint32_t v = 0; v < n; ++v) first[v + 1] = first[v] + degree[v];
  std::vector<std::uint32_t> neighbour(first[n]);
  std::vector<std::uint32_t> filled(n, 0);
  auto link = [&](std::uint32_t from, std::uint32_t to) { neighbour[first[from] + filled[from]++] = to; };
  for (std::uint32_t v = 0; v < n; ++v) link(v, (v + 1) % n), link(v, (v + n - 1) % n);
  for (const auto& [a, b] : diagonals) link(a, b), link(b, a);
  // Counter-clockwise by angle around each vertex with diagonals.
  for (std::uint32_t v = 0; v < n; ++v) {
    if (degree[v] == 2) continue;
    auto angle = [&](std::uint32_t w) { return std::atan2(points[w].y - points[v].y, points[w].x - points[v].x); };
    std::sort(neighbour.begin() + first[v], neighbour.begin() + first[v + 1],
              [&](std::uint32_t a, std::uint32_t b) { return angle(a) < angle(b); });
  }
  // A half-edge is a slot of the neighbour arrays. The outside of the polygon is to the left
  // of the reversed boundary edges (v -> v-1): mark those used, so no face walks them.
  std::vector<bool> used(neighbour.size(), false);
  auto slotOf = [&](std::uint32_t from, std::uint32_t to) {
    for (std::uint32_t s = first[from]; s < first[from + 1]; ++s)
      if (neighbour[s] == to) return s;
    return first[from + 1];  // not found
  };
  for (std::uint32_t v = 0; v < n; ++v) used[slotOf(v, (v + n - 1) % n)] = true;

  std::vector<std::vector<std::uint32_t>> faces;
  std::size_t cornersInFaces = 0;
  for (std::uint32_t start = 0; start < n; ++start) {
    for (std::uint32_t s = first[start]; s < first[start + 1]; ++s) {
      if (used[s]) continue;
      std::vector<std::uint32_t> face;
      std::uint32_t from = start, slot = s;
      do {
        if (used[slot]) return {};  // ran into another face's edge (or the outside)
        used[slot] = true;
        face.push_back(from);
        const std::uint32_t to = neighbour[slot];
        // Keep the face on the left: at `to`, turn to the neighbour just clockwise of `from`.
        const std::uint32_t back = slotOf(to, from);
        if (back == first[to + 1]) return {};
        slot = back == first[to] ? first[to + 1] - 1 : back - 1;
        from = to;
      } while (slot != s);
      if (face.size() < 3) return {};
      cornersInFaces += face.size();
      faces.push_back(std::move(face));
    }
  }
  // Euler: d diagonals cut the polygon into d + 1 faces holding n + 2d corners in all.
  if (faces.size() != diagonals.size() + 1 || cornersInFaces != n + 2 * diagonals.size()) return {};
  return faces;
}

// Triangulates a y-monotone face (corners counter-clockwise) by the stack walk down its two
// chains (de Berg et al., ch. 3.3): the stack holds a reflex chain; a vertex on the other chain
// sees all of it, a vertex on the same chain cuts off the corners it sees. False when the face
// is not monotone after all (then nothing is appended).
bool triangulateMonotoneFace(const std::vector<Point2>& points, const SweepOrder& order, const TurnTest& turns,
                             const std::vector<std::uint32_t>& face, std::vector<Triangle>& out) {
  const std::size_t k = face.size();
  std::size_t top = 0, bottom = 0;
  for (std::size_t i = 1; i < k; ++i) {
    if (order.above(face[i], face[top])) top = i;
    if (order.above(face[bottom], face[i])) bottom = i;
  }
  // Counter-clockwise from the top, the boundary runs down the left chain to the bottom, then
  // up the right chain. Merge the two into one top-to-bottom sequence, checking monotonicity.
  std::vector<std::uint32_t> left, right;
  for (std::size_t i = top; i != bottom; i = (i + 1) % k) left.push_back(face[i]);
  for (std::size_t i = (top + k - 1) % k; i != bottom; i = (i + k - 1) % k) right.push_back(face[i]);
  auto descending = [&](const std::vector<std::uint32_t>& chain) {
    for (std::size_t i = 1; i < chain.size(); ++i)
      if (!order.above(chain[i - 1], chain[i])) return false;
    return true;
  };
  if (!descending(left) || !descending(right)) return false;
  struct Entry {
    std::uint32_t vertex;
    bool onLeft;
  };
  std::vector<Entry> sequence;
  sequence.reserve(k);
  std::size_t l = 0, r = 0;
  while (l < left.size() || r < right.size()) {
    const bool takeLeft = r == right.size() || (l < left.size() && order.above(left[l], right[r]));
    sequence.push_back(takeLeft ? Entry{left[l++], true} : Entry{right[r++], false});
  }
  sequence.push_back({face[bottom], true});

  const std::size_t before = out.size();
  // (upper, lower) consecutive on the stack plus the current vertex, counter-clockwise: down the
  // left chain, or up the right chain, according to the side the stack's reflex chain is on.
  auto triangle = [](std::uint32_t upper, std::uint32_t lower, std::uint32_t current, bool stackOnLeft) {
    return stackOnLeft ? Triangle{upper, lower, current} : Triangle{lower, upper, current};
  };
  auto isLeftTurn = [&](const Triangle& t) { return turns.isLeftTurn(points[t[0]], points[t[1]], points[t[2]]); };
  std::vector<Entry> stack{sequence[0], sequence[1]};
  for (std::size_t j = 2; j + 1 < sequence.size(); ++j) {
    const Entry current = sequence[j];
    if (current.onLeft != stack.back().onLeft) {
      // Opposite chain: every stacked vertex is visible; fan to all of them.
      const bool stackOnLeft = stack.back().onLeft;
      for (std::size_t q = 0; q + 1 < stack.size(); ++q)
        out.push_back(triangle(stack[q].vertex, stack[q + 1].vertex, current.vertex, stackOnLeft));
      const Entry previous = stack.back();
      stack = {previous, current};
    } else {
      // Same chain: cut off stacked corners while they are convex seen from the current vertex.
      Entry popped = stack.back();
      stack.pop_back();
      while (!stack.empty()) {
        const Triangle t = triangle(stack.back().vertex, popped.vertex, current.vertex, current.onLeft);
        if (!isLeftTurn(t)) break;
        out.push_back(t);
        popped = stack.back();
        stack.pop_back();
      }
      stack.push_back(popped);
      stack.push_back(current);
    }
  }
  const bool stackOnLeft = stack.back().onLeft;
  for (std::size_t q = 0; q + 1 < stack.size(); ++q)
    out.push_back(triangle(stack[q].vertex, stack[q + 1].vertex, sequence.back().vertex, stackOnLeft));
  if (out.size() - before != k - 2) {
    out.resize(before);
    return false;
  }
  return true;
}

bool triangulateByMonotonePieces(const std::vector<Point2>& points, std::vector<Triangle>& out) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> diagonals;
  if (!MonotonePartition(points).run(diagonals)) return false;
  const std::vector<std::vector<std::uint32_t>> faces = facesCutByDiagonals(points, diagonals);
  if (faces.empty()) return false;
  const SweepOrder order{&points};
  const TurnTest turns = turnTestFor(points);
  const std::size_t before = out.size();
  for (const std::vector<std::uint32_t>& face : faces) {
    if (!triangulateMonotoneFace(points, order, turns, face, out)) {
      out.resize(before);
      return false;
    }
  }
  return true;
}

}  // namespace

PolygonCut triangulatePolygon(std::span<const Vec3> corners, std::vector<Triangle>& out) {
  const auto n = static_cast<std::uint32_t>(corners.size());
  if (n < 3) return PolygonCut::kFanFallback;
  if (n == 3) {
    out.push_back({0, 1, 2});
    return PolygonCut::kTriangle;
  }
  const std::vector<Point2> points = projectOntoPlane(corners, newellNormal(corners));
  if (!points.empty()) {
    if (isStrictlyConvex(points, SweepOrder{&points}, turnTestFor(points))) {
      appendFan(n, out);
      return PolygonCut::kConvexFan;
    }
    if (triangulateByMonotonePieces(points, out)) return PolygonCut::kMonotone;
  }
  appendFan(n, out);
  return PolygonCut::kFanFallback;
}

PolygonCut appendFaceTriangles(const std::vector<Vec3>& vertices, std::span<const std::uint32_t> corners,
                               std::vector<Triangle>& triangles) {
  if (corners.size() == 3) {
    triangles.push_back({corners[0], corners[1], corners[2]});
    return PolygonCut::kTriangle;
  }
  std::vector<Vec3> positions;
  positions.reserve(corners.size());
  for (std::uint32_t c : corners) positions.push_back(vertices[c]);
  const std::size_t first = triangles.size();
  const PolygonCut cut = triangulatePolygon(positions, triangles);
  for (std::size_t t = first; t < triangles.size(); ++t)
    for (std::uint32_t& c : triangles[t]) c = corners[c];
  return cut;
}

}  // namespace clod::detail
