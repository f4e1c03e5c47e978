// Geodesic scheme: a frequency-f subdivided icosahedron projected onto the sphere, its covering
// radius and the paper's octant ("quadrant of the hemisphere") retrieval. The default O(1)
// retrieval is the cube-map candidate grid of sampling_grid.cpp.
//
// The octant lists are exact supersets: every direction u lies in some spherical triangle of the
// subdivision and is within that triangle's circumradius of one of its corners, so its nearest
// sample is within R (the largest circumradius, "covering radius") of u, and hence within R of
// u's octant.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "clod/error.h"
#include "clod/sphere_sampling.h"

namespace clod {
namespace {

// Extra angle (radians) added to every candidate-list bound. acos near 1 turns a 1e-16 error in
// a dot product into ~1e-8 in the angle; 1e-7 keeps the lists supersets at negligible cost.
constexpr double kAngleSlack = 1e-7;

double angleBetween(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)); }

struct Icosahedron {
  std::array<Vec3, 12> vertices;
  std::vector<std::array<int, 3>> faces;  // 20, counter-clockwise seen from outside
  std::vector<std::array<int, 2>> edges;  // 30, first < second
};

Icosahedron makeIcosahedron() {
  // Vertices (0, +-1, +-g), (+-1, +-g, 0), (+-g, 0, +-1) with g the golden ratio; edge length 2.
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  Icosahedron ico;
  int v = 0;
  for (double a : {-1.0, 1.0}) {
    for (double b : {-g, g}) {
      ico.vertices[v++] = Vec3(0.0, a, b);
      ico.vertices[v++] = Vec3(a, b, 0.0);
      ico.vertices[v++] = Vec3(b, 0.0, a);
    }
  }
  // Faces and edges found from the edge length rather than typed in: no table to get wrong.
  auto adjacent = [&](int i, int j) { return std::abs((ico.vertices[i] - ico.vertices[j]).norm() - 2.0) < 1e-9; };
  for (int i = 0; i < 12; ++i) {
    for (int j = i + 1; j < 12; ++j) {
      if (!adjacent(i, j)) continue;
      ico.edges.push_back({i, j});
      for (int k = j + 1; k < 12; ++k) {
        if (!adjacent(i, k) || !adjacent(j, k)) continue;
        const Vec3 normal = (ico.vertices[j] - ico.vertices[i]).cross(ico.vertices[k] - ico.vertices[i]);
        if (normal.dot(ico.vertices[i]) > 0.0) {
          ico.faces.push_back({i, j, k});
        } else {
          ico.faces.push_back({i, k, j});
        }
      }
    }
  }
  for (Vec3& vertex : ico.vertices) vertex.normalize();
  CLOD_ASSERT(ico.faces.size() == 20 && ico.edges.size() == 30);
  return ico;
}

int octantOf(const Vec3& u) { return (u.x() < 0.0 ? 1 : 0) | (u.y() < 0.0 ? 2 : 0) | (u.z() < 0.0 ? 4 : 0); }

// Cosine of the angle from unit vector s to the closed octant `octant`: the octant is a convex
// cone and the closest unit direction in it is the normalised projection of s, which for an
// orthant is s with the wrong-signed components set to zero (Moreau decomposition).
double cosAngleToOctant(const Vec3& s, int octant) {
  Vec3 p = s;
  for (int axis = 0; axis < 3; ++axis) {
    const bool negative = (octant >> axis) & 1;
    if (negative ? p[axis] > 0.0 : p[axis] < 0.0) p[axis] = 0.0;
  }
  return p.norm();  // 0 when s lies in the opposite octant: at least 90 degrees away
}

}  // namespace

void SphereSampling::buildGeodesic() {
  const int f = resolution_;
  const Icosahedron ico = makeIcosahedron();
  for (const Vec3& vertex : ico.vertices) addSample(vertex);

  // Edge points: edge e, weight w (1..f-1) on its first (lower-id) vertex.
  std::array<std::array<int, 12>, 12> edgeId{};
  for (auto& row : edgeId) row.fill(-1);
  const auto edgeBase = size();
  for (std::size_t e = 0; e < ico.edges.size(); ++e) {
    const auto [a, b] = ico.edges[e];
    edgeId[a][b] = edgeId[b][a] = static_cast<int>(e);
    for (int w = 1; w < f; ++w) {
      addSample((w * ico.vertices[a] + (f - w) * ico.vertices[b]).normalized());
    }
  }
  // Face interior points, i, j, k >= 1 with i + j + k = f (weights on the face's corners).
  const auto faceBase = size();
  const auto interiorPerFace = static_cast<std::uint32_t>(f >= 3 ? (f - 1) * (f - 2) / 2 : 0);
  for (const auto& face : ico.faces) {
    for (int i = 1; i < f; ++i) {
      for (int j = 1; i + j < f; ++j) {
        const int k = f - i - j;
        addSample((i * ico.vertices[face[0]] + j * ico.vertices[face[1]] + k * ico.vertices[face[2]]).normalized());
      }
    }
  }

  // Global index of grid point (i, j, f - i - j) of face `faceIndex`, following the order above.
  auto gridIndex = [&](std::size_t faceIndex, int i, int j) -> std::uint32_t {
    const auto& face = ico.faces[faceIndex];
    const std::array<int, 3> weights = {i, j, f - i - j};
    int zeros = 0;
    for (int w : weights) zeros += (w == 0);
    if (zeros == 2) {
      for (int c = 0; c < 3; ++c) {
        if (weights[c] == f) return static_cast<std::uint32_t>(face[c]);
      }
    }
    if (zeros == 1) {
      int c0 = -1, c1 = -1;
      for (int c = 0; c < 3; ++c) {
        if (weights[c] == 0) continue;
        (c0 < 0 ? c0 : c1) = c;
      }
      int va = face[c0], vb = face[c1], wa = weights[c0];
      if (va > vb) {
        std::swap(va, vb);
        wa = f - wa;
      }
      return edgeBase + static_cast<std::uint32_t>(edgeId[va][vb] * (f - 1) + (wa - 1));
    }
    // Interior: rank of (i, j) in the loops above.
    std::uint32_t rank = 0;
    for (int ii = 1; ii < i; ++ii) rank += static_cast<std::uint32_t>(f - 1 - ii);
    rank += static_cast<std::uint32_t>(j - 1);
    return faceBase + static_cast<std::uint32_t>(faceIndex) * interiorPerFace + rank;
  };

  // Covering radius: the largest circumradius of the subdivision's spherical triangles.
  double covering = 0.0;
  auto addTriangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const Vec3 pa = direction(a), pb = direction(b), pc = direction(c);
    Vec3 centre = (pb - pa).cross(pc - pa).normalized();
    if (centre.dot(pa) < 0.0) centre = -centre;
    covering = std::max(covering, angleBetween(centre, pa));
  };
  for (std::size_t face = 0; face < ico.faces.size(); ++face) {
    for (int i = 0; i < f; ++i) {
      for (int j = 0; i + j < f; ++j) {
        addTriangle(gridIndex(face, i, j), gridIndex(face, i + 1, j), gridIndex(face, i, j + 1));
        if (i + j <= f - 2) {
          addTriangle(gridIndex(face, i + 1, j), gridIndex(face, i + 1, j + 1), gridIndex(face, i, j + 1));
        }
      }
    }
  }
  coveringRadius_ = covering + kAngleSlack;

  // Octant candidate lists (the paper's quadrant search): samples within R of the octant.
  const double cosCovering = std::cos(std::min(coveringRadius_, M_PI));
  octantStart_.assign(1, 0);
  for (int octant = 0; octant < 8; ++octant) {
    for (std::uint32_t s = 0; s < size(); ++s) {
      if (cosAngleToOctant(direction(s), octant) >= cosCovering) octantSamples_.push_back(s);
    }
    octantStart_.push_back(static_cast<std::uint32_t>(octantSamples_.size()));
  }

  buildCandidateGrid();
}

std::uint32_t SphereSampling::nearestQuadrantSearch(const Vec3& u) const noexcept {
  CLOD_ASSERT(scheme_ == SamplingScheme::kGeodesic);
  const int octant = octantOf(u);
  return nearestAmong(std::span(octantSamples_).subspan(octantStart_[octant], octantStart_[octant + 1] - octantStart_[octant]), u);
}

}  // namespace clod
