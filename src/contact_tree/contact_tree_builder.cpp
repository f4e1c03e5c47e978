#include "clod/contact_tree_builder.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "clod/error.h"
#include "clod/mesh_validation.h"
#include "clod/proximity.h"
#include "clod/solid_boundary.h"
#include "half_space_code.h"
#include "lattice.h"

namespace clod {
namespace {

using detail::childCornerLattice;
using detail::kLatticeSize;
using detail::kLatticeSlot;

constexpr double kSqrt3 = 1.7320508075688772;
// The interpolation error peaks between test points where the field has a kink (medial axis,
// sharp edges) or curvature varies: a 1-D kink at a quarter of the spacing already peaks 1.5x
// above the nearest samples. Measured errors are therefore inflated by this factor, both for
// the refinement test (measured <= eps / kGapFactor) and for the stored bound (kGapFactor *
// measured, capped by the rigorous half-diagonal). docs/contact-tree.md has the measurements.
constexpr double kGapFactor = 2.0;
// Spacing of the samples that find where a soup's solid boundary crosses a face (solid_boundary.h):
// a crossing that clips less than this off a face can be missed.
constexpr double kBoundarySampleSpacingRel = 1.0 / 64.0;

// A cell waiting to be processed: where it is, its corner values as stored (rounded to the
// value step q, ContactTree::valueStep) and as measured (float-rounded exact values: the
// half-space fit and the discontinuity test compare exact values with each other).
struct PendingCell {
  std::uint32_t index[3];
  std::array<float, 8> corners;
  std::array<float, 8> exactCorners;
};

// What processing one cell decided. Written by one TBB task, read by the serial linking pass.
struct CellResult {
  bool split = false;
  bool surface = false;
  bool measured = false;
  bool discontinuous = false;
  bool aboveError = false;
  bool far = false;
  float error = 0.0f;
  float bandError = 0.0f;
  std::uint32_t queries = 0;
  ContactHalfSpace halfSpace{};
  std::array<float, kLatticeSize> lattice{};       // rounded to q: the children's corners
  std::array<float, kLatticeSize> latticeExact{};  // as measured
};

void checkSettings(const ContactTreeSettings& s) {
  auto bad = [](const std::string& what) { throw Error(ErrorCode::kInvalidArgument, "contact tree settings: " + what); };
  // Stored values are integers of steps >= q 2^-24 (detail::latticeStep) that the codec keeps
  // below 2^46: with errorRel >= 1e-6 they stay below 1.2 diagonals / (2^-28 eps) < 2^39.
  if (!(std::isfinite(s.errorRel) && s.errorRel >= 1e-6))
    bad("errorRel " + std::to_string(s.errorRel) + " must be finite and >= 1e-6");
  if (s.maxDepth < 1 || s.maxDepth > 20) bad("maxDepth " + std::to_string(s.maxDepth) + " must be in 1..20");
  if (!(std::isfinite(s.bandRel) && s.bandRel >= 0.0))
    bad("bandRel " + std::to_string(s.bandRel) + " must be finite and >= 0");
  if (!(std::isfinite(s.cubeMarginRel) && s.cubeMarginRel > s.bandRel && s.cubeMarginRel <= 10.0))
    bad("cubeMarginRel " + std::to_string(s.cubeMarginRel) + " must be finite, > bandRel and <= 10");
  if (!(std::isfinite(s.discontinuityStopRel) && s.discontinuityStopRel >= 0.0))
    bad("discontinuityStopRel " + std::to_string(s.discontinuityStopRel) + " must be finite and >= 0");
}

// A shared lattice point of one level: its position on the level's half-cell lattice (packed)
// and who asked for it. Sorting by (key, cell) makes the lowest-numbered cell the owner that
// evaluates it, whatever the thread count.
struct LatticeRequest {
  std::uint64_t key;
  std::uint32_t cell;  // index into the chunk
  std::uint32_t lattice;
  bool operator<(const LatticeRequest& o) const { return key != o.key ? key < o.key : cell < o.cell; }
};
// Cells measured together; the frontier is in Morton order (children are appended in parent
// and octant order), so most neighbours share a chunk. Bounds the request buffer (~18 MB).
constexpr std::size_t kChunkCells = 1u << 16;

class Builder {
public:
  // `inferSigns`: the sign inference holds for a field continuous across space (a closed mesh's,
  // or a winding number's away from its membranes); a sheet's pseudonormal sign jumps across
  // the plane beyond its border, and a corner below it there "proved" points above the floor
  // inside (a box 0.669 above a two-triangle floor read -0.669).
  Builder(const MeshDistance& distance, const ContactTreeSettings& settings, bool inferSigns = true)
      : distance_(distance), settings_(settings), inferSigns_(inferSigns) {}

  ContactTree build(ContactTreeBuildStats* stats);

private:
  // True when the cell must be measured; otherwise fills r as a proven-far leaf.
  bool needsMeasuring(const PendingCell& cell, std::uint32_t depth, CellResult& r) const;
  // Sign of the exact distance at local position t (cell units) of `cell` when a corner value
  // proves it, else 0.
  int inferSign(const PendingCell& cell, std::uint32_t depth, const Vec3& t) const;
  // Exact signed distance at local position t (cell units) of `cell`, see the sign inference.
  MeshDistance::Signed exactQuery(const PendingCell& cell, std::uint32_t depth, const Vec3& t) const;
  // The rest of the refinement test, given the exact values at the cell's 18 shared lattice
  // points (exact[l] for lattice index l, corners and the centre excluded).
  void measureCell(const PendingCell& cell, std::uint32_t depth, double* exact, CellResult& r) const;
  // Measures frontier[begin, end) (the cells with results[i].measured): evaluates each distinct
  // shared lattice point once, then runs measureCell per cell. Returns the number of shared
  // lattice evaluations.
  std::uint64_t measureChunk(const std::vector<PendingCell>& frontier, std::size_t begin, std::size_t end,
                             std::uint32_t depth, std::vector<CellResult>& results);

  const MeshDistance& distance_;
  const ContactTreeSettings& settings_;
  bool inferSigns_;
  ContactTree tree_;
  std::vector<double> exactScratch_;
  std::vector<LatticeRequest> requests_;
  std::vector<std::size_t> groupStarts_;
};

bool Builder::needsMeasuring(const PendingCell& cell, std::uint32_t depth, CellResult& r) const {
  // Lipschitz: every point x of the cell is within half a diagonal of its nearest corner c, so
  // |d(x)| >= |d(c)| - diagonal/2 (ContactTree::provenFar, which also allows for the rounding
  // of the stored corners). If all corners exceed band + diagonal/2 (same sign), no point of
  // the cell is in the band and the surface does not cross it.
  if (tree_.provenFar(cell.corners, depth)) {
    // Rigorous for any 1-Lipschitz field: |d(x) - sum w_i d(c_i)| <= sum w_i |x - c_i| <=
    // sqrt(sum w_i |x - c_i|^2) = h sqrt(sum_axes t(1-t)) <= h sqrt(3)/2, plus q/2 for the
    // rounded corners (farErrorCode). The decoder derives all of it from the corners.
    r.far = true;
    return false;
  }
  r.measured = true;
  return true;
}

int Builder::inferSign(const PendingCell& cell, std::uint32_t depth, const Vec3& t) const {
  // The sign is the expensive part of an exact query for open meshes (a winding number), and
  // often it is already known: if a corner value v has |v| > |x - corner|, d(x) has v's sign,
  // since |d(x) - v| <= |x - corner|. Then only the unsigned distance is needed.
  if (!inferSigns_) return 0;
  const double h = tree_.cellSize(depth);
  for (int c = 0; c < 8; ++c) {
    const double reach = h * (t - Vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1)).norm();
    const double v = cell.exactCorners[c];
    if (std::abs(v) * (1.0 - 1e-6) > reach + 1e-9 * h) return v < 0.0 ? -1 : 1;
  }
  return 0;
}

MeshDistance::Signed Builder::exactQuery(const PendingCell& cell, std::uint32_t depth, const Vec3& t) const {
  const Vec3 p = tree_.origin + tree_.cellSize(depth) * (Vec3(cell.index[0], cell.index[1], cell.index[2]) + t);
  const int sign = inferSign(cell, depth, t);
  if (sign == 0) return distance_.signedQuery(p);
  const ClosestPoint closest = distance_.closestPoint(p);
  return {closest, sign * closest.distance};
}

std::uint64_t Builder::measureChunk(const std::vector<PendingCell>& frontier, std::size_t begin, std::size_t end,
                                    std::uint32_t depth, std::vector<CellResult>& results) {
  // A face centre is shared by 2 cells, an edge midpoint by 4: near the surface, where most
  // cells are measured, each distinct point is evaluated once instead of 19 times per cell,
  // roughly halving the exact queries (docs/contact-tree.md).
  const std::size_t count = end - begin;
  exactScratch_.resize(count * kLatticeSize);
  requests_.clear();
  // Lattice coordinates at depth + 1 are <= 2^21, so (2^21 + 1)^3 < 2^64 keys are unique.
  constexpr std::uint64_t kSpan = (std::uint64_t{1} << 21) + 1;
  for (std::size_t i = 0; i < count; ++i) {
    if (!results[begin + i].measured) continue;
    const PendingCell& cell = frontier[begin + i];
    for (int l = 0; l < kLatticeSize; ++l) {
      if (kLatticeSlot[l] < 0 || l == 13) continue;
      const std::uint64_t x = 2ull * cell.index[0] + l % 3, y = 2ull * cell.index[1] + (l / 3) % 3, z = 2ull * cell.index[2] + l / 9;
      requests_.push_back({x + kSpan * (y + kSpan * z), static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(l)});
    }
  }
  tbb::parallel_sort(requests_.begin(), requests_.end());
  groupStarts_.clear();
  for (std::size_t r = 0; r < requests_.size(); ++r)
    if (r == 0 || requests_[r].key != requests_[r - 1].key) groupStarts_.push_back(r);
  groupStarts_.push_back(requests_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groupStarts_.size() - 1, 64), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t g = range.begin(); g != range.end(); ++g) {
      // The unsigned distance is shared; the sign is inferred per requesting cell from its own
      // corners, exactly as if the cell had evaluated the point itself. (Inferring it once for
      // all would differ across the sign jump of an open mesh's winding-number membrane, where
      // the field is not 1-Lipschitz: neighbours would disagree about the jump's position.)
      // The winding-number sign is computed at most once per point.
      const LatticeRequest& owner = requests_[groupStarts_[g]];
      const PendingCell& ownerCell = frontier[begin + owner.cell];
      const int lo = static_cast<int>(owner.lattice);
      const Vec3 p = tree_.origin + tree_.cellSize(depth) * (Vec3(ownerCell.index[0], ownerCell.index[1], ownerCell.index[2]) +
                                                             0.5 * Vec3(lo % 3, (lo / 3) % 3, lo / 9));
      const double unsignedDistance = distance_.closestPoint(p).distance;
      double windingSigned = 0.0;
      bool haveWinding = false;
      for (std::size_t r = groupStarts_[g]; r < groupStarts_[g + 1]; ++r) {
        const int l = static_cast<int>(requests_[r].lattice);
        const int sign = inferSign(frontier[begin + requests_[r].cell], depth, 0.5 * Vec3(l % 3, (l / 3) % 3, l / 9));
        if (sign == 0 && !haveWinding) {
          windingSigned = distance_.signedQuery(p).signedDistance;
          haveWinding = true;
        }
        exactScratch_[std::size_t{requests_[r].cell} * kLatticeSize + requests_[r].lattice] =
            sign == 0 ? windingSigned : sign * unsignedDistance;
      }
    }
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 8), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i)
      if (results[begin + i].measured) measureCell(frontier[begin + i], depth, exactScratch_.data() + i * kLatticeSize, results[begin + i]);
  });
  return groupStarts_.size() - 1;
}

void Builder::measureCell(const PendingCell& cell, std::uint32_t depth, double* exact, CellResult& r) const {
  const double h = tree_.cellSize(depth);
  const double diagonal = kSqrt3 * h;
  const double band = tree_.bandAbs;
  const Vec3 cellMin = tree_.origin + h * Vec3(cell.index[0], cell.index[1], cell.index[2]);
  auto exactAt = [&](const Vec3& t) {
    ++r.queries;
    return exactQuery(cell, depth, t).signedDistance;
  };
  // Corners as measured (the stored, rounded corners only enter the interpolation below).
  for (int c = 0; c < 8; ++c) exact[detail::parentCornerLattice(c)] = cell.exactCorners[c];
  ++r.queries;
  const MeshDistance::Signed centre = exactQuery(cell, depth, Vec3::Constant(0.5));
  exact[13] = centre.signedDistance;
  // Interpolation error at the test points, overall and restricted to the band. A band point
  // is within 0.28 h of a test point (covering radius of this body-centred lattice), so a
  // test point counts for the band if |d| <= band + h/2.
  const double bandTest = band + 0.5 * h;
  double error = 0.0, bandError = 0.0;
  auto account = [&](const Vec3& t, double exactValue) {
    const double e = std::abs(interpolateTrilinear(cell.corners, t, nullptr) - exactValue);
    error = std::max(error, e);
    if (std::abs(exactValue) <= bandTest) bandError = std::max(bandError, e);
  };
  for (int l = 0; l < kLatticeSize; ++l)
    if (kLatticeSlot[l] >= 0) account(0.5 * Vec3(l % 3, (l / 3) % 3, l / 9), exact[l]);
  // The octant centres only matter when the lattice alone does not already demand a split
  // (they become the children's centres and are measured there anyway).
  if (!(kGapFactor * bandError > tree_.errorAbs && depth < settings_.maxDepth)) {
    for (int o = 0; o < 8; ++o) {
      const Vec3 t(0.25 + 0.5 * (o & 1), 0.25 + 0.5 * ((o >> 1) & 1), 0.25 + 0.5 * ((o >> 2) & 1));
      account(t, exactAt(t));
    }
  }

  // A distance is 1-Lipschitz; lattice neighbours (h/2 apart) differing by more reveal a sign
  // discontinuity (winding-number membrane over a hole, or a sign tie) that no refinement fixes.
  const double lipschitz = 0.5 * h * (1.0 + 1e-4) + 1e-6 * (std::abs(exact[13]) + diagonal);
  for (int l = 0; l < kLatticeSize && !r.discontinuous; ++l) {
    const int i = l % 3, j = (l / 3) % 3, k = l / 9;
    if (i < 2 && std::abs(exact[l] - exact[l + 1]) > lipschitz) r.discontinuous = true;
    if (j < 2 && std::abs(exact[l] - exact[l + 3]) > lipschitz) r.discontinuous = true;
    if (k < 2 && std::abs(exact[l] - exact[l + 9]) > lipschitz) r.discontinuous = true;
  }

  // Measured values cannot exceed the rigorous Lipschitz bound unless the field jumps.
  const double step = detail::latticeStep(tree_, depth);
  r.error = static_cast<float>(r.discontinuous ? kGapFactor * error : std::min(kGapFactor * error, 0.5 * (diagonal + step)));
  r.bandError = static_cast<float>(bandError);
  // Stored as the bake file stores them: prediction from the corners + a multiple of q.
  for (int l = 0; l < kLatticeSize; ++l) {
    r.latticeExact[l] = static_cast<float>(exact[l]);
    const double prediction = detail::latticePrediction(cell.corners, l);
    r.lattice[l] = detail::storedValue(prediction, detail::residualUnits(exact[l], prediction, step), step);
  }
  for (int c = 0; c < 8; ++c) r.lattice[detail::parentCornerLattice(c)] = cell.corners[c];

  // The surface crosses the cell iff some point of it has d = 0; every point is within half a
  // diagonal of the centre, so |d(centre)| <= diagonal/2 is necessary (and with a sign change
  // on the lattice, sufficient). Cells that pass get a half-space: the first-order Taylor plane
  // of d at the centre, d(x) ~ d(c) + grad d(c) . (x - c), whose gradient is the unit vector
  // from the closest point to the centre (outward), or the closest feature's normal when the
  // centre is on the surface. For a convex patch this plane supports the body.
  bool signChange = false;
  for (int l = 1; l < kLatticeSize; ++l) signChange = signChange || ((exact[l] < 0.0) != (exact[0] < 0.0));
  const double dc = centre.signedDistance;
  const bool canSplit = depth < settings_.maxDepth &&
                        (!r.discontinuous || diagonal > settings_.discontinuityStopRel * tree_.meshDiagonal);
  const bool overError = kGapFactor * bandError > tree_.errorAbs;
  r.split = overError && canSplit;
  r.aboveError = !r.split && overError && !r.discontinuous;

  if (std::abs(dc) <= 0.5 * diagonal * (1.0 + 1e-9) || signChange) {
    r.surface = true;
    Vec3 n = centre.closest.normal;
    const Vec3 toCentre = (cellMin + Vec3::Constant(0.5 * h)) - centre.closest.point;
    if (std::abs(dc) > 1e-9 * diagonal && toCentre.norm() > 0.0) n = toCentre / dc;
    if (!(n.norm() > 0.5)) n = Vec3::UnitZ();  // degenerate feature: any unit normal, fitError says how bad
    n.normalize();
    // Rounded as the bake file stores it (half_space_code.h): normal through its octahedral
    // code, offset = prediction + a multiple of step/1024. The fit is measured against the rounded
    // plane and rounded up, so it still bounds |plane - exact| at the lattice points.
    const std::array<std::int32_t, 2> oct = detail::encodeOctNormal(n.x(), n.y(), n.z());
    r.halfSpace.normal = detail::decodeOctNormal(oct[0], oct[1]);
    const double hsStep = detail::latticeStep(tree_, depth) / detail::kOffsetStepDivisor;
    const double prediction = detail::offsetPrediction(cell.corners, r.split, r.lattice[13]);
    r.halfSpace.offset = detail::storedValue(prediction, detail::residualUnits(-dc, prediction, hsStep), hsStep);
    const Vec3 nr(r.halfSpace.normal[0], r.halfSpace.normal[1], r.halfSpace.normal[2]);
    double fit = 0.0;
    for (int l = 0; l < kLatticeSize; ++l) {
      if (std::abs(exact[l]) > diagonal) continue;
      const Vec3 offset = 0.5 * h * Vec3((l % 3) - 1.0, ((l / 3) % 3) - 1.0, (l / 9) - 1.0);
      fit = std::max(fit, std::abs(nr.dot(offset) - double(r.halfSpace.offset) - exact[l]));
    }
    r.halfSpace.fitError = detail::fitErrorFromCode(ContactTree::encodeErrorRatio(fit / h, detail::kFitMantissaBits), h);
  }
}

ContactTree Builder::build(ContactTreeBuildStats* stats) {
  const Aabb box = distance_.mesh().bounds();
  const double diag = box.diagonal();
  tree_.meshDiagonal = diag;
  tree_.errorAbs = settings_.errorRel * diag;
  tree_.bandAbs = settings_.bandRel * diag;
  tree_.maxDepth = settings_.maxDepth;
  const double margin = settings_.cubeMarginRel * diag;
  tree_.rootSize = box.extent().maxCoeff() + 2.0 * margin;
  tree_.origin = box.center() - Vec3::Constant(0.5 * tree_.rootSize);

  ContactTreeBuildStats st;
  std::vector<PendingCell> frontier(1);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner = tree_.origin + tree_.rootSize * Vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const double d = distance_.signedDistance(corner);
    frontier[0].exactCorners[c] = static_cast<float>(d);
    frontier[0].corners[c] = static_cast<float>(d);
    ++st.distanceQueries;
  }
  tree_.rootCorners = frontier[0].corners;
  frontier[0].index[0] = frontier[0].index[1] = frontier[0].index[2] = 0;

  std::vector<CellResult> results;
  std::vector<PendingCell> next;
  std::vector<std::uint8_t> interior, surface;  // per node, packed into bitmaps at the end
  tree_.levelOffsets.push_back(0);
  for (std::uint32_t depth = 0; !frontier.empty(); ++depth) {
    results.assign(frontier.size(), CellResult{});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, frontier.size(), 256), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i) needsMeasuring(frontier[i], depth, results[i]);
    });
    for (std::size_t begin = 0; begin < frontier.size(); begin += kChunkCells)
      st.distanceQueries += measureChunk(frontier, begin, std::min(frontier.size(), begin + kChunkCells), depth, results);
    // Link serially in frontier order: children are appended in the same order as their
    // parents, which keeps the layout breadth-first and independent of scheduling.
    next.clear();
    for (std::size_t i = 0; i < frontier.size(); ++i) {
      const CellResult& r = results[i];
      st.distanceQueries += r.queries;
      st.measuredCells += r.measured;
      st.discontinuousCells += r.discontinuous;
      // Capped at the Lipschitz bound D/2 + q/2 (farErrorCode) except where the field jumps;
      // the cap also absorbs the float rounding of r.error, which could otherwise round the
      // code up. Codes are monotone in the ratio, so the cap applies to the codes.
      const std::uint16_t farCode = tree_.farErrorCode(depth);
      const std::uint16_t code =
          r.far ? farCode : ContactTree::encodeErrorRatio(double(r.error) / tree_.cellRadius(depth));
      tree_.errorCode.push_back(r.discontinuous ? code : std::min(code, farCode));
      surface.push_back(r.surface ? 1 : 0);
      if (r.surface) tree_.halfSpaces.push_back(r.halfSpace);
      interior.push_back(r.split ? 1 : 0);
      if (!r.split) {
        ++st.leaves;
        st.leavesAboveError += r.aboveError;
        if (r.measured && !r.discontinuous) st.maxBandLeafError = std::max(st.maxBandLeafError, double(r.bandError));
        continue;
      }
      const std::size_t firstChild = tree_.levelOffsets.back() + frontier.size() + next.size();
      if (firstChild + 8 > 0xfffffff0u) throw Error(ErrorCode::kUnsupportedMesh, "contact tree: more than 2^32 nodes; raise errorRel or lower maxDepth");
      if (settings_.maxNodes > 0 && firstChild + 8 > settings_.maxNodes) {
        throw Error(ErrorCode::kResourceLimit,
                    "contact tree: more than " + std::to_string(settings_.maxNodes) + " nodes at depth " +
                        std::to_string(depth + 1) +
                        " (ContactTreeSettings::maxNodes, from BakeSettings::maxMemoryBytes; clod bake "
                        "--max-memory-mb); raise it, or raise the error bound (--sdf-error) or lower the depth (--sdf-depth)");
      }
      for (int l = 0; l < kLatticeSize; ++l)
        if (kLatticeSlot[l] >= 0) tree_.lattice.push_back(r.lattice[l]);
      for (int o = 0; o < 8; ++o) {
        PendingCell child;
        for (int a = 0; a < 3; ++a) child.index[a] = 2 * frontier[i].index[a] + ((o >> a) & 1);
        for (int c = 0; c < 8; ++c) {
          child.corners[c] = r.lattice[childCornerLattice(o, c)];
          child.exactCorners[c] = r.latticeExact[childCornerLattice(o, c)];
        }
        next.push_back(child);
      }
    }
    tree_.levelOffsets.push_back(static_cast<std::uint32_t>(tree_.levelOffsets.back() + frontier.size()));
    frontier.swap(next);
  }
  tree_.assignNodeBits(interior, surface);
  st.nodes = tree_.nodeCount();
  st.surfaceCells = tree_.halfSpaces.size();
  if (stats) *stats = st;
  tree_.buildLookupGrid();
  tree_.deriveFlatSurfaces();
  return std::move(tree_);
}

// An open mesh that encloses nothing: a sheet (a floor quad, a terrain). Just behind its faces
// the winding number stays near 1/2 (the sheet's own half of the solid angle), where behind a
// closed mesh's faces, or one with holes (stanford-bunny), or an open box, it is near 1 (0.8 for
// the box: its missing face's share). Judged on up to 256 faces spread over the mesh, each
// probed 1e-4 of the diagonal behind its centroid: a sheet when fewer than 1 in 10 reach 3/4.
bool enclosesNothing(const MeshDistance& distance) {
  const TriangleMesh& mesh = distance.mesh();
  const std::uint32_t count = mesh.triangleCount();
  const std::uint32_t stride = std::max<std::uint32_t>(1, count / 256);
  const double behind = 1e-4 * mesh.bounds().diagonal();
  std::uint32_t probed = 0, enclosed = 0;
  for (std::uint32_t t = 0; t < count; t += stride) {
    const Vec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.norm() > 0.0)) continue;
    ++probed;
    if (distance.windingNumber((a + b + c) / 3.0 - behind * n.normalized()) >= 0.75) ++enclosed;
  }
  return probed > 0 && enclosed * 10 < probed;
}

}  // namespace

ContactTree buildContactTree(const MeshDistance& distance, const ContactTreeSettings& settings, ContactTreeBuildStats* stats) {
  checkSettings(settings);
  // A sheet's winding number never reaches 1/2 off it: signed by it, the field is a distance
  // without an inside, and a box sliding on a two-triangle floor sank through it. Signed by its
  // pseudonormals, behind the sheet is inside (docs/contact-tree.md, "Sheets").
  if (distance.signMethod() == SignMethod::kWindingNumber && enclosesNothing(distance)) {
    const MeshDistance sheet(distance.mesh(), MeshDistanceSettings{.sheetPseudonormals = true});
    if (sheet.signMethod() == SignMethod::kPseudonormal) {
      Builder builder(sheet, settings, /*inferSigns=*/false);
      return builder.build(stats);
    }
  }
  // A soup of overlapping parts has walls inside its solid: the field is the distance to the
  // solid's boundary (solid_boundary.h), and a wall's -|d| kink would be refined to the tree's
  // depth on both sides. One closed manifold part has no walls.
  if (distance.signMethod() == SignMethod::kWindingNumber || validateMesh(distance.mesh()).components > 1) {
    // Wall pieces are left within eps of the crossings, about what the field may be off by.
    const double diag = distance.mesh().bounds().diagonal();
    const double resolution = settings.errorRel * diag;
    const SolidBoundary boundary =
        solidBoundary(distance, resolution, std::max(resolution, kBoundarySampleSpacingRel * diag));
    if (boundary.changed() && !boundary.mesh.triangles.empty()) {
      const MeshDistance solid(boundary.mesh, MeshDistanceSettings{.forceWindingNumber = true});
      Builder builder(solid, settings);
      return builder.build(stats);
    }
  }
  Builder builder(distance, settings);
  return builder.build(stats);
}

}  // namespace clod
