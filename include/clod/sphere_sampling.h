#pragma once
// Sample points on the unit sphere and retrieval of the sample nearest to a direction.
//
// A closest feature map (Giang & O'Sullivan 2006, "Approximate collision response using closest
// feature maps", Computers & Graphics 30:423-431, section 4-5) stores one value per sample point
// on the surface of every sphere of a sphere-tree. At run time the contact point, seen from the
// sphere centre, is a direction; the value of the sample nearest to that direction is used.
// This header provides the sample sets ("schemes") and that nearest-sample retrieval.
//
// A SphereSampling is immutable, built once per (scheme, resolution) and shared by every sphere
// that uses it: it holds only unit directions and the tables its lookup needs, never per-sphere
// data. A CFM stores per sphere a flat array of values indexed by the sample index returned here.
//
// Conventions (all schemes):
//   * Directions are unit vectors in double precision. Polar angle phi in [0, pi] is measured
//     from +z, azimuth theta from +x towards +y:  (sin phi cos theta, sin phi sin theta, cos phi).
//   * "Nearest" means largest dot product with the query (smallest great-circle angle, smallest
//     chord). nearest() is exact: it returns a sample whose dot product with the query is within
//     1e-12 of the largest over all samples (ties between equidistant samples may go either way).
//   * No lookup allocates, locks or throws; lookups on one SphereSampling are thread-safe.
//
// See docs/sampling.md for the derivations, measured retrieval costs and Table 1/2 of the paper.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "clod/math.h"

namespace clod {

/// How sample points are placed on the sphere. Values are stable (bake files store them).
enum class SamplingScheme : std::uint8_t {
  /// Paper's "full polar": S rings at phi_i = i*pi/S, i = 0..S-1, each with S samples at equal
  /// theta steps theta_j = 2*pi*j/S. Ring 0 (the north pole) holds S coincident samples and there
  /// is no ring at the south pole, exactly as the paper's ListSize_phi x ListSize_theta arrays.
  /// S*S samples. Index = i*S + j.
  kPolar = 0,
  /// Paper's "adaptive polar": rings i = 0..S-1 at phi_i = i*pi/S with
  /// n_i = max(1, round(S*sin(phi_i))) samples at theta_ij = 2*pi*j/n_i (so ring 0 is one pole
  /// sample; no south-pole ring). 65 samples at S = 10, 3 at S = 2, 11 at S = 4 (Table 1).
  /// Index = ringOffset(i) + j, rings north to south.
  kAdaptivePolar = 1,
  /// Paper's geodesic scheme: vertices of an icosahedron whose edges are split into f equal parts
  /// (class-I subdivision of frequency f), projected onto the sphere: 10*f*f + 2 samples. Near-
  /// uniform, but no closed-form index. Index: the 12 icosahedron vertices first, then the other
  /// vertices in construction order (edge points, then face interior points). Retrieval through a
  /// cube-map grid of candidate lists (see nearest()).
  kGeodesic = 2,
  /// HEALPix (Gorski et al. 2005, ApJ 622:759, eqs. 4-9) pixel centres at N_side = N: 12*N*N
  /// samples on 4N-1 iso-latitude rings, every pixel the same area pi/(3 N^2) sr. Index = the
  /// RING ordering of HEALPix (rings north to south, theta increasing within a ring), which is
  /// what makes the O(1) ring lookup possible; NESTED ordering is not provided (yet).
  kHealpix = 3,
  /// Spherical Fibonacci point set (Keinert et al., "Spherical Fibonacci Mapping", ACM TOG 34(6)
  /// 2015, eq. 2): resolution = the number of samples n, any n >= 1 (so sample counts can match
  /// another scheme exactly). Sample i: z = 1 - (2i+1)/n, theta = 2 pi frac(i / golden ratio);
  /// index = i (north to south). Near-uniform (every sample owns an equal-area z band).
  /// Retrieval through the same cube-map candidate grid as geodesic (not Keinert's inverse map).
  kFibonacci = 4,
};

/// All schemes, in enum order.
std::span<const SamplingScheme> allSamplingSchemes() noexcept;

/// CLI / file name of a scheme: "polar", "adaptive-polar", "geodesic", "healpix", "fibonacci".
std::string_view samplingSchemeName(SamplingScheme scheme) noexcept;

/// Inverse of samplingSchemeName (exact, case-sensitive). Throws clod::Error(kInvalidArgument)
/// naming the string and listing the valid names.
SamplingScheme parseSamplingScheme(std::string_view name);

/// Largest accepted resolution per scheme (stacks for the polar schemes, subdivision frequency
/// for geodesic, N_side for HEALPix, sample count for Fibonacci): 1024, 1024, 64, 256, 16384.
/// Chosen so that a sampling stays below ~1.1 M samples and the candidate grids of geodesic and
/// Fibonacci build in well under a second.
int maxSamplingResolution(SamplingScheme scheme) noexcept;

/// Progressive refinement (paper section 5, Table 1): a sphere `level` levels below the root
/// uses rootStacks halved `level` times with integer division (10 -> 5 -> 2 -> 1,
/// 16 -> 8 -> 4 -> 2 -> 1), never less than 1 (one sample: a sphere that stores a single value).
/// Preconditions (CLOD_ASSERT): rootStacks >= 1, level >= 0.
int stacksAtLevel(int rootStacks, int level) noexcept;

/// Number of samples of `scheme` at `resolution`, without building it (closed form; O(S) for
/// adaptive polar). Throws clod::Error(kInvalidArgument) if resolution is outside
/// [1, maxSamplingResolution(scheme)].
std::uint32_t samplingSampleCount(SamplingScheme scheme, int resolution);

/// Maps a stack count to the resolution of `scheme` with a comparable number of samples, so that
/// "--stacks S" means something for every scheme:
///   polar, adaptive polar: S itself;
///   geodesic, HEALPix: the resolution >= 1 whose sample count is closest to the adaptive-polar
///   count at S (ties to the smaller), e.g. S = 10 (65 samples) -> geodesic f = 2 (42),
///   HEALPix N = 2 (48). So geodesic/HEALPix never have fewer than 12 samples;
///   Fibonacci: exactly the adaptive-polar count (65 at S = 10), at most its maximum resolution.
/// Throws clod::Error(kInvalidArgument) if stacks is outside [1, maxSamplingResolution(kPolar)].
int samplingResolutionForStacks(SamplingScheme scheme, int stacks);

/// An immutable set of unit directions plus the tables its nearest-sample lookup needs.
/// Memory: 24 bytes per sample (SoA doubles) + for ring schemes ~40 bytes per ring + for
/// geodesic and Fibonacci the lookup grid (about 4 cells per sample, 100-160 bytes per sample).
class SphereSampling {
public:
  /// Builds `scheme` at `resolution` (stacks S for the polar schemes, frequency f for geodesic,
  /// N_side for HEALPix, sample count for Fibonacci). Cost: O(samples) for ring schemes;
  /// O(samples^1.5) for the candidate grid of geodesic and Fibonacci (parallel with TBB), plus
  /// O(samples) octant lists for geodesic. Throws clod::Error(kInvalidArgument) if resolution
  /// is outside [1, maxSamplingResolution(scheme)].
  static SphereSampling build(SamplingScheme scheme, int resolution);

  /// build(scheme, samplingResolutionForStacks(scheme, stacks)).
  static SphereSampling buildForStacks(SamplingScheme scheme, int stacks);

  SamplingScheme scheme() const noexcept { return scheme_; }
  /// The resolution it was built with (stacks / frequency / N_side).
  int resolution() const noexcept { return resolution_; }
  /// Number of samples; indices are 0..size()-1.
  std::uint32_t size() const noexcept { return static_cast<std::uint32_t>(x_.size()); }
  /// Unit direction of sample `index` (CLOD_ASSERT index < size()).
  Vec3 direction(std::uint32_t index) const noexcept;
  /// The directions as structure-of-arrays, each of length size().
  std::span<const double> xs() const noexcept { return x_; }
  std::span<const double> ys() const noexcept { return y_; }
  std::span<const double> zs() const noexcept { return z_; }

  /// Index of the sample nearest to `unitDirection` (exact, see the file comment).
  /// Precondition: finite, |unitDirection| = 1 within 1e-6 (not checked in release builds).
  ///   Ring schemes (polar, adaptive polar, HEALPix): O(1). The ring nearest in phi comes from
  ///   a closed form; rings are then visited outwards from it, and in each ring the two samples
  ///   bracketing theta are tested, until a ring's best possible dot product
  ///   cos(phi - phi_ring) cannot beat the best found. This visits 2-4 rings in practice and is
  ///   exact, unlike rounding phi then theta (see nearestPaperFormula).
  ///   Geodesic, Fibonacci: O(1) via a cube map with about 4 cells per sample; each cell lists every sample
  ///   that is nearest to some direction in the cell (a superset, by the triangle inequality:
  ///   d(c, s) <= d_min(c) + 2 r_cell for cell centre c and cell radius r_cell); the list
  ///   (typically 4-8 samples) is scanned.
  std::uint32_t nearest(const Vec3& unitDirection) const noexcept;

  /// The paper's plain formula (its equations 4-5) for ring schemes: i = ring nearest in phi
  /// (round(phi*S/pi) for the polar schemes, the HEALPix closed form for HEALPix), then
  /// j = round(theta*n_i / 2pi) mod n_i within that ring. O(1), but near ring boundaries and
  /// the poles it may return a sample that is not the nearest; docs/sampling.md gives the miss
  /// rate and the largest angular excess. CLOD_ASSERT: a ring scheme.
  std::uint32_t nearestPaperFormula(const Vec3& unitDirection) const noexcept;

  /// The paper's geodesic retrieval: find the octant ("quadrant of the hemisphere") of the
  /// direction, then scan every sample that can be nearest to a direction in that octant (the
  /// samples within the covering radius of the octant). Exact. O(samples / 8 * ~1.3).
  /// CLOD_ASSERT: scheme() == kGeodesic.
  std::uint32_t nearestQuadrantSearch(const Vec3& unitDirection) const noexcept;

  /// Reference retrieval: argmax of the dot product over all samples (first index on exact
  /// ties). O(samples). Any scheme.
  std::uint32_t nearestLinearScan(const Vec3& unitDirection) const noexcept;

  /// Ring layout (ring schemes only; 0 for geodesic and Fibonacci): rings are ordered north to south, the
  /// samples of ring k are indices ringOffset(k) .. ringOffset(k) + ringSize(k) - 1 with
  /// theta_j = (j + ringThetaShift(k)) * 2pi / ringSize(k).
  std::uint32_t ringCount() const noexcept { return static_cast<std::uint32_t>(ringSize_.size()); }
  std::uint32_t ringOffset(std::uint32_t ring) const noexcept { return ringOffset_[ring]; }
  std::uint32_t ringSize(std::uint32_t ring) const noexcept { return ringSize_[ring]; }
  /// Polar angle of ring `ring` in radians.
  double ringPolarAngle(std::uint32_t ring) const noexcept { return ringPhi_[ring]; }
  /// Azimuthal offset of the ring's first sample, in units of the ring's theta step (0, 0.5 or 1).
  double ringThetaShift(std::uint32_t ring) const noexcept { return ringShift_[ring]; }

  /// Geodesic only (0 otherwise): an upper bound on the angle (radians) from any direction to its
  /// nearest sample: the largest circumradius of the spherical triangles of the subdivision.
  double coveringRadius() const noexcept { return coveringRadius_; }

  /// Bytes held by this object (directions and lookup tables).
  std::size_t memoryBytes() const noexcept;

private:
  SphereSampling() = default;
  void addSample(const Vec3& direction);
  void buildPolarRings(bool adaptive);      // sampling_rings.cpp
  void buildHealpixRings();                 // sampling_rings.cpp
  void buildGeodesic();                     // sampling_geodesic.cpp
  void buildFibonacci();                    // sampling_fibonacci.cpp
  void buildCandidateGrid();                // sampling_grid.cpp
  std::uint32_t nearestInRings(const Vec3& u) const noexcept;       // sampling_rings.cpp
  std::uint32_t closestRingByFormula(double z, double rho) const noexcept;
  std::uint32_t nearestInGrid(const Vec3& u) const noexcept;        // sampling_grid.cpp
  std::uint32_t gridCell(const Vec3& u) const noexcept;
  // The sample among `candidates` with the largest dot product with u (the nearest on the sphere).
  std::uint32_t nearestAmong(std::span<const std::uint32_t> candidates, const Vec3& u) const noexcept {
    std::uint32_t best = 0;
    double bestDot = -2.0;
    for (const std::uint32_t s : candidates) {
      const double d = x_[s] * u.x() + y_[s] * u.y() + z_[s] * u.z();
      if (d > bestDot) {
        bestDot = d;
        best = s;
      }
    }
    return best;
  }

  SamplingScheme scheme_ = SamplingScheme::kPolar;
  int resolution_ = 0;
  std::vector<double> x_, y_, z_;

  // Ring schemes.
  std::vector<std::uint32_t> ringOffset_, ringSize_;
  std::vector<double> ringPhi_, ringCosPhi_, ringSinPhi_, ringShift_;

  // Geodesic: octant candidate lists (paper retrieval) and the cube-map candidate grid.
  double coveringRadius_ = 0.0;
  std::vector<std::uint32_t> octantStart_, octantSamples_;  // 9 starts, CSR
  std::uint32_t gridSide_ = 0;                              // cells per cube-face edge (even)
  std::vector<std::uint32_t> cellStart_, cellSamples_;      // 6*side*side + 1 starts, CSR
};

}  // namespace clod
