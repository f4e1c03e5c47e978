// clod as MuJoCo's mesh collider: conventions, installation, budget (include/clod/mujoco/collider.h).
#include <gtest/gtest.h>

#if CLOD_HAVE_MUJOCO

#include <cmath>

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

TEST(MujocoCollider, CubeOnCubeFollowsMujocoConventions) {
  for (const bool upperFirst : {false, true}) {
    for (const double yaw : {0.0, 30.0}) {
      SCOPED_TRACE("upper first " + std::to_string(upperFirst) + ", yaw " + std::to_string(yaw));
      mujoco::ModelPtr m = test::loadXmlText(twoCubes(0.1, yaw, upperFirst), "cubes.xml");
      mujoco::DataPtr d(mj_makeData(m.get()));
      ColliderSettings settings;
      settings.model = ContactModel::kExact;
      Collider collider(settings);
      collider.addModel(m.get());
      collider.install();
      mj_forward(m.get(), d.get());
      collider.uninstall();
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
