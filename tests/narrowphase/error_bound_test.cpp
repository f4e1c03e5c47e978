// What a contact's error bound promises (issue 18, point 3; docs/narrow-phase.md, "Error
// bounds"), measured against the meshes' exact signed distance (MeshDistance, an oracle that
// shares no code with the narrow phase):
//
//   For a contact (p, n, d, e) -- n from B toward A -- the penetration along the normal line
//   through p, D = t_A + t_B, lies within d +- e. t_A is how far p can move along -n before it
//   leaves A (negative: how far along +n it must move to enter A), t_B the same along +n for B:
//   for two faces pressed together D is their overlap along n at p, for a sample on one
//   surface the other body's depth along n there.
//
// The rate at which that holds is measured over random overlapping poses of primitives and the
// shared meshes, every model at three budgets. CLOD_ERROR_BOUND_POSES sets the poses per body
// pair (default 25, the ctest sample); CLOD_ERROR_BOUND_CSV writes one row per contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/query.h"
#include "narrowphase_test_support.h"

namespace clod {
namespace {

using test::settingsFor;

struct Shape {
  std::string name;
  std::unique_ptr<CollisionBody> body;
  std::unique_ptr<MeshDistance> distance;
};

Shape makeShape(const std::string& name, const TriangleMesh& mesh) {
  Shape s;
  s.name = name;
  s.body = std::make_unique<CollisionBody>(test::makeTestBody(mesh, test::curvedMeshTestDepth()));
  s.distance = std::make_unique<MeshDistance>(mesh);
  return s;
}

// How far p moves along dir (unit, world) before it leaves the body (>= 0 when p is inside),
// or minus how far it must move along -dir... i.e. the signed position of the boundary crossing
// along dir: inside, march forward to the exit; outside, march backward to the entry (returned
// negative). Steps of max(|phi|, hMin) (sphere tracing, which never steps over the boundary
// when |phi| > hMin) and bisection on the sign change, to 1e-10 of the diagonal. `limit`: the
// most distance searched.
double boundaryAlong(const MeshDistance& field, const Pose& xfWorldFromBody, const Vec3& p, const Vec3& dir, double hMin,
                     double limit) {
  auto phi = [&](double t) { return field.signedDistance(xfWorldFromBody.applyInverse(Vec3(p + t * dir))); };
  const double phi0 = phi(0.0);
  const double sign = phi0 <= 0.0 ? 1.0 : -1.0;  // inside: forward to the exit; outside: back to the entry
  double t = 0.0, f = phi0;
  while (std::abs(t) < limit) {
    const double step = std::max(std::abs(f), hMin);
    const double next = t + sign * step;
    const double fn = phi(next);
    if ((fn > 0.0) != (f > 0.0)) {
      double lo = t, hi = next;
      for (int i = 0; i < 60 && std::abs(hi - lo) > 1e-10 * limit; ++i) {
        const double mid = 0.5 * (lo + hi);
        if ((phi(mid) > 0.0) == (f > 0.0)) lo = mid; else hi = mid;
      }
      return 0.5 * (lo + hi);
    }
    t = next;
    f = fn;
  }
  return sign * limit;
}

// The penetration along the normal line through p (the header comment's D). A contact on the
// rim of a contact region (the corners of two faces' overlap) has its line in a side face of a
// body, where inside and outside are a matter of rounding: the line is also taken 1e-5 of the
// diagonals to either side along two tangents, and the largest of the five counts.
double penetrationAlongNormal(const Shape& a, const Pose& poseA, const Shape& b, const Pose& poseB, const Vec3& p,
                              const Vec3& n) {
  const double scale = a.body->diagonal() + b.body->diagonal();
  const double hMin = 1e-4 * scale;
  const Vec3 t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  const double delta = 1e-5 * scale;
  double best = -std::numeric_limits<double>::infinity();
  for (const Vec3& q : {p, Vec3(p + delta * t1), Vec3(p - delta * t1), Vec3(p + delta * t2), Vec3(p - delta * t2)}) {
    const double tA = boundaryAlong(*a.distance, poseA, q, -n, hMin, scale);  // exit of A going -n
    const double tB = boundaryAlong(*b.distance, poseB, q, n, hMin, scale);   // exit of B going +n
    best = std::max(best, tA + tB);
  }
  return best;
}

struct Tally {
  std::uint64_t contacts = 0;
  std::uint64_t held = 0;
  double worstExcess = 0.0;  // largest |D - d| - e, in units of the diagonal
};

TEST(ErrorBound, DepthWithinItsBoundOfThePenetrationAlongTheNormal) {
  // Under the sanitizers 2 poses per pair run every model's code path; the rates below are
  // statistics of 25 and more, asserted in Release only (tests/support/test_scale.h).
  const int poses = std::getenv("CLOD_ERROR_BOUND_POSES") ? std::atoi(std::getenv("CLOD_ERROR_BOUND_POSES"))
                                                          : (test::sanitizerRun() ? 2 : 25);
  std::vector<Shape> shapes;
  shapes.push_back(makeShape("box", makeBox(Vec3::Constant(0.5))));
  shapes.push_back(makeShape("sphere", makeIcosphere(0.5, 2)));
  shapes.push_back(makeShape("bunny-1500", test::loadUnitMesh("bunny-1500.obj")));
  shapes.push_back(makeShape("spot", test::loadUnitMesh("spot.obj")));
  // Each shape against itself, and the two meshes against the box: a mesh resting on or dropped
  // onto a box is the flat patch the exact model answers with its vertices inside (per point).
  struct PairCase {
    std::string name;
    const Shape* a;
    const Shape* b;
  };
  std::vector<PairCase> pairs;
  for (const Shape& shape : shapes) pairs.push_back({shape.name, &shape, &shape});
  pairs.push_back({"box/bunny-1500", &shapes[0], &shapes[2]});
  pairs.push_back({"box/spot", &shapes[0], &shapes[3]});
  std::unique_ptr<std::ofstream> csv;
  if (const char* path = std::getenv("CLOD_ERROR_BOUND_CSV")) {
    csv = std::make_unique<std::ofstream>(path);
    *csv << "shape,pose,model,budget,depth,error_bound,penetration_along_normal,held\n";
  }
  const std::vector<ContactModel> models = {ContactModel::kDos, ContactModel::kCfm, ContactModel::kContactTree,
                                            ContactModel::kExact};
  const std::vector<std::uint64_t> budgets = {16, 256, kUnlimitedTests};
  std::map<std::string, Tally> tallies;
  std::mt19937_64 rng(18);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  QueryScratch scratch;
  QueryResult result;
  for (const PairCase& pair : pairs) {
    const Shape& shapeA = *pair.a;
    const Shape& shapeB = *pair.b;
    const double diagonal = std::max(shapeA.body->diagonal(), shapeB.body->diagonal());
    for (int k = 0; k < poses; ++k) {
      // B turned at random and moved along a random direction to where the two touch (bisection
      // on the exact model), then 0.2-3 % of the diagonal deeper.
      const Pose turn = test::randomPose(rng, 0.0);
      const Vec3 dir = test::randomPose(rng, 1.0).translation.normalized();
      double lo = 0.0, hi = 2.0 * diagonal;
      QuerySettings exact = settingsFor(ContactModel::kExact, kUnlimitedTests);
      for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        queryContacts(*shapeA.body, Pose{}, *shapeB.body, Pose{turn.rotation, mid * dir}, exact, scratch, result);
        (result.colliding ? lo : hi) = mid;
      }
      const Pose poseB{turn.rotation, (lo - (0.002 + 0.028 * unit(rng)) * diagonal) * dir};
      for (ContactModel model : models) {
        for (std::uint64_t budget : budgets) {
          queryContacts(*shapeA.body, Pose{}, *shapeB.body, poseB, settingsFor(model, budget), scratch, result);
          const std::string key = pair.name + " " + std::string(contactModelName(model)) + " " +
                                  (budget == kUnlimitedTests ? std::string("unlimited") : std::to_string(budget));
          Tally& tally = tallies[key];
          for (const Contact& c : result.contacts) {
            // The promise is about penetrating contacts; a speculative one (depth <= 0, the
            // surfaces apart there) is left out: its line may pass beside the other body.
            if (!(c.depth > 0.0)) continue;
            const double along = penetrationAlongNormal(shapeA, Pose{}, shapeB, poseB, c.point, c.normal);
            // Slack: the side lines lie 1e-5 of the two diagonals off p, which on a face tilted
            // up to 80 degrees against n moves its crossing by up to 6 times that, 1.2e-4 of the
            // diagonal (the line search itself ends within 1e-10 of it).
            const double excess = std::abs(along - c.depth) - c.errorBound;
            const bool held = excess <= 1.2e-4 * diagonal;
            ++tally.contacts;
            tally.held += held;
            tally.worstExcess = std::max(tally.worstExcess, excess / diagonal);
            if (csv) {
              *csv << pair.name << ',' << k << ',' << contactModelName(model) << ','
                   << (budget == kUnlimitedTests ? 0 : budget) << ',' << c.depth << ',' << c.errorBound << ',' << along
                   << ',' << held << '\n';
            }
          }
        }
      }
    }
  }
  std::printf("%-32s %9s %9s %8s %12s\n", "shape model budget", "contacts", "held", "rate %", "worst excess");
  for (const auto& [key, t] : tallies) {
    std::printf("%-32s %9llu %9llu %8.2f %12.4g\n", key.c_str(), static_cast<unsigned long long>(t.contacts),
                static_cast<unsigned long long>(t.held), t.contacts ? 100.0 * double(t.held) / double(t.contacts) : 100.0,
                t.worstExcess);
  }
  // The promise is not held everywhere yet (docs/narrow-phase.md, "Error bounds"; 10,000 poses
  // in docs/benchmarks/narrowphase.md). Guarded against regressions where it mostly holds:
  // two boxes in cfm and exact at every budget (99.6 % of 2,257 contacts over 1,700 poses: the
  // separating-axis normal and the clipped faces' corners, error bound 0; the misses are clipped
  // corners just beyond a face's rim, whose lines pass beside a body) and the contact tree on the icosphere at full
  // budget (96.5 % of 19,949). 90 %: the 10,000-pose rates less the spread of a 25-pose sample.
  auto expectRate = [&](const std::string& key, double rate) {
    const Tally& t = tallies[key];
    EXPECT_GT(t.contacts, 0u) << key;
    if (test::sanitizerRun()) return;
    EXPECT_GE(double(t.held), rate * double(t.contacts)) << key << ": worst excess " << t.worstExcess << " of the diagonal";
  };
  for (const char* model : {"cfm", "exact"}) {
    for (const char* budget : {"16", "256", "unlimited"}) expectRate(std::string("box ") + model + " " + budget, 0.9);
  }
  expectRate("sphere contact-tree unlimited", 0.9);
  // The exact model's vertex contacts (convex polyhedra on a side: two icospheres, the box on
  // spot): 100.0 % of 8,387 and 96.2 % of 12,383 over 1,700 poses per pair.
  expectRate("sphere exact unlimited", 0.9);
  expectRate("box/spot exact unlimited", 0.9);
  // cfm's leaf patches of two icospheres: 75.4 % of 4,020 over 1,700 poses since a piece of a
  // convex body's surface may no longer take a normal that pushes it through itself (57.5 %
  // before; 54 % of this 25-pose sample, 72 % after). 65 %: the 1,700-pose rate less a 25-pose
  // sample's spread.
  expectRate("sphere cfm unlimited", 0.65);
}

}  // namespace
}  // namespace clod
