// `clod experiment flat-contact`: the JSON contract external checks rely on, the files written
// with -o, bad usage, and the physical sanity of the setups against hand-derived expectations
// (a box passing over a 4 cm bump must rise by a good part of it in the reference animation and
// not at all on flat ground; a box at rest on a slab under the exact model stays put).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "clod/world.h"
#include "cli_runner.h"
#include "support/test_scale.h"

namespace {

namespace fs = std::filesystem;

// The box's front face reaches the bump's centre when its centre is half a box short of it.
constexpr double kBumpReach = 0.5;
using clod::test::quoted;
using clod::test::runCli;

fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clod_experiment_flat_contact_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(ExperimentFlatContactCli, JsonHasRestAndBumpRowsPerModelAndWritesTablesAndPlots) {
  if (clod::test::sanitizerRun()) {
    // Even the --quick second of contact-tree resting contact takes minutes under ASan.
    GTEST_SKIP() << "the contact-tree simulations are too slow under sanitizers; the Release run covers this test";
  }
  const fs::path dir = scratchDir("json");
  // --quick: 1 s at rest and 1 s of sliding instead of 10 s and 2 s (the keys are the same).
  const clod::test::CliRun run = runCli("experiment flat-contact --quick --trials 1 --json -o " + quoted(dir / "out"));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto doc = nlohmann::json::parse(run.out);
  for (const char* key : {"experiment", "paper", "settings", "rest", "bump"}) ASSERT_TRUE(doc.contains(key)) << key;
  EXPECT_EQ(doc["experiment"], "flat-contact");
  EXPECT_EQ(doc["settings"]["trials"], 1);
  EXPECT_EQ(doc["settings"]["rest_seconds"], 1.0);
  const double boxHalf = doc["settings"]["box_half"];

  std::set<std::string> restModels;
  for (const auto& row : doc["rest"]) {
    for (const char* key : {"model", "budget", "raw_contacts", "manifold_contacts", "mean_contacts", "max_contacts",
                            "median_iterations", "p95_iterations", "capped_substeps", "substeps", "drift_mm",
                            "horizontal_drift_mm", "vertical_drift_mm", "rotation_deg", "max_rotation_deg", "ms_per_step"}) {
      ASSERT_TRUE(row.contains(key)) << key;
    }
    restModels.insert(row["model"].get<std::string>());
    // rest_seconds at 60 Hz, at least one substep per step.
    EXPECT_GE(row["substeps"].get<double>(), std::floor(doc["settings"]["rest_seconds"].get<double>() * 60.0));
    EXPECT_LE(row["manifold_contacts"].get<int>(), 8);  // the manifold size
    EXPECT_GE(row["raw_contacts"].get<int>(), row["manifold_contacts"].get<int>());
    EXPECT_GE(row["median_iterations"].get<double>(), 1.0);
    EXPECT_LE(row["median_iterations"].get<double>(), doc["settings"]["velocity_iterations"].get<double>());
    if (row["model"] == "exact") {
      // Face on face: the four corners of the overlap square at least.
      EXPECT_GE(row["manifold_contacts"].get<int>(), 4);
      // At rest under exact contacts the box neither slides nor tips; it sinks at most by the
      // solver's allowed penetration (slop 0.002 of the box diagonal ~ 3.5 mm) plus a margin.
      EXPECT_LT(row["horizontal_drift_mm"].get<double>(), 0.02 * boxHalf * 2e3);
      EXPECT_LT(row["rotation_deg"].get<double>(), 1.0);
    }
  }
  EXPECT_EQ(restModels, (std::set<std::string>{"contact-tree", "exact", "cfm", "dos"}));

  ASSERT_EQ(doc["bump"].size(), 4u);
  std::set<std::string> bumpModels;
  for (const auto& row : doc["bump"]) {
    for (const char* key : {"model", "budget", "trials", "max_lift_mm", "flat_max_lift_mm", "final_x", "flat_final_x",
                            "final_yaw_deg", "final_offset_mm", "bump_lift_mm", "bump_yaw_deg", "bump_offset_mm",
                            "bump_lift_error_mm", "bump_yaw_error_deg", "rms_position_error_mm", "max_yaw_error_deg",
                            "ms_per_step", "spread"}) {
      ASSERT_TRUE(row.contains(key)) << key;
    }
    bumpModels.insert(row["model"].get<std::string>());
    EXPECT_TRUE(std::isfinite(row["rms_position_error_mm"].get<double>()));
  }
  EXPECT_EQ(bumpModels, (std::set<std::string>{"contact-tree", "exact", "cfm", "dos"}));
  const auto& reference = doc["bump"][0];
  EXPECT_EQ(reference["model"], "exact");
  EXPECT_EQ(reference["rms_position_error_mm"].get<double>(), 0.0);  // the reference against itself
  for (const char* file : {"flat-contact.json", "flat-contact.csv", "flat_contact_rest.csv", "flat_contact_bump.csv",
                           "flat_contact_drift.png", "flat_contact_contacts.png",
                           "flat_contact_iterations.png", "flat_contact_bump_lift.png", "flat_contact_bump_yaw.png",
                           "flat_contact_bump_lift.gp"}) {
    ASSERT_TRUE(fs::exists(dir / "out" / file)) << file;
    EXPECT_GT(fs::file_size(dir / "out" / file), 0u) << file;
  }
  fs::remove_all(dir);
}

// The reference animation must show the bump's effect: the exact model gives each connected
// contact patch its own normal and depth (07e55db), so the bump's patch lifts the box while the
// flush patch on the flat ground holds it up (with one normal and depth per pair the flush patch
// dominated both, and the box ploughed through: docs/narrow-phase.md, "Patches").
TEST(ExperimentFlatContactCli, ReferenceBoxRisesOverTheBumpButNotOnFlatGround) {
  // As the test above: the full experiment (10 s of resting contact per model) took 10 minutes of
  // the sanitizer run; the Release run covers it.
  if (clod::test::sanitizerRun()) GTEST_SKIP() << "10 s simulations per model: the Release run covers this test";
  // Three starts, not one: a single sliding track is chaotic at the rounding level (moving B's
  // corners with a rotation matrix instead of the quaternion, aa01b56, took the nominal start's
  // lift from 26.3 to 17.5 mm; the three-start mean went 24.2 -> 21.2 mm, sd 3.4 mm).
  const clod::test::CliRun run = runCli("experiment flat-contact --trials 3 --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto doc = nlohmann::json::parse(run.out);
  const double bumpHeight = doc["settings"]["bump_height"];
  // The world's allowed penetration (WorldSettings::slopRel of the box's diagonal, the smaller
  // body): each edge may rest that deep in what it stands on, lowering the centre by up to one slop.
  const double boxHalf = doc["settings"]["box_half"];
  const double slopMm = clod::WorldSettings{}.slopRel * 2.0 * std::sqrt(3.0) * boxHalf * 1e3;
  const auto& reference = doc["bump"][0];
  ASSERT_EQ(reference["model"], "exact");
  // The reference box (3 m/s, friction 0.2: it stops after v^2 / (2 mu g) ~ 2.3 m) reaches the
  // bump and rises while one side rides over it: a rigid box tipped onto the bump by one edge
  // lifts its centre by half the bump's height, less the slop. Ploughing through gives ~0 (cfm and
  // dos in this experiment; the exact model gave -1.7 mm before 07e55db). On flat ground it never
  // rises by more than a quarter of the bump's height (the slop is ~3.5 mm).
  EXPECT_GT(reference["final_x"].get<double>(), doc["settings"]["bump_center"][0].get<double>() - kBumpReach);
  EXPECT_GT(reference["bump_lift_mm"].get<double>(), 0.5 * bumpHeight * 1e3 - slopMm);
  EXPECT_LT(reference["flat_max_lift_mm"].get<double>(), 0.25 * bumpHeight * 1e3);
}

// Issue 17, point 4: cfm's box follows the reference (the exact model) over the bump. The first
// second (--quick) is the approach and the climb, where cfm went wrong: the ground patch offered
// only its hull's vertices, so the bump's flank under the box's front edge gave no contact; the
// box ploughed in until the bump's top was ~4 cm inside and was thrown up or stopped, turned
// (3 starts: 105 mm rms; now 28-30 mm). Bound: the 50 mm, which the reference itself
// keeps against a 1 mm shift of its start (24 mm over the full 2 s, REPRODUCING.md
// "flat-contact"). The heading is not asserted: since friction is a cone (world.cpp,
// frictionStep) the reference box yaws 5.7 deg as the bump under its +y half pushes that side
// back along the bump's slope, with no lateral friction left to hold it (a pyramid's independent
// lateral friction held it straight: cfm was within 0.15 deg of it); cfm's contacts on the bump's
// flank push along the box's face, not the slope, and its box stays straight: 5.6 deg off (docs/dynamics.md, "Known
// limits").
// The contact tree is held to the same bound (quick run: 17 mm; 28 mm before its flat partners
// were answered by support points and a flat leaf's samples reported at its surface,
// docs/contact-tree.md).
TEST(ExperimentFlatContactCli, CfmAndTheContactTreeFollowTheReferenceUpTheBump) {
  if (clod::test::sanitizerRun()) GTEST_SKIP() << "contact-tree simulations: the Release run covers this test";
  const clod::test::CliRun run = runCli("experiment flat-contact --quick --trials 3 --json");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto doc = nlohmann::json::parse(run.out);
  for (const char* model : {"cfm", "contact-tree"}) {
    bool found = false;
    for (const auto& row : doc["bump"]) {
      if (row["model"] != model) continue;
      found = true;
      EXPECT_LT(row["rms_position_error_mm"].get<double>(), 50.0) << model;
    }
    EXPECT_TRUE(found) << model;
  }
}

TEST(ExperimentFlatContactCli, BadTrialsExitWithTwo) {
  clod::test::CliRun run = runCli("experiment flat-contact --trials 500");
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.err.find("--trials"), std::string::npos);
  run = runCli("experiment flat-contact --trials x");
  EXPECT_EQ(run.exitCode, 2);
}

}  // namespace
