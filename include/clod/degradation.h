#pragma once
// Graceful-degradation scenarios (issue 17): small scenes with an analytic (or reference)
// outcome, built in code, run under a contact model and a per-frame budget, and judged against
// fixed plausibility thresholds. Tests, `clod experiment degradation` and the benchmarks share
// them, so all three measure the same thing. scenes/ holds the same scenes as JSON for
// `clod simulate` (scenes/stack_5.json, slope_rest.json, ...).
//
// The scenes (all on a static ground box whose top is at z = 0 or, for the slopes, a static box
// rotated by the slope angle about +y; 1 m boxes are 12-triangle meshes; gravity 9.81 m/s^2):
//   stack5          5 boxes stacked face on face, aligned;             friction 0.6, 10 s
//   stack5-twisted  the same, box k turned 10 k degrees about z;       friction 0.6, 10 s
//   pyramid10       a 4-3-2-1 pyramid (in x-z), 2 cm gaps between the boxes of a row, each box of
//                   an upper row centred over a gap;                   friction 0.6, 10 s
//   slide           a box sliding along +x at 2 m/s;                   friction 0.3, 3 s
//   slope-rest      a box resting on a 20 degree slope;                friction 0.6, 4 s
//   slope-slide     a box released on a 35 degree slope;               friction 0.3, 2 s
//   drop-bunny, drop-spot, drop-fandisk
//                   the shared meshes (bunny-1500.obj, spot.obj, fandisk.obj of
//                   ScenarioSettings::meshDir) scaled to a ~0.75 m bounding-box diagonal and
//                   dropped from 0.25 m onto the ground;               friction 0.6, 3 s
// Both bodies of a contact get the same friction (the world mixes by the geometric mean).
//
// Plausibility criteria (the thresholds; the "tracked" body is the top box, the box or
// the dropped mesh; displacement is of its centre of mass from its start; tilt is the angle
// between its initial and current body z axis):
//   every scene   no divergence (World::step throwing kSimulationDiverged), no dynamic body's
//                 centre of mass inside a static box in any frame, no body leaving the bounds;
//   stacks        after the run: displacement < 2 cm (pyramid 5 cm), tilt < 1 deg (pyramid
//                 2 deg), speed < 5 cm/s;
//   slide         stopped (speed < 5 cm/s), distance travelled along +x within 10 % of
//                 v^2 / (2 mu g), tilt < 2 deg;
//   slope-rest    displacement < 2 cm;
//   slope-slide   distance down the slope within 10 % of a t^2 / 2, a = g (sin th - mu cos th);
//   drops         the lowest mesh vertex is never more than 1 % of the mesh's bounding-box
//                 diagonal below the ground's top (checked every frame).
// The outcome error (ScenarioOutcome::error, metres) is the distance of the tracked body's final
// centre of mass from the analytic one: the start for stacks and slope-rest, start + expected
// distance along the motion for slide and slope-slide, and for drops the final centre of mass of
// a reference run (the exact model at an unlimited budget) when one is given.
//
// Budget rule (monotone degradation): doubling a budget may not make the error worse by more
// than the larger of 10 % and 2 mm (degradesMonotonically).

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "clod/scene.h"

namespace clod {

/// The scenarios. Values are stable (tables key on the names).
enum class ScenarioKind : std::uint8_t {
  kStack5 = 0,
  kStack5Twisted,
  kPyramid10,
  kSlide,
  kSlopeRest,
  kSlopeSlide,
  kDropBunny,
  kDropSpot,
  kDropFandisk,
};

/// Every scenario, in the order above.
inline constexpr std::array<ScenarioKind, 9> kAllScenarios = {
    ScenarioKind::kStack5,    ScenarioKind::kStack5Twisted, ScenarioKind::kPyramid10,
    ScenarioKind::kSlide,     ScenarioKind::kSlopeRest,     ScenarioKind::kSlopeSlide,
    ScenarioKind::kDropBunny, ScenarioKind::kDropSpot,      ScenarioKind::kDropFandisk};

/// Stable name: "stack5", "stack5-twisted", "pyramid10", "slide", "slope-rest", "slope-slide",
/// "drop-bunny", "drop-spot", "drop-fandisk".
std::string_view scenarioName(ScenarioKind kind) noexcept;
/// Inverse of scenarioName (exact). Throws clod::Error(kInvalidArgument) naming the text and
/// listing the valid names.
ScenarioKind parseScenarioKind(std::string_view name);
/// True for the three mesh drops (their error needs a reference run).
bool isDropScenario(ScenarioKind kind) noexcept;
/// The simulated time the criteria are stated for (s): 10 for the stacks, 3 for the slide,
/// 4 for slope-rest, 2 for slope-slide, 3 for the drops.
double defaultScenarioSeconds(ScenarioKind kind) noexcept;

/// How to run a scenario.
struct ScenarioSettings {
  ContactModel model = ContactModel::kExact;
  std::uint64_t budgetTests = 0;  ///< WorldSettings::budgetTests (tests per frame, 0 = unlimited)
  double budgetMicros = 0.0;      ///< WorldSettings::budgetMicros (µs per frame, 0 = unlimited)
  double rateHz = 60.0;           ///< frames per second: dt = 1 / rateHz (> 0)
  double seconds = 0.0;           ///< simulated time; 0 = defaultScenarioSeconds
  /// Folder of the shared meshes (bunny-1500.obj, spot.obj, fandisk.obj); drops only.
  std::filesystem::path meshDir;
  /// Drops only: metres added to the drop height (finite), to measure how far a landing moves
  /// when it starts a hair higher (the reference's own sensitivity, `clod experiment degradation`).
  double dropHeightOffset = 0.0;
};

/// The scene of a scenario, with the settings applied (model, budgets, dt, steps; the stacks use
/// WorldSettings::minSubsteps = 8 like scenes/stack_10.json). The tracked body is the last one.
/// Drops read their mesh (to place it on the ground). Throws clod::Error(kInvalidArgument) for a
/// non-positive or non-finite rate, negative seconds, a negative/non-finite budgetMicros or a
/// non-finite dropHeightOffset, and
/// the mesh loader's errors (mesh_io.h).
SceneDescription makeScenario(ScenarioKind kind, const ScenarioSettings& settings);

/// What a run measured. Lengths in metres, angles in degrees, speeds in m/s.
struct ScenarioOutcome {
  ScenarioKind kind = ScenarioKind::kStack5;
  std::uint32_t steps = 0;           ///< frames simulated (fewer when it diverged)
  double simulatedSeconds = 0.0;
  // The tracked body at the end.
  Vec3 finalCenter = Vec3::Zero();   ///< centre of mass, world
  double displacement = 0.0;         ///< |final - initial centre of mass|
  double tiltDeg = 0.0;              ///< final tilt
  double maxTiltDeg = 0.0;           ///< largest tilt over the frames
  double speed = 0.0;                ///< final centre-of-mass speed
  /// slide and slope-slide: distance along the expected direction of motion, and its analytic
  /// value (v^2 / (2 mu g), resp. a t^2 / 2); 0 elsewhere.
  double distance = 0.0;
  double expectedDistance = 0.0;
  /// drops: the deepest the lowest mesh vertex got below the ground's top over all frames, as a
  /// fraction of the mesh's bounding-box diagonal (<= 0 when it never went below); 0 elsewhere.
  double maxSinkRel = 0.0;
  bool diverged = false;             ///< World::step threw kSimulationDiverged
  bool fellThrough = false;          ///< a centre of mass inside a static box, or out of bounds
  /// Cost: wall and CPU (this thread) seconds per simulated second, stepping only (the world's
  /// construction and baking excluded). Real time means < 1.
  double wallPerSimSecond = 0.0;
  double cpuPerSimSecond = 0.0;
  // Narrow-phase budget use (StepReport), over all frames.
  std::uint64_t testsSpent = 0;
  double meanBudgetSpent = 0.0;      ///< mean StepReport::budgetSpent per frame
  std::uint64_t maxBudgetSpent = 0;  ///< largest StepReport::budgetSpent of a frame
  std::uint64_t pairsSkipped = 0;
  std::uint64_t pairsInterrupted = 0;
  double meanNarrowMicros = 0.0;     ///< mean narrow-phase wall time per frame (µs)
  /// Distance from the analytic outcome (see the top); NaN for a drop without a reference and for
  /// a diverged run.
  double error = 0.0;
  bool plausible = true;             ///< every criterion of the scenario held
  /// One line per failed criterion, e.g. "top box moved 0.199 m (limit 0.02)".
  std::vector<std::string> failures;
};

/// Builds the scene (makeScenario, buildWorld with `cacheDir` as its bake cache), steps it for
/// the scenario's time on this thread and judges it. `reference` (drops): the outcome of the
/// reference run, whose finalCenter the error is measured from. Throws what makeScenario and
/// buildWorld throw; a diverging simulation is an outcome (diverged, implausible), not an error.
/// No allocation per frame.
ScenarioOutcome runScenario(ScenarioKind kind, const ScenarioSettings& settings,
                            const std::filesystem::path& cacheDir,
                            const ScenarioOutcome* reference = nullptr);

/// Judges a run of a scenario's scene that was stepped elsewhere -- another engine running
/// makeScenario's scene (bench/bullet_compare.cpp runs them in Bullet) -- by the criteria at the
/// top of this file, with the code runScenario uses. Reads from `outcome`: kind, simulatedSeconds,
/// finalCenter, speed, maxTiltDeg, maxSinkRel, diverged and `failures` (the caller has already
/// recorded there how the run diverged or fell through, and set fellThrough). `initialCenter`: the
/// tracked body's centre of mass at the start; `finalTiltDeg`: its tilt at the end. Sets
/// displacement, tiltDeg, distance, expectedDistance, error, plausible, and appends the failed
/// criteria to failures. `reference`: as for runScenario.
void judgeScenario(ScenarioOutcome& outcome, const Vec3& initialCenter, double finalTiltDeg,
                   const ScenarioOutcome* reference = nullptr);

/// The budget rule: true when errorAt2N <= errorAtN + max(0.1 errorAtN, 0.002 m). NaN on
/// either side: false.
bool degradesMonotonically(double errorAtN, double errorAt2N) noexcept;

}  // namespace clod
