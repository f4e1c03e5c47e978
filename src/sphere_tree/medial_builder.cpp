#include "medial_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <tbb/parallel_for.h>

#include "medial_axis.h"
#include "medial_reduction.h"
#include "top_down_build.h"

namespace clod::detail {
namespace {

// How far a piece's clustering point moves from the surface towards its inner pole
// (0 = surface point, 1 = pole), by the level being split. Near the root, pulling far groups
// whole limbs and both sides of thin parts into one sphere; deeper down the poles are far
// compared to the nodes, and a small pull keeps clusters compact on the surface. Chosen by
// measuring the fit on the shared closed meshes (docs/benchmarks/sphere_tree.md).
double polePull(std::uint32_t level) {
  constexpr double kPull[] = {0.5, 0.25, 0.15};
  return kPull[std::min<std::uint32_t>(level, 2)];
}
// Pieces larger than this fraction of their node's diagonal are split before clustering.
constexpr double kMaxPieceFraction = 0.2;
constexpr int kLloydIterations = 12;
constexpr int kFitDirections = 32;
constexpr int kScoreDirections = 128;
constexpr std::uint32_t kClusteringRestarts = 4;

struct Context {
  const TriangleMesh* mesh = nullptr;
  SurfaceSamples samples;
  std::unique_ptr<SampleGrid> grid;
  std::unique_ptr<VertexTriangles> adjacency;
  MedialReduction reduction = MedialReduction::kBest;
  std::vector<Vec3> directions;  // unit vectors for the fit estimate
  std::vector<Vec3> scoreDirections;  // denser, for comparing two splits of a node
  std::uint32_t branching = 8;
  std::uint32_t seed = 1;

  void setPoleOffset(SurfacePiece& piece) const {
    const Vec3 c = piece.centroid();
    if (samples.size() == 0) {
      piece.poleOffset = Vec3::Zero();
      piece.pole = 0;
      return;
    }
    const std::uint32_t s = grid->nearest(c);
    piece.poleOffset = samples.poleCenter[s] - samples.position[s];
    piece.pole = samples.poleId[s];
  }
};

std::vector<Vec3> fibonacciDirections(int count) {
  std::vector<Vec3> dirs;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    dirs.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return dirs;
}

// Splits pieces that are large relative to the node, and keeps splitting the largest ones while
// there are too few to make `branching` children from.
void refinePieces(const Context& ctx, std::vector<SurfacePiece>& pieces) {
  Aabb box;
  for (const SurfacePiece& p : pieces) box.extend(p.bounds());
  const double diag = box.diagonal();
  if (!(diag > 0.0)) return;
  auto splitOne = [&](const SurfacePiece& piece, std::vector<SurfacePiece>& out) -> bool {
    const Aabb pb = piece.bounds();
    int axis = 0;
    pb.extent().maxCoeff(&axis);
    const double mid = 0.5 * (pb.min[axis] + pb.max[axis]);
    SurfacePiece below = clipPiece(piece, axis, mid, true);
    SurfacePiece above = clipPiece(piece, axis, mid, false);
    const bool keepBelow = keepClippedPart(below, piece), keepAbove = keepClippedPart(above, piece);
    if (!keepBelow || !keepAbove) {
      out.push_back(piece);
      return false;
    }
    ctx.setPoleOffset(below);
    ctx.setPoleOffset(above);
    out.push_back(below);
    out.push_back(above);
    return true;
  };
  const double limit = kMaxPieceFraction * diag;
  for (int pass = 0; pass < 12; ++pass) {
    bool any = false;
    for (const SurfacePiece& p : pieces) any = any || p.bounds().diagonal() > limit;
    if (!any) break;
    std::vector<SurfacePiece> out;
    out.reserve(pieces.size() * 2);
    for (const SurfacePiece& p : pieces) {
      if (p.bounds().diagonal() > limit)
        splitOne(p, out);
      else
        out.push_back(p);
    }
    pieces.swap(out);
  }
  const std::size_t wanted = 2 * static_cast<std::size_t>(ctx.branching);
  for (int pass = 0; pass < 8 && pieces.size() < wanted; ++pass) {
    std::vector<SurfacePiece> out;
    bool changed = false;
    for (const SurfacePiece& p : pieces) {
      if (p.bounds().diagonal() > 1e-6 * diag)
        changed = splitOne(p, out) || changed;
      else
        out.push_back(p);
    }
    pieces.swap(out);
    if (!changed) break;
  }
}

// Weighted k-means (k-means++ seeding) of the pieces' clustering points. Returns a cluster id per
// piece; ids are in [0, k).
std::vector<std::uint32_t> clusterPieces(const std::vector<SurfacePiece>& pieces, const std::vector<Vec3>& feature,
                                         std::uint32_t k, std::uint32_t seed) {
  const std::size_t n = pieces.size();
  std::vector<std::uint32_t> label(n, 0);
  if (k <= 1) return label;
  std::mt19937 rng(seed);
  std::vector<double> weight(n);
  double minPositive = std::numeric_limits<double>::infinity();
  for (const SurfacePiece& p : pieces)
    if (p.area > 0.0) minPositive = std::min(minPositive, p.area);
  if (!std::isfinite(minPositive)) minPositive = 1.0;
  for (std::size_t i = 0; i < n; ++i) weight[i] = std::max(pieces[i].area, minPositive);

  std::vector<Vec3> centers;
  centers.push_back(feature[std::uniform_int_distribution<std::size_t>(0, n - 1)(rng)]);
  std::vector<double> d2(n, std::numeric_limits<double>::infinity());
  while (centers.size() < k) {
    double total = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], (feature[i] - centers.back()).squaredNorm());
      total += weight[i] * d2[i];
    }
    if (!(total > 0.0)) break;  // fewer distinct points than k
    double pick = std::uniform_real_distribution<double>(0.0, total)(rng);
    std::size_t chosen = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      pick -= weight[i] * d2[i];
      if (pick <= 0.0) {
        chosen = i;
        break;
      }
    }
    centers.push_back(feature[chosen]);
  }
  const std::size_t kk = centers.size();
  std::vector<Vec3> sum(kk);
  std::vector<double> mass(kk);
  for (int iteration = 0; iteration < kLloydIterations; ++iteration) {
    bool changed = iteration == 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t best = 0;
      double bestD = std::numeric_limits<double>::infinity();
      for (std::size_t c = 0; c < kk; ++c) {
        const double d = (feature[i] - centers[c]).squaredNorm();
        if (d < bestD) {
          bestD = d;
          best = static_cast<std::uint32_t>(c);
        }
      }
      changed = changed || label[i] != best;
      label[i] = best;
    }
    if (!changed) break;
    std::fill(sum.begin(), sum.end(), Vec3::Zero());
    std::fill(mass.begin(), mass.end(), 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      sum[label[i]] += weight[i] * feature[i];
      mass[label[i]] += weight[i];
    }
    for (std::size_t c = 0; c < kk; ++c) {
      if (mass[c] > 0.0) {
        centers[c] = sum[c] / mass[c];
        continue;
      }
      // An empty cluster restarts at the piece farthest from its own centre, so nodes keep
      // `branching` children whenever there are enough distinct pieces.
      std::size_t farthest = 0;
      double farthestD = -1.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double d = (feature[i] - centers[label[i]]).squaredNorm();
        if (d > farthestD) {
          farthestD = d;
          farthest = i;
        }
      }
      centers[c] = feature[farthest];
      label[farthest] = static_cast<std::uint32_t>(c);
      changed = true;
    }
  }
  return label;
}

// Score of a clustering: largest plus mean radius of the clusters' smallest enclosing spheres.
// The radius bounds a sphere's overshoot, so this steers the restarts towards a low worst fit
// without running the (costlier) fit estimate for every restart.
double clusteringScore(const std::vector<SurfacePiece>& pieces, const std::vector<std::uint32_t>& label,
                       std::uint32_t k, std::vector<Vec3>& scratch) {
  std::vector<std::vector<Vec3>> corners(k);
  for (std::size_t i = 0; i < pieces.size(); ++i)
    corners[label[i]].insert(corners[label[i]].end(), pieces[i].points().begin(), pieces[i].points().end());
  double largest = 0.0, sum = 0.0;
  std::uint32_t used = 0;
  for (const auto& points : corners) {
    if (points.empty()) continue;
    const double r = minimumEnclosingSphere(points, scratch).radius;
    largest = std::max(largest, r);
    sum += r;
    ++used;
  }
  return largest + (used > 0 ? sum / used : 0.0);
}

// Estimated fit of a sphere: the largest distance from points on its surface to the nearest of
// `surfacePoints` (points sampled on the surface the sphere must bound).
double estimateFit(const Sphere& sphere, const std::vector<Vec3>& directions, const std::vector<Vec3>& surfacePoints) {
  double worst = 0.0;
  for (const Vec3& d : directions) {
    const Vec3 q = sphere.center + sphere.radius * d;
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& p : surfacePoints) best = std::min(best, (p - q).squaredNorm());
    worst = std::max(worst, best);
    if (worst == std::numeric_limits<double>::infinity()) break;
  }
  return std::sqrt(worst);
}

Sphere chooseSphere(const Context& ctx, const std::vector<SurfacePiece>& pieces, std::vector<Vec3>& corners,
                    std::vector<Vec3>& scratch, std::vector<Vec3>& surfacePoints) {
  corners.clear();
  surfacePoints.clear();
  Vec3 medial = Vec3::Zero();
  double mass = 0.0;
  for (const SurfacePiece& p : pieces) {
    corners.insert(corners.end(), p.points().begin(), p.points().end());
    surfacePoints.insert(surfacePoints.end(), p.points().begin(), p.points().end());
    surfacePoints.push_back(p.centroid());
    const double w = std::max(p.area, 1e-300);
    medial += w * (p.centroid() + p.poleOffset);
    mass += w;
  }
  const Sphere smallest = minimumEnclosingSphere(corners, scratch);
  if (pieces.size() == 1) return smallest;
  medial /= mass;
  // Candidates on the segment from the smallest enclosing sphere's centre to the cluster's
  // medial centre, each expanded to cover the cluster; keep the one of lowest estimated fit.
  constexpr int kCandidates = 5;
  Sphere candidates[kCandidates];
  for (int i = 0; i < kCandidates; ++i) {
    const double t = static_cast<double>(i) / (kCandidates - 1);
    candidates[i].center = (1.0 - t) * smallest.center + t * medial;
    candidates[i].radius = i == 0 ? smallest.radius : farthestDistance(candidates[i].center, corners);
  }
  int best = 0;
  double bestFit = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kCandidates; ++i) {
    const double fit = estimateFit(candidates[i], ctx.directions, surfacePoints);
    if (fit < bestFit) {
      bestFit = fit;
      best = i;
    }
  }
  return candidates[best];
}

}  // namespace

SphereTree buildMedialSphereTree(const TriangleMesh& mesh, const SphereTreeSettings& settings) {
  Context ctx;
  ctx.mesh = &mesh;
  ctx.branching = settings.branching;
  const Aabb bounds = mesh.bounds();
  ctx.samples = sampleSurface(mesh, settings.medialSamples, 0x6d656469u);
  computeInnerPoles(ctx.samples, bounds);
  double area = 0.0;
  for (std::uint32_t t = 0; t < mesh.triangleCount(); ++t) area += mesh.triangleArea(t);
  const double spacing = std::sqrt(area / std::max<std::uint32_t>(1, ctx.samples.size()));
  ctx.grid = std::make_unique<SampleGrid>(ctx.samples.position, 2.0 * spacing);
  ctx.directions = fibonacciDirections(kFitDirections);
  ctx.scoreDirections = fibonacciDirections(kScoreDirections);
  ctx.reduction = settings.medialReduction;
  if (ctx.reduction != MedialReduction::kKMeans) ctx.adjacency = std::make_unique<VertexTriangles>(mesh);

  BuildNode root;
  root.pieces.resize(mesh.triangleCount());
  tbb::parallel_for(std::uint32_t{0}, mesh.triangleCount(), [&](std::uint32_t t) {
    root.pieces[t] = makeTrianglePiece(mesh, t);
    ctx.setPoleOffset(root.pieces[t]);
  });
  std::vector<Vec3> scratch;
  root.sphere = minimumEnclosingSphere(mesh.vertices, scratch);

  auto split = [&ctx](const BuildNode& parent, std::uint32_t level, std::uint32_t index,
                      std::vector<BuildNode>& children) {
    std::vector<SurfacePiece> pieces = parent.pieces;
    refinePieces(ctx, pieces);
    const std::uint32_t k = static_cast<std::uint32_t>(std::min<std::size_t>(ctx.branching, pieces.size()));
    auto kMeansLabels = [&] {
      std::vector<std::uint32_t> label;
      // k-means from a few seedings; keep the one whose clusters have the smallest spheres.
      std::vector<Vec3> feature(pieces.size());
      const double pull = polePull(level);
      for (std::size_t i = 0; i < pieces.size(); ++i) feature[i] = pieces[i].centroid() + pull * pieces[i].poleOffset;
      double bestScore = std::numeric_limits<double>::infinity();
      std::vector<Vec3> scoreScratch;
      for (std::uint32_t restart = 0; restart < kClusteringRestarts; ++restart) {
        std::vector<std::uint32_t> candidate =
            clusterPieces(pieces, feature, k, ctx.seed * 0x9e3779b9u + level * 7919u + index * 31u + restart);
        const double score = k > 1 ? clusteringScore(pieces, candidate, k, scoreScratch) : 0.0;
        if (score < bestScore) {
          bestScore = score;
          label = std::move(candidate);
        }
        if (k <= 1) break;
      }
      return label;
    };
    // Children from labels, each expanded to cover its pieces exactly ("expand"); returns the
    // estimated fit of the split: largest plus a quarter of the mean overshoot of the children,
    // at more directions than the centre choice uses (the worst sphere of a level decides
    // how early a query can trust it, and narrow overhangs hide between 32 directions).
    auto makeChildren = [&](const std::vector<std::uint32_t>& label, std::vector<BuildNode>& out) {
      std::uint32_t clusterCount = 0;
      for (std::uint32_t l : label) clusterCount = std::max(clusterCount, l + 1);
      std::vector<BuildNode> clusters(clusterCount);
      for (std::size_t i = 0; i < pieces.size(); ++i) clusters[label[i]].pieces.push_back(pieces[i]);
      std::vector<Vec3> corners, scratchPoints, surfacePoints;
      double largest = 0.0, sum = 0.0;
      for (BuildNode& cluster : clusters) {
        if (cluster.pieces.empty()) continue;
        cluster.sphere = chooseSphere(ctx, cluster.pieces, corners, scratchPoints, surfacePoints);
        const double fit = estimateFit(cluster.sphere, ctx.scoreDirections, surfacePoints);
        largest = std::max(largest, fit);
        sum += fit;
        out.push_back(std::move(cluster));
      }
      return largest + 0.25 * (out.empty() ? 0.0 : sum / static_cast<double>(out.size()));
    };
    switch (ctx.reduction) {
      case MedialReduction::kKMeans: makeChildren(kMeansLabels(), children); break;
      case MedialReduction::kMergeBurst:
        makeChildren(reduceByMergeAndBurst(*ctx.mesh, *ctx.adjacency, pieces, k), children);
        break;
      case MedialReduction::kBest: {
        std::vector<BuildNode> other;
        const double mergeBurstFit =
            makeChildren(reduceByMergeAndBurst(*ctx.mesh, *ctx.adjacency, pieces, k), children);
        const double kMeansFit = makeChildren(kMeansLabels(), other);
        if (kMeansFit < mergeBurstFit) children.swap(other);
        break;
      }
    }
  };
  return buildTopDown(mesh, std::move(root), settings.depth, settings.branching, split);
}

}  // namespace clod::detail
