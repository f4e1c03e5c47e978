// clod as MuJoCo's mesh collider: conventions, installation, budget (include/clod/mujoco/collider.h).
#include <gtest/gtest.h>

#if CLOD_HAVE_MUJOCO

#include <cmath>
#include <vector>

#include "clod/error.h"
#include "clod/primitives.h"
#include "mujoco_test_support.h"

namespace clod {
namespace {

using mujoco::Collider;
using mujoco::ColliderSettings;

// Two unit cubes as meshes: `lower` fixed at the origin, `upper` free at (x, 0, 0.99), turned by
// `yawDeg` about z: the upper cube's bottom face sinks 0.01 into the lower's top face.
std::string twoCubes(double x, double yawDeg, bool upperFirst) {
  const std::string lower = "<geom name=\"lower\" type=\"mesh\" mesh=\"cube\"/>";
  const std::string upper = "<body name=\"upper\" pos=\"" + std::to_string(x) + " 0 0.99\" euler=\"0 0 " +
                            std::to_string(yawDeg) + "\"><freejoint/><geom name=\"upper\" type=\"mesh\" mesh=\"cube\"/></body>";
  return "<mujoco><compiler angle=\"degree\"/><asset>" + test::inlineMesh("cube", makeBox(Vec3(0.5, 0.5, 0.5))) +
         "</asset><worldbody>" + (upperFirst ? upper + lower : lower + upper) + "</worldbody></mujoco>";
}

// The frame MuJoCo gets: rows orthonormal, right-handed, first row = the normal.
void expectFrame(const mjContact& c) {
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> f(c.frame);
  EXPECT_NEAR((f * f.transpose() - Mat3::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(f.determinant(), 1.0, 1e-12);
}

// One mj_forward of `m` with `collider` installed for it, uninstalled afterwards.
void forwardOnce(Collider& collider, const mjModel* m, mjData* d) {
  collider.addModel(m);
  collider.install();
  mj_forward(m, d);
  collider.uninstall();
}

TEST(MujocoCollider, CubeOnCubeFollowsMujocoConventions) {
  for (const bool upperFirst : {false, true}) {
    for (const double yaw : {0.0, 30.0}) {
      SCOPED_TRACE("upper first " + std::to_string(upperFirst) + ", yaw " + std::to_string(yaw));
      mujoco::ModelPtr m = test::loadXmlText(twoCubes(0.1, yaw, upperFirst), "cubes.xml");
      mujoco::DataPtr d(mj_makeData(m.get()));
      ColliderSettings settings;
      settings.model = ContactModel::kExact;
      Collider collider(settings);
      forwardOnce(collider, m.get(), d.get());
      ASSERT_GE(d->ncon, 3) << "a face-on-face contact needs a support polygon";
      const int upperGeom = mj_name2id(m.get(), mjOBJ_GEOM, "upper");
      for (int i = 0; i < d->ncon; ++i) {
        const mjContact& c = d->contact[i];
        expectFrame(c);
        // Analytic: the faces overlap 0.01 along z; the normal points from geom1 to geom2, so
        // up when geom1 is the lower cube. Exact model between two convex polyhedra: the
        // separating-axis depth and normal, exact up to rounding of the unit-size coordinates.
        const double up = c.geom1 == upperGeom ? -1.0 : 1.0;
        EXPECT_NEAR(c.frame[0], 0.0, 1e-9);
        EXPECT_NEAR(c.frame[1], 0.0, 1e-9);
        EXPECT_NEAR(c.frame[2], up, 1e-9);
        EXPECT_NEAR(c.dist, -0.01, 1e-9);
        // pos: midway between the two face planes (z 0.49 and 0.5), inside both faces' overlap.
        EXPECT_NEAR(c.pos[2], 0.495, 1e-9);
        EXPECT_LE(std::abs(c.pos[0]), 0.5 + 1e-9);
        EXPECT_LE(std::abs(c.pos[1]), 0.5 + 1e-9);
      }
      EXPECT_EQ(collider.lastStep(d.get()).pairs, 1u);
      EXPECT_EQ(collider.lastStep(d.get()).contacts, std::uint32_t(d->ncon));
    }
  }
}

// MuJoCo's geom margin: cubes 0.01 apart face to face count as a contact (dist > 0) when the
// margin is larger, through clod's speculative contact (QuerySettings::marginAbs). Analytic: one
// contact at dist 0.01, normal up from the lower cube (geom1) to the upper, pos midway.
TEST(MujocoCollider, GeomMarginGivesCubesApartOneContactAtTheirGap) {
  for (const double margin : {0.02, 0.005}) {
    SCOPED_TRACE("margin " + std::to_string(margin));
    const std::string m2 = "margin=\"" + std::to_string(margin) + "\" ";
    const std::string xml = "<mujoco><asset>" + test::inlineMesh("cube", makeBox(Vec3(0.5, 0.5, 0.5))) +
                            "</asset><worldbody><geom name=\"lower\" type=\"mesh\" mesh=\"cube\" " + m2 +
                            "/><body name=\"upper\" pos=\"0.1 0 1.01\"><freejoint/><geom name=\"upper\" type=\"mesh\" "
                            "mesh=\"cube\" " + m2 + "/></body></worldbody></mujoco>";
    mujoco::ModelPtr m = test::loadXmlText(xml, "cubes.xml");
    mujoco::DataPtr d(mj_makeData(m.get()));
    ColliderSettings settings;
    settings.model = ContactModel::kCfm;
    Collider collider(settings);
    forwardOnce(collider, m.get(), d.get());
    if (margin < 0.01) {
      EXPECT_EQ(d->ncon, 0);
      continue;
    }
    ASSERT_EQ(d->ncon, 1);
    const mjContact& c = d->contact[0];
    expectFrame(c);
    EXPECT_NEAR(c.dist, 0.01, 1e-9);
    EXPECT_NEAR(c.frame[2], 1.0, 1e-9);
    EXPECT_NEAR(c.pos[2], 0.505, 1e-9);
  }
}

TEST(MujocoCollider, UninstallRestoresMujocosOwnFunctions) {
  mjfCollision before[mjNGEOMTYPES][mjNGEOMTYPES];
  for (int i = 0; i < mjNGEOMTYPES; ++i)
    for (int j = 0; j < mjNGEOMTYPES; ++j) before[i][j] = mjCOLLISIONFUNC[i][j];
  {
    Collider a, b;
    a.install();
    EXPECT_TRUE(a.installed());
    EXPECT_NE(mjCOLLISIONFUNC[mjGEOM_MESH][mjGEOM_MESH], before[mjGEOM_MESH][mjGEOM_MESH]);
    EXPECT_EQ(mjCOLLISIONFUNC[mjGEOM_PLANE][mjGEOM_MESH], before[mjGEOM_PLANE][mjGEOM_MESH]);  // a half-space: MuJoCo's
    b.install();  // replaces a
    EXPECT_FALSE(a.installed());
    EXPECT_TRUE(b.installed());
    b.uninstall();
    for (int i = 0; i < mjNGEOMTYPES; ++i)
      for (int j = 0; j < mjNGEOMTYPES; ++j) EXPECT_EQ(mjCOLLISIONFUNC[i][j], before[i][j]) << i << "," << j;
    a.install();
  }  // a's destructor uninstalls
  for (int i = 0; i < mjNGEOMTYPES; ++i)
    for (int j = 0; j < mjNGEOMTYPES; ++j) EXPECT_EQ(mjCOLLISIONFUNC[i][j], before[i][j]) << i << "," << j;
}

TEST(MujocoCollider, ModelsNotAddedKeepMujocosCollider) {
  mujoco::ModelPtr m = test::loadXmlText(twoCubes(0.1, 0.0, false), "cubes.xml");
  mujoco::DataPtr d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());
  const int own = d->ncon;
  Collider collider;  // m not added
  collider.install();
  mj_forward(m.get(), d.get());
  EXPECT_EQ(d->ncon, own);
  EXPECT_EQ(collider.lastStep(d.get()).pairs, 0u);
}

TEST(MujocoCollider, BoxGeomAgainstMeshPointsFromGeom1ToGeom2) {
  // A primitive box (MuJoCo passes it as geom1: its type comes before mesh) sunk 0.02 into the
  // top of a mesh cube: the normal points from the box down into the cube.
  const std::string xml = "<mujoco><asset>" + test::inlineMesh("cube", makeBox(Vec3(0.5, 0.5, 0.5))) +
                          "</asset><worldbody><geom name=\"cube\" type=\"mesh\" mesh=\"cube\"/>"
                          "<body pos=\"0 0 0.58\"><freejoint/><geom name=\"box\" type=\"box\" size=\"0.2 0.2 0.1\"/></body>"
                          "</worldbody></mujoco>";
  mujoco::ModelPtr m = test::loadXmlText(xml, "box-mesh.xml");
  mujoco::DataPtr d(mj_makeData(m.get()));
  Collider collider;
  collider.addModel(m.get());
  collider.install();
  mj_forward(m.get(), d.get());
  ASSERT_GE(d->ncon, 3);
  const int box = mj_name2id(m.get(), mjOBJ_GEOM, "box");
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    expectFrame(c);
    const double down = c.geom1 == box ? -1.0 : 1.0;
    EXPECT_NEAR(c.frame[2], down, 1e-9);
    EXPECT_NEAR(c.dist, -0.02, 1e-9);  // box bottom at 0.48, cube top at 0.5
    EXPECT_NEAR(c.pos[2], 0.49, 1e-9);
  }
}

TEST(MujocoCollider, StepBudgetIsSharedAndNeverExceeded) {
  // Four cubes side by side on a mesh slab, four pairs per step.
  std::string bodies;
  for (int i = 0; i < 4; ++i)
    bodies += "<body pos=\"" + std::to_string(-1.5 + i) + " 0 0.59\"><freejoint/><geom type=\"mesh\" mesh=\"cube\"/></body>";
  const std::string xml = "<mujoco><asset>" + test::inlineMesh("cube", makeBox(Vec3(0.4, 0.4, 0.4))) +
                          test::inlineMesh("slab", makeBox(Vec3(3, 3, 0.2))) +
                          "</asset><worldbody><geom type=\"mesh\" mesh=\"slab\"/>" + bodies + "</worldbody></mujoco>";
  mujoco::ModelPtr m = test::loadXmlText(xml, "budget.xml");
  for (const std::uint64_t budget : {16u, 128u, 2048u}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    mujoco::DataPtr d(mj_makeData(m.get()));
    ColliderSettings settings;
    settings.model = ContactModel::kCfm;
    settings.budgetTests = budget;
    Collider collider(settings);
    collider.addModel(m.get());
    collider.install();
    std::uint32_t pairs = 0, queried = 0;
    for (int step = 0; step < 100; ++step) {
      mj_step(m.get(), d.get());
      const mujoco::StepStats s = collider.lastStep(d.get());
      EXPECT_LE(s.budgetSpent, budget);
      EXPECT_EQ(s.testsBudget, budget);
      pairs = s.pairs;
      queried += s.pairs - s.pairsSkipped;
    }
    const mujoco::StepStats total = collider.totals(d.get());
    EXPECT_GE(pairs, 4u);  // MuJoCo's broad phase: the four cube-slab pairs and neighbouring cubes
    EXPECT_GE(queried, 100u) << "every step queries some pair";
    EXPECT_GT(total.testsSpent, 0u);
    EXPECT_EQ(total.pairsFallback, 0u) << collider.lastError();
    // Whatever the budget, the cubes rest on the slab (top at 0.2; cube centres at 0.6).
    for (int b = 1; b <= 4; ++b) EXPECT_NEAR(test::bodyPosition(d.get(), b).z(), 0.6, 0.02);
  }
}

// An icosphere (r 0.5) per body, sunk `sink` into a mesh slab whose top is at z 0, the bodies
// 3 apart along x (so MuJoCo's broad phase pairs no two of them): one clod pair per sphere, each
// touching the slab on a small cap.
std::string spheresOnSlab(int spheres, double sink) {
  std::string bodies;
  for (int i = 0; i < spheres; ++i)
    bodies += "<body name=\"s" + std::to_string(i) + "\" pos=\"" + std::to_string(3.0 * (i - 1)) + " 0 " +
              std::to_string(0.5 - sink) + "\"><freejoint/><geom type=\"mesh\" mesh=\"ball\"/></body>";
  return "<mujoco><asset>" + test::inlineMesh("ball", makeIcosphere(0.5, 3)) +
         test::inlineMesh("slab", makeBox(Vec3(5, 2, 0.25))) +
         "</asset><worldbody><geom type=\"mesh\" mesh=\"slab\" pos=\"0 0 -0.25\"/>" + bodies + "</worldbody></mujoco>";
}

// The contacts of one mj_forward, in MuJoCo's order.
struct Seen {
  int geom1, geom2;
  Vec3 pos;
  double dist;
};
std::vector<Seen> contactsOf(const mjData* d) {
  std::vector<Seen> out;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    out.push_back({c.geom1, c.geom2, Vec3(c.pos[0], c.pos[1], c.pos[2]), c.dist});
  }
  return out;
}

// One step at a fixed pose: the collider tells steps apart by mjData::time, so advancing the
// clock and calling mj_forward is a step in which the bodies rest exactly where they were.
void stepAt(const mjModel* m, mjData* d, int step) {
  d->time = 0.001 * step;
  mj_forward(m, d);
}

TEST(MujocoCollider, InterruptedPairResumesFromItsFrontInTheNextStep) {
  // A sphere resting on the slab (the same pose every step). Oracle: the unlimited query's contacts
  // at that pose. The step budget is the largest at which the first step is interrupted; the
  // coherence cache keeps the front it reached, and the next step, re-testing that front (one test
  // per pair) and refining it, finishes with the unlimited answer. Without the cache every step
  // starts again from the roots below the cost and never finishes.
  // frontierPairCost 0: with the default charge of 2 units per front pair a resumed query needs
  // five units per pair of its final front (re-test, charge, and the charge reserved for each
  // test's growth), more than this pair's whole cold query costs: docs/engines-mujoco.md, limits.
  mujoco::ModelPtr m = test::loadXmlText(spheresOnSlab(1, 0.01), "resume.xml");
  ColliderSettings settings;
  settings.model = ContactModel::kCfm;
  settings.frontierPairCost = 0;
  // One step from a fresh state at `budget` tests (0 = unlimited): its contacts, and whether the
  // query was interrupted.
  auto firstStep = [&](std::uint64_t budget, std::vector<Seen>* contacts) {
    ColliderSettings probe = settings;
    probe.budgetTests = budget;
    mujoco::DataPtr d(mj_makeData(m.get()));
    Collider collider(probe);
    collider.addModel(m.get());
    collider.install();
    stepAt(m.get(), d.get(), 0);
    if (contacts) *contacts = contactsOf(d.get());
    return std::pair(collider.totals(d.get()).pairsInterrupted > 0, collider.totals(d.get()).testsSpent);
  };
  std::vector<Seen> unlimited;
  const auto [unlimitedInterrupted, cost] = firstStep(0, &unlimited);
  ASSERT_FALSE(unlimitedInterrupted);
  ASSERT_GE(unlimited.size(), 1u);
  for (const Seen& c : unlimited) EXPECT_LT(c.dist, 0.0);
  // The largest budget at which the first step is interrupted (a query stops before an expansion
  // it cannot pay for whole, so this is up to one expansion below the cost).
  std::uint64_t lo = 1, hi = cost;  // interrupted at lo (asserted below), finished at hi
  while (hi - lo > 1) {
    const std::uint64_t mid = (lo + hi) / 2;
    (firstStep(mid, nullptr).first ? lo : hi) = mid;
  }
  ASSERT_TRUE(firstStep(lo, nullptr).first);
  settings.budgetTests = lo;
  SCOPED_TRACE("unlimited query: " + std::to_string(cost) + " tests, budget " + std::to_string(settings.budgetTests));
  for (const bool coherence : {true, false}) {
    SCOPED_TRACE(coherence ? "coherence" : "no coherence");
    settings.coherence = coherence;
    mujoco::DataPtr d(mj_makeData(m.get()));
    Collider collider(settings);
    collider.addModel(m.get());
    collider.install();
    int finishedAt = -1;
    for (int step = 0; step < 20 && finishedAt < 0; ++step) {
      stepAt(m.get(), d.get(), step);
      if (collider.totals(d.get()).pairsInterrupted == std::uint32_t(step)) finishedAt = step;
    }
    if (!coherence) {
      EXPECT_EQ(finishedAt, -1) << "a query restarted from the roots cannot finish below its cost";
      continue;
    }
    EXPECT_EQ(finishedAt, 1) << "interrupted in the first step, finished from its front in the second";
    const std::vector<Seen> resumed = contactsOf(d.get());
    ASSERT_EQ(resumed.size(), unlimited.size());
    for (std::size_t i = 0; i < resumed.size(); ++i) {
      EXPECT_NEAR(resumed[i].dist, unlimited[i].dist, 1e-12);
      EXPECT_NEAR((resumed[i].pos - unlimited[i].pos).norm(), 0.0, 1e-12);
    }
    EXPECT_LE(collider.totals(d.get()).testsSpent, 2 * settings.budgetTests);
  }
}

TEST(MujocoCollider, SkippedPairReplaysItsContactsMovedWithTheGeoms) {
  // Three spheres on the slab at a step budget that cannot query them all. Every step slides the
  // spheres by dx along x. A pair the budget skips keeps its previous contacts anchored in both
  // geoms (collider.h): the slab's point stays, the sphere's moves dx, so the contact point moves
  // dx / 2 and the depth (along the slab's vertical normal) is unchanged -- whereas a new query
  // puts the point under the sphere, dx further. So in each step exactly as many pairs as the
  // collider reports skipped must show their previous contacts moved by dx / 2, none missing.
  const int spheres = 3;
  mujoco::ModelPtr m = test::loadXmlText(spheresOnSlab(spheres, 0.01), "replay.xml");
  mujoco::DataPtr d(mj_makeData(m.get()));
  ColliderSettings settings;
  settings.model = ContactModel::kExact;
  settings.budgetTests = 8;
  Collider collider(settings);
  collider.addModel(m.get());
  collider.install();
  const double dx = 1e-3;
  std::vector<Seen> previous;
  std::uint32_t skippedTotal = 0, skippedChecked = 0;
  int checked = 0;
  for (int step = 0; step < 30; ++step) {
    for (int b = 0; b < spheres; ++b) d->qpos[7 * b] = 3.0 * (b - 1) + dx * step;
    stepAt(m.get(), d.get(), step);
    const std::vector<Seen> now = contactsOf(d.get());
    const mujoco::StepStats s = collider.totals(d.get());
    const std::uint32_t skipped = s.pairsSkipped - skippedTotal;
    skippedTotal = s.pairsSkipped;
    // Each sphere's contacts (its pair is (slab, sphere) in either order).
    auto ofSphere = [&](const std::vector<Seen>& all, int b) {
      std::vector<const Seen*> out;
      for (const Seen& c : all)
        if (m->geom_bodyid[c.geom1] == b + 1 || m->geom_bodyid[c.geom2] == b + 1) out.push_back(&c);
      return out;
    };
    // From the step after every pair has been queried once (before that a skipped pair has
    // nothing to replay) every sphere must have contacts in every step, queried or replayed.
    bool allQueried = step > 0;
    for (int b = 0; b < spheres; ++b) allQueried = allQueried && !ofSphere(previous, b).empty();
    if (!allQueried) {
      previous = now;
      continue;
    }
    ++checked;
    std::uint32_t replayed = 0;
    for (int b = 0; b < spheres; ++b) {
      const std::vector<const Seen*> before = ofSphere(previous, b), after = ofSphere(now, b);
      EXPECT_FALSE(after.empty()) << "sphere " << b << ", step " << step;
      bool moved = !before.empty() && before.size() == after.size();
      for (std::size_t i = 0; moved && i < before.size(); ++i)
        moved = std::abs(after[i]->dist - before[i]->dist) < 1e-9 &&
                (after[i]->pos - before[i]->pos - Vec3(dx / 2, 0, 0)).norm() < 1e-9;
      replayed += moved;
    }
    EXPECT_EQ(replayed, skipped) << "step " << step;
    skippedChecked += skipped;
    previous = now;
  }
  EXPECT_GE(checked, 20);
  EXPECT_GE(skippedChecked, 20u) << "the budget must be too small for three pairs a step";
  EXPECT_EQ(collider.totals(d.get()).pairsFallback, 0u) << collider.lastError();
}

TEST(MujocoCollider, ContactsPerPairAreCappedAtMjmaxconpair) {
  // A bed of 8 x 8 separate square pillars (one mesh) sunk 0.01-0.013 into a slab: 64 disjoint
  // contact patches, far more contacts than MuJoCo's per-pair array holds (mjMAXCONPAIR, 50). The
  // pillars reach deeper toward the bed's middle (a bowl, up to 3 mm), so that every patch adds
  // depth to the manifold: a flat bed's interior patches add nothing to its support polygon's
  // corners and the manifold reduction leaves them out (docs/narrow-phase.md, "Manifold").
  TriangleMesh bed;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      TriangleMesh pillar = makeBox(Vec3(0.05, 0.05, 0.05));
      const auto base = std::uint32_t(bed.vertices.size());
      const Vec3 centre(0.25 * i - 0.875, 0.25 * j - 0.875, 0.0);
      const double reach = 0.003 * (1.0 - centre.squaredNorm() / (2.0 * 0.875 * 0.875));
      for (const Vec3& v : pillar.vertices) bed.vertices.push_back(v + centre - Vec3(0, 0, v.z() < 0 ? reach : 0.0));
      for (const Triangle& t : pillar.triangles) bed.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
  const std::string xml = "<mujoco><asset>" + test::inlineMesh("bed", bed) +
                          test::inlineMesh("slab", makeBox(Vec3(2, 2, 0.25))) +
                          "</asset><worldbody><geom name=\"slab\" type=\"mesh\" mesh=\"slab\" pos=\"0 0 -0.25\"/>"
                          "<body pos=\"0 0 0.04\"><freejoint/><geom name=\"bed\" type=\"mesh\" mesh=\"bed\"/></body>"
                          "</worldbody></mujoco>";
  mujoco::ModelPtr m = test::loadXmlText(xml, "bed.xml");
  for (const std::uint32_t maxContacts : {8u, 50u}) {
    SCOPED_TRACE("maxContacts " + std::to_string(maxContacts));
    mujoco::DataPtr d(mj_makeData(m.get()));
    ColliderSettings settings;
    settings.model = ContactModel::kExact;
    settings.maxContacts = maxContacts;
    Collider collider(settings);
    collider.addModel(m.get());
    collider.install();
    mj_forward(m.get(), d.get());
    EXPECT_EQ(d->ncon, int(maxContacts));  // 64 patches, each deeper than MuJoCo's margin 0
    for (int i = 0; i < d->ncon; ++i) {
      EXPECT_LT(d->contact[i].dist, 0.0);
      EXPECT_NEAR(d->contact[i].pos[2], -0.0065, 0.0065 + 1e-9);  // within the 1-1.3 cm overlap
    }
  }
  EXPECT_EQ(mjMAXCONPAIR, 50);
  EXPECT_THROW(Collider(ColliderSettings{.maxContacts = mjMAXCONPAIR + 1}), Error);
  EXPECT_THROW(Collider(ColliderSettings{.maxContacts = 0}), Error);
}

TEST(MujocoCollider, BadModelFilesNameTheirError) {
  try {
    mujoco::loadModel("/nonexistent/model.xml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kFileNotFound);
  }
  try {
    test::loadXmlText("<mujoco><worldbody><geom type=\"mesh\" mesh=\"missing\"/></worldbody></mujoco>", "bad.xml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kParseError);
    EXPECT_NE(std::string(e.what()).find("bad.xml"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Collider(ColliderSettings{.maxContacts = 0}), Error);
}

}  // namespace
}  // namespace clod

#else

TEST(MujocoCollider, SkippedWithoutMujoco) {
  GTEST_SKIP() << "MuJoCo (libmujoco-dev) was not found at configure time (or this is the sanitizer build): "
                  "clod_mujoco and its tests are not built";
}

#endif
