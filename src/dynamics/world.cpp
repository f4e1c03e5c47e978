// The world: broad phase -> budget division -> narrow phase -> sequential impulses. The design
// and its reasons are in docs/dynamics.md; the contracts in include/clod/world.h.
#include "clod/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include <Eigen/Eigenvalues>

#include "clod/error.h"
#include "clod/quaternion.h"
#include "clod/query.h"
#include "dynamics/ball_contacts.h"
#include "dynamics/hull_points.h"
#include "narrowphase/separation.h"
#include "narrowphase/support_polygon.h"

namespace clod {
namespace {

// Fraction of the thinnest body's extent a body may travel per substep. Below 1/2 a body cannot
// pass through a body as thick as that extent without overlapping it in some substep.
constexpr double kTravelFraction = 0.25;
// Split-impulse correction per substep at most this fraction of the smaller body's diagonal.
constexpr double kMaxCorrectionRel = 0.02;
// A previous contact passes its impulse on only to a new contact whose normal is within ~18 deg.
constexpr double kWarmStartNormalCos = 0.95;
// A persistent contact keeps its body-anchored points while the two anchors have slid apart by
// less than this fraction of the smaller body's diagonal (tangentially) and have not opened by
// more than it (Bullet's contact breaking threshold plays the same role: 2 cm for unit bodies).
constexpr double kAnchorDriftRel = 0.01;
// The contact tree's samples within this fraction of the smaller diagonal of touching are
// contacts (speculative ones where they are apart): a face resting on a face touches at depth ~0,
// where the fields' noise (~1e-6 of the diagonal on flat cells, within their error bounds) puts
// some samples a hair inside and the rest a hair outside. With no margin the answer held whichever
// corner the noise made deepest -- one contact of a box at rest, changing from substep to substep
// -- and a box spinning on the floor drifted 12 cm on the interior contacts the persistent manifold
// carried in between (the exact model: 0). Far below the slop (2e-3), so a speculative contact's
// allowed approach (its gap per substep) never matters to a body in flight. Finished answers only
// (QuerySettings::contactSampling; docs/narrow-phase.md, "Margin").
constexpr double kSampleMarginRel = 1e-4;
// A pair that leaves the broad phase keeps its coherence cache while the two bodies' boxes are
// less than this fraction of the smaller diagonal apart (hysteresis, as a pair cache's): a body
// that hops by a hair and lands again resumes the front it had refined instead of starting from
// the roots, which a small budget may not get past (World::Impl::substep).
constexpr double kPairKeepGapRel = 0.01;  // (and while they have moved less than that)
// Substeps for bodies about to touch (World::step): two bodies whose boxes, grown by their travel
// over the step, overlap move at most this fraction of the smaller body's diagonal together per
// substep, so a body arriving at speed is first found at most that deep inside the other (issue
// 17 allows 1 % at any frame), in at most kMaxArrivalSubsteps substeps from this rule.
constexpr double kArrivalTravelRel = 0.005;
// Sphere tests a pair without contacts may spend proving itself apart (proveApart) before a time
// budget answers it from the roots (World::Impl::substep).
constexpr std::uint64_t kProofTests = 128;
constexpr double kMaxArrivalSubsteps = 8.0;
// ... and up to this many for the part of that travel that brings them together: all of it for
// a pair without contacts, the motion along the contacts' normals and the turning for a pair in
// contact (World::Impl::arrivalTravel). At 60 Hz, 8 substeps let a mesh falling at 4 m/s, or a
// tumbling fandisk's far corner, enter the floor 1.1-3.6 % of its diagonal before any contact.
constexpr double kMaxApproachSubsteps = 16.0;
// ... but never so few that the approach per substep exceeds this fraction of the smaller
// diagonal (issue 17 allows a body 1 % inside another at any frame; the solver needs the first
// contact shallower than that to push it out within the frame), up to maxSubsteps.
constexpr double kMaxFirstContactRel = 0.008;

// Substeps for the part of a pair's travel over a step that brings it together (`approach`,
// World::Impl::arrivalTravel), the smaller body's diagonal `diag`: the capped rule, floored.
double approachSubsteps(double approach, double diag) {
  return std::max(std::min(approach / (kArrivalTravelRel * diag), kMaxApproachSubsteps),
                  approach / (kMaxFirstContactRel * diag));
}
// Passes over each support layer's pairs in the shock-propagation sweep (World::Impl::solve). One
// pass left a 1,000 kg box on a 1 kg box sliding at 5-7 cm/s after 3 s (friction and the four
// corners are coupled through the rotation); 2 hold it (WorldMassRatio tests).
constexpr std::uint32_t kShockPasses = 2;
// Least substeps for a stack (World::step): as many as the bodies in its tallest support chain,
// up to this, each with the full velocityIterations. Projected Gauss-Seidel passes support down a
// stack about one body per iteration, and smaller steps converge far better than more iterations
// at equal cost (Macklin et al., "Small steps in physics simulation", SCA 2019): at one substep
// per 60 Hz frame a tower of five boxes whose middle one is 50 times heavier than the one under
// it shook at up to 13 cm/s for good; at its five substeps it stands still.
constexpr std::uint32_t kMaxStackSubsteps = 8;

bool finite(const Vec3& v) { return v.allFinite(); }

// What substep i of n may spend of a step's `budget` units, `spent` of them already gone: an
// equal share of what the step has left, rounded up (what a substep does not spend rolls over to
// the ones after it), but never ahead of the even schedule -- by its end substep i may have spent
// ceil(budget (i + 1) / n). The schedule matters where the substeps outnumber the units: the
// queries are then spaced every n / budget substeps from the first. Rounding each share up gave
// each of the first substeps a unit and left the rest of the step without queries -- a 1 mm
// bunny at 60 Hz and 16 tests per frame, spinning at ~100 rad/s in 128 substeps, kept 112
// substeps' stale contacts and sank 11 % of its diagonal.
std::uint64_t substepAllowance(std::uint64_t budget, std::uint64_t spent, std::uint32_t i, std::uint32_t n) {
  const std::uint64_t left = budget - std::min(budget, spent);
  const std::uint64_t share = (left + (n - i) - 1) / (n - i);
  // ceil(budget (i + 1) / n) without overflow (a budget may be up to 2^64 - 1 units):
  // budget = q n + r with r < n, and r (i + 1) < n^2 fits.
  const std::uint64_t q = budget / n, r = budget % n;
  const std::uint64_t target = q * (i + 1) + (r * (i + 1) + n - 1) / n;
  return std::min(share, target > spent ? target - spent : 0);
}

// A ball body (RigidBodyDesc::ballRadius) is one whose mesh encloses the ball about its origin,
// and a dynamic one turns about that origin: the contacts put on the ball would otherwise miss
// what the narrow phase saw, or push off-centre.
template <class Fail>
void requireBallHull(const RigidBodyDesc& d, Fail bad) {
  const double r = d.ballRadius;
  // Rounding of the hull's planes: ~1e-15 of the radius; a user's hull may be a hair inside.
  const double slack = 1e-9 * r;
  if (d.type == BodyType::kDynamic && d.centerOfMass.norm() > slack)
    bad("a ball's centre of mass must be its mesh origin (ballRadius)");
  const TriangleMesh& mesh = d.shape->mesh();
  for (const Triangle& t : mesh.triangles) {
    const Vec3 &p0 = mesh.vertices[t[0]], &p1 = mesh.vertices[t[1]], &p2 = mesh.vertices[t[2]];
    const Vec3 n = (p1 - p0).cross(p2 - p0);
    // Outward faces (counter-clockwise seen from outside) have the origin behind them.
    if (!(n.dot(p0) >= (r - slack) * n.norm()))
      bad("the mesh must enclose the ball of ballRadius " + std::to_string(r) +
          " about its origin (every face's plane at least that far; makeBallHull)");
  }
}

Mat3 worldInverseInertia(const Mat3& invInertiaLocal, const Quat& q) {
  const Mat3 r = q.toRotationMatrix();
  return r * invInertiaLocal * r.transpose();
}

struct Body {
  RigidBodyDesc desc;
  BodyType type = BodyType::kDynamic;
  double invMass = 0.0;
  Mat3 inertiaLocal = Mat3::Zero();
  Mat3 invInertiaLocal = Mat3::Zero();
  Vec3 comLocal = Vec3::Zero();
  Aabb localBox;         // mesh bounds, mesh coordinates
  Aabb hullLocalBox;     // its hull's box (hullPoints), grown by the slack, mesh coordinates
  const detail::HullPoints* hullPoints = nullptr;  // its shape's, shared (World::Impl::hulls)
  // A closed convex polyhedron's face planes n . x <= d (mesh coordinates; none for other bodies).
  std::array<Eigen::Vector4d, CollisionBody::kMaxSphereFaceNormals> facePlanes;
  std::uint32_t facePlaneCount = 0;
  double minExtent = 0;  // smallest side of localBox
  double frameReach = 0; // farthest corner of localBox from the mesh origin (a turn's lever)
  std::uint32_t maxChildren = 0;  // the most children a sphere of its sphere-tree has
  // The hull's world box and support points (holdAtBoxes) at the pose (x, q) they were found for:
  // a body in many pairs finds them once per substep.
  struct HullCache {
    Vec3 x = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    Quat q = Quat::Identity();
    Aabb box;
    std::array<std::uint8_t, 6> haveSupports{};   // how many found, per direction 2 axis + (sign > 0)
    std::array<std::array<Vec3, 5>, 6> supports;  // along holdDirections(axis, sign)
  };
  mutable HullCache hull;
  // State: centre of mass in the world, orientation, velocities.
  Vec3 x = Vec3::Zero();
  Quat q = Quat::Identity();
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
  // Split-impulse pseudo velocities (reset every substep).
  Vec3 vp = Vec3::Zero();
  Vec3 wp = Vec3::Zero();
  Mat3 invInertiaWorld = Mat3::Zero();
  // World editing (world.h; the functions at the end of this file): a retired id, the force and
  // torque for the next step, the collision filter.
  bool removed = false;
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
  CollisionFilter filter;

  Pose pose() const { return Pose{q, x - q * comLocal}; }
  Aabb worldBox(double margin) const {
    const Pose p = pose();
    const Vec3 c = p.apply(localBox.center());
    const Mat3 r = p.rotation.toRotationMatrix().cwiseAbs();
    const Vec3 h = r * (0.5 * localBox.extent()) + Vec3::Constant(margin);
    return Aabb{c - h, c + h};
  }
};

// A contact's point on A (on B): its anchor in the body -- or, on a ball (RigidBodyDesc::
// ballRadius), the ball's surface point along the normal (-normal on A, +normal on B). A ball has
// no material contact point: it rolls, and an anchor turning with it would lift off the ground
// as a cycloid, opening the contact (docs/dynamics.md, "Balls").
Vec3 ballSupport(const Body& ball, const Vec3& towardOther) {
  return ball.pose().translation + ball.desc.ballRadius * towardOther;
}
Vec3 pointOnA(const Body& a, const Vec3& anchor, const Vec3& normal) {
  return a.desc.ballRadius > 0.0 ? ballSupport(a, -normal) : Vec3(a.x + a.q * anchor);
}
Vec3 pointOnB(const Body& b, const Vec3& anchor, const Vec3& normal) {
  return b.desc.ballRadius > 0.0 ? ballSupport(b, normal) : Vec3(b.x + b.q * anchor);
}

// The Coulomb coefficient of a contact between two bodies: the geometric mean of theirs.
double pairFriction(const Body& a, const Body& b) { return std::sqrt(a.desc.friction * b.desc.friction); }

// The inverse effective mass of a contact in its tangent plane, in the basis (t1, t2): the
// tangential velocity change per unit tangential impulse, K = [k11 k12; k12 k22]. The two
// tangents are coupled through the bodies' rotation (k12 != 0 off the principal axes).
struct TangentInverseMass {
  double k11 = 0, k12 = 0, k22 = 0;
};

// One contact constraint; accumulated impulses persist for warm starting. The contact is
// anchored in both bodies (anchorA, anchorB: body-frame offsets from the centre of mass), so its
// separation follows the bodies' motion point by point (see persistContacts below).
struct SolverContact {
  Contact c;
  Vec3 anchorA = Vec3::Zero(), anchorB = Vec3::Zero();
  double separation = 0;  // (anchor A - anchor B) . normal in the world: < 0 penetrating
  double speculative = 0; // max(separation, 0) / h: approach speed the velocity solve allows
  Vec3 rA = Vec3::Zero(), rB = Vec3::Zero(), t1 = Vec3::UnitX(), t2 = Vec3::UnitY();
  double massN = 0;
  TangentInverseMass tangentK;  // the tangent plane's 2 x 2 inverse effective mass (t1, t2)
  // The same with the lower body of a shock-propagation pair held fixed (orderSupportLayers).
  double shockMassN = 0;
  TangentInverseMass shockTangentK;
  double restitution = 0; // coefficient if this contact bounces this substep, else 0
  double targetPos = 0;   // pseudo-velocity target (split impulse)
  double lambdaN = 0, lambdaT1 = 0, lambdaT2 = 0, lambdaP = 0;
  // The part of lambdaN the shock sweep added to the upper body alone (shockOnA: A is the upper).
  double lambdaShock = 0;
  bool shockOnA = false;
  Vec3 frictionImpulse = Vec3::Zero();  // world-frame tangential impulse, for warm starting
  bool matched = false;                 // as a previous contact: already inherited by a new one
  bool hold = false;                    // a hold at the bodies' hull boxes (holdAtBoxes), this substep only
};

struct PairState {
  CoherenceCache cache;
  // Rolling resistance (solve): the accumulated angular impulse about the tangent axes u1, u2 of
  // the pair's mean contact normal, and the 2 x 2 inverse angular mass about them.
  double rollingL1 = 0, rollingL2 = 0;
  Vec3 rollingU1 = Vec3::UnitX(), rollingU2 = Vec3::UnitY();
  TangentInverseMass rollingK;
  // Patch friction (solve, patchFrictionStep): a pair whose contacts stand for a patch they do not
  // lie on takes its friction as one force at the load's centre and one torque about the normal.
  // The accumulated impulses: tangential (world) and about the normal; kept for warm starting.
  bool patch = false;
  Vec3 patchNormal = Vec3::UnitZ(), patchT1 = Vec3::UnitX(), patchT2 = Vec3::UnitY();
  double patchL1 = 0, patchL2 = 0, patchTorsion = 0;
  Vec3 patchImpulse = Vec3::Zero();
  // Where the bodies' hull boxes meet (patchInterface): the plane u . x = patchInterfaceAt.
  bool patchHasInterface = false;
  Vec3 patchInterfaceAxis = Vec3::UnitZ();
  double patchInterfaceAt = 0.0;
  std::vector<SolverContact> contacts;
  std::vector<SolverContact> previous;
  std::vector<SolverContact> heldBefore;  // last substep's holds: their impulses warm-start this one's
  std::uint32_t stale = 0;   // substeps since last query
  double priority = 0.0;
  bool seen = false;         // in this substep's broad phase
  bool fresh = false;        // queried this substep (else: skipped, contacts kept)
  bool interrupted = false;  // the last query stopped at its budget (QueryResult::finished false)
  bool keptFiner = false;    // the last query's coarser answer was dropped for the finer manifold
  bool reusable = false;     // the last query finished; `queriedAt` is B's pose in A's frame then
  double apartBy = 0.0;      // the last query proved the surfaces this far apart (QueryResult::separation)
  bool proofFailed = false;  // proveApart could not separate the pair at B's pose `proofFailedAt` in A
  Pose proofFailedAt;
  std::uint64_t share = 0;   // the budget the last query was granted before its frontier's (limited budgets)
  Pose queriedAt;
  bool holding = false;      // `contacts` is this substep's hold at the bodies' boxes (holdAtBoxes), no answer
  // A contact approaches by more than the slop within this substep (a hit, not resting contact):
  // the pair gets every velocity iteration (solve).
  bool impact = false;
};

std::uint64_t pairKey(BodyId a, BodyId b) { return (std::uint64_t(a) << 32) | b; }

// A body's world box from its hull: the hull's box whatever the body's turn, where the mesh box
// turned with the body reaches past the hull by up to its corners' lever.
const Aabb& hullBox(const Body& b) {
  Body::HullCache& c = b.hull;
  if (c.x == b.x && c.q.coeffs() == b.q.coeffs()) return c.box;
  c.x = b.x;
  c.q = b.q;
  c.haveSupports.fill(0);
  const Pose pose = b.pose();
  const std::optional<Aabb> box = b.hullPoints->boxUnder(pose.rotation.toRotationMatrix(), pose.translation);
  return c.box = box ? *box : b.worldBox(0.0);
}

// The hull's box in mesh coordinates: a body's box in its own frame.
Aabb hullBoxInMesh(const detail::HullPoints& hull, const CollisionBody& shape) {
  return hull.boxUnder(Mat3::Identity(), Vec3::Zero()).value_or(shape.mesh().bounds());
}

// A closed convex polyhedron's face planes (its root patch is the whole body, whose distinct face
// normals and vertices it lists): n . x <= d, mesh coordinates. Returns their count, 0 for any
// other body.
std::uint32_t convexFacePlanes(const CollisionBody& shape, std::array<Eigen::Vector4d, CollisionBody::kMaxSphereFaceNormals>& out) {
  if (!shape.patchIsWholeConvexBody(0)) return 0;
  std::uint32_t count = 0;
  for (const Vec3f& normal : shape.sphereFaceNormals(0)) {
    const Vec3 n = normal.cast<double>();
    double reach = -std::numeric_limits<double>::infinity();
    for (const std::uint32_t v : shape.spherePatchVertices(0)) reach = std::max(reach, n.dot(shape.mesh().vertices[v]));
    out[count++] = Eigen::Vector4d(n.x(), n.y(), n.z(), reach);
  }
  return count;
}

// The first point of a convex body (its facePlanes) on the world line from `from` along `dir`
// (before `from` too: the body may reach past it); none where the line misses the body.
std::optional<Vec3> firstPointAlong(const Body& b, const Vec3& from, const Vec3& dir) {
  if (b.facePlaneCount == 0) return std::nullopt;
  const Pose pose = b.pose();
  const Vec3 p = pose.applyInverse(from), u = pose.rotation.conjugate() * dir;  // mesh coordinates
  // A line along a side face (the support point was a corner on it) is inside that face within
  // this much: a turn of 1e-4 rad otherwise made it enter through the side face high up.
  const double grazing = 1e-3 * b.desc.shape->diagonal();
  double enter = -std::numeric_limits<double>::infinity(), leave = std::numeric_limits<double>::infinity();
  for (std::uint32_t k = 0; k < b.facePlaneCount; ++k) {
    const Vec3 n = b.facePlanes[k].head<3>();
    const double room = b.facePlanes[k].w() - n.dot(p), rate = n.dot(u);  // inside while s rate <= room
    if (std::abs(rate) < 0.5) {  // a side face: the line is inside it or misses the body
      if (room < -grazing) return std::nullopt;
    } else if (rate < 0.0) {
      enter = std::max(enter, room / rate);
    } else {
      leave = std::min(leave, room / rate);
    }
  }
  if (!(enter <= leave) || !std::isfinite(enter)) return std::nullopt;
  return from + enter * dir;
}

// The hull's box in the frame whose axes are the columns of `r` (coordinates r^T x): one pass.
Aabb hullBoxAlong(const Body& b, const Mat3& r) {
  const Pose pose = b.pose();
  const Mat3 m = r.transpose() * pose.rotation.toRotationMatrix();
  const Vec3 t = r.transpose() * pose.translation;
  if (std::optional<Aabb> box = b.hullPoints->boxUnder(m, t)) return *box;
  Aabb box;  // the mesh box's corners
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1) ? b.localBox.max.x() : b.localBox.min.x(), (k & 2) ? b.localBox.max.y() : b.localBox.min.y(),
                      (k & 4) ? b.localBox.max.z() : b.localBox.min.z());
    box.extend(m * corner + t);
  }
  return box;
}

// The hold's directions about axis `axis` of the frame whose axes are r's columns: along it, and
// tilted by ~14 deg toward the four sides.
constexpr double kHoldTilt = 0.25;  // tan of ~14 deg
std::array<Vec3, 5> holdDirections(const Mat3& r, int axis, double sign) {
  const Vec3 along = sign * r.col(axis), u = r.col((axis + 1) % 3), v = r.col((axis + 2) % 3);
  return {along, along + kHoldTilt * u, along - kHoldTilt * u, along + kHoldTilt * v, along - kHoldTilt * v};
}

// The hull's points farthest along the first `count` world directions (its support points),
// moved on by the slack; the body's box centre where it has no hull (HullPoints).
std::array<Vec3, 5> supportPoints(const Body& b, const std::array<Vec3, 5>& directions, std::size_t count) {
  std::array<Vec3, 5> out;
  const detail::HullPoints& hull = *b.hullPoints;
  if (hull.empty()) {
    out.fill(b.worldBox(0.0).center());
    return out;
  }
  std::array<Vec3, 5> local;  // in mesh coordinates
  local.fill(Vec3::Zero());
  for (std::size_t k = 0; k < count; ++k) local[k] = b.q.conjugate() * directions[k];
  const std::array<Vec3, 5> farthest = hull.farthestAlong(local, count);
  const Pose pose = b.pose();
  for (std::size_t k = 0; k < count; ++k) out[k] = pose.apply(farthest[k]) + hull.slack() * directions[k];
  return out;
}

// supportPoints along holdDirections about a world axis, cached at the body's pose.
const std::array<Vec3, 5>& hullSupports(const Body& b, int axis, double sign, std::size_t count) {
  hullBox(b);  // the cache at this pose
  Body::HullCache& c = b.hull;
  const std::size_t slot = 2 * std::size_t(axis) + (sign > 0.0 ? 1 : 0);
  std::array<Vec3, 5>& out = c.supports[slot];
  if (c.haveSupports[slot] >= count) return out;
  c.haveSupports[slot] = std::uint8_t(count);
  return out = supportPoints(b, holdDirections(Mat3::Identity(), axis, sign), count);
}

// A pair the test budget skipped this substep and whose contacts cannot speak for it -- it has
// none (found none yet, or its last answer was empty), or they are an interrupted answer's, which
// covers only the regions its coarse level reached, and a moving body's centre of mass does not
// rest within them (withinContacts) -- is held where its bodies' hull boxes (hullBox) are apart: the
// coarsest bound of the hierarchy, for no test. On the axis on which the boxes are farthest
// apart (the world's, or a turned immovable body's own, chooseHoldFrame), speculative contacts
// against the other box's face, each with its own gap: the bodies may close them, not pass the
// face, until a query answers the pair.
//   * A pair without contacts: one at the middle of the boxes' overlap, and one at each moving
//     body's hull point nearest the face (its support point along the axis). Without a hold such
//     a pair was free: a pyramid of 1 mm boxes at 16 tests per frame has 26 pairs, a frame of free
//     fall is 2.7 mm, and every box fell through the ground before its turn. (Holding only the
//     pairs no query had answered yet was not enough: boxes placed exactly on each other got an
//     empty first answer, then fell 5 % of a side while skipped.) The middle alone let a box of a
//     1 mm pile spinning at ~70 rad/s turn a corner through the face; its support point alone made
//     a mesh landing on it pivot, and spot's and the bunny's drops ended 21-59 cm from the
//     reference.
//   * A pair with such an answer's contacts (this substep's too; `out` holds them): each moving
//     body's support points along the axis and tilted from it by kHoldTilt toward the four sides
//     -- the points it would pivot onto about the contacts it has. A bunny landing on one contact
//     of its roots' answer turned about it and its other side came down 1.1 % of its diagonal
//     into the floor before the next answer. (Held beside every interrupted answer, the 200-body
//     bin at 1,024 tests per frame took 65 ms per frame against 36; beside those of fewer than
//     three contacts only, a 1 mm bunny turned off three contacts on one side of it.)
//   * Only points whose projection lies within the other box across the axis: its face is there
//     only within it (a box's corner held past a table's edge stood on thin air). A point past it
//     moves onto the face's nearest point, the table's edge, where the body's surface above it is
//     known (a convex body's face planes).
// The boxes were the mesh boxes turned with the bodies first: a turned bunny of 1.3 cm had its
// box's corner 4 mm below its lowest vertex, the boxes overlapped on every axis before it landed,
// and it fell 1.4 % of its diagonal into the floor unheld. Boxes that overlap on every axis by
// more than kHoldOverlapRel of the smaller diagonal say nothing (a body inside a bin's box,
// turned bodies whose boxes interlock): no hold. Returns whether it added contacts.
constexpr double kHoldOverlapRel = 0.01;

// Whether `point`, seen along axis `axis` of the frame whose axes are `frame`'s columns, lies
// within the convex polygon of the contacts' points: a centre of mass there rests on them and
// cannot turn off them.
bool withinContacts(const std::vector<SolverContact>& contacts, const Vec3& point, const Mat3& frame, int axis) {
  const Vec3 u = frame.col((axis + 1) % 3), w = frame.col((axis + 2) % 3);
  std::array<Eigen::Vector2d, 16> p;
  std::size_t n = 0;
  for (const SolverContact& c : contacts)
    if (n < p.size()) p[n++] = Eigen::Vector2d(u.dot(c.c.point), w.dot(c.c.point));
  if (n < 3) return false;
  std::sort(p.begin(), p.begin() + n, [](const auto& l, const auto& r) { return l.x() < r.x() || (l.x() == r.x() && l.y() < r.y()); });
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::array<Eigen::Vector2d, 33> hull;  // Andrew's monotone chain, counter-clockwise
  std::size_t k = 0;
  for (std::size_t m = 0; m < n; ++m) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[m]) <= 0.0) --k;
    hull[k++] = p[m];
  }
  for (std::size_t m = n - 1, lower = k + 1; m-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[m]) <= 0.0) --k;
    hull[k++] = p[m];
  }
  if (k < 4) return false;  // fewer than three corners: a point or a line
  const Eigen::Vector2d c(u.dot(point), w.dot(point));
  for (std::size_t m = 0; m + 1 < k; ++m)
    if (cross(hull[m], hull[m + 1], c) < 0.0) return false;
  return true;
}

// The hulls' boxes in one frame (coordinates r^T x), the axis on which they are farthest apart
// and by how much (< 0: they overlap on every axis), and whether A's lies on its + side.
struct HoldFrame {
  Mat3 r = Mat3::Identity();
  Aabb a, b;
  int axis = 0;
  double gap = -std::numeric_limits<double>::infinity();
  bool aAbove = false;
};
HoldFrame holdFrame(const Mat3& r, const Aabb& a, const Aabb& b) {
  HoldFrame f{r, a, b};
  for (int k = 0; k < 3; ++k) {
    const double above = a.min[k] - b.max[k], below = b.min[k] - a.max[k];
    if (std::max(above, below) > f.gap) {
      f.gap = std::max(above, below);
      f.axis = k;
      f.aAbove = above >= below;
    }
  }
  return f;
}

// Whether a rotation's axes are the world's, up to order and sign (its frame finds what the
// world's does).
bool alongWorldAxes(const Quat& q) {
  const Mat3 r = q.toRotationMatrix();
  for (int k = 0; k < 3; ++k)
    if (r.col(k).cwiseAbs().maxCoeff() < 1.0 - 1e-9) return false;
  return true;
}

// The frame of the pair's hold: the world's axes with the cached hull boxes; where those overlap
// on every axis, a turned immovable body's own axes, in which its box is its hull's (a slope's
// face, a tilted wall's), if they find a wider gap. (A slope's world box holds whatever rests on
// it, so a small box sliding down a slope at 16 tests per frame was never held, turned off its
// roots' one contact and went through. A moving body's own axes were tried too: they held the
// boxes of a 1 mm pile in turned frames that turn with them, and one of them was pressed 40 % of
// its diagonal into the ground, seed 1404's pile, where the world's axes had held it.)
HoldFrame chooseHoldFrame(const Body& a, const Body& b, double overlapAllowed) {
  HoldFrame best = holdFrame(Mat3::Identity(), hullBox(a), hullBox(b));
  if (best.gap >= -overlapAllowed) return best;
  for (const Body* own : {&b, &a}) {
    if (own->invMass > 0.0 || alongWorldAxes(own->q)) continue;
    const Pose pose = own->pose();
    const Mat3 r = pose.rotation.toRotationMatrix();
    Aabb mine = own->hullLocalBox;
    mine.min += r.transpose() * pose.translation;
    mine.max += r.transpose() * pose.translation;
    const Aabb other = hullBoxAlong(own == &a ? b : a, r);
    const HoldFrame f = own == &a ? holdFrame(r, mine, other) : holdFrame(r, other, mine);
    if (f.gap > best.gap) best = f;
  }
  return best;
}

bool holdAtBoxes(const Body& a, const Body& b, double sinkAllowed, std::vector<SolverContact>& out) {
  if (a.invMass == 0.0 && b.invMass == 0.0) return false;
  const double diag = std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
  const HoldFrame f = chooseHoldFrame(a, b, kHoldOverlapRel * diag);
  if (!(f.gap >= -kHoldOverlapRel * diag)) return false;
  const int axis = f.axis;
  const Aabb &ba = f.a, &bb = f.b;  // in frame coordinates
  const std::size_t first = out.size();
  const bool alongside = !out.empty();
  const double sign = f.aAbove ? 1.0 : -1.0;  // the normal's sign along the axis
  const Vec3 n = sign * f.r.col(axis);         // out of B toward A, in the world
  const double faceA = f.aAbove ? ba.min[axis] : ba.max[axis];  // A's box face toward B
  const double faceB = f.aAbove ? bb.max[axis] : bb.min[axis];  // B's box face toward A
  const bool worldFrame = f.r == Mat3::Identity();
  // Each moving body's support points toward the other box's face (alongside an answer, also
  // tilted toward the four sides).
  const std::size_t directions = alongside ? 5 : 1;
  auto supportsOf = [&](const Body& body, double toward, std::size_t count) {
    return worldFrame ? hullSupports(body, axis, toward, count)
                      : supportPoints(body, holdDirections(f.r, axis, toward), count);
  };
  // Beside contacts that a moving body's centre of mass rests within, that body needs no hold:
  // they hold it -- unless its hull reaches past the other box's face by more than `sinkAllowed`
  // all the same (its lowest point, support[0]): then the answer's points are not where it
  // rests. A box thrown at the floor at 16 tests per frame rested on D&O points of its level-1
  // spheres, above the floor and around its centre of mass, and turned about them until a corner
  // was 18-22 % of its diagonal below the floor (dos and average; the boxes then overlap on every
  // axis, where no hold is made).
  auto restsOnContacts = [&](const Body& body, double outward, double faceOther) {
    if (!withinContacts(out, body.x, f.r, axis)) return false;
    const Vec3 lowest = supportsOf(body, -outward, directions)[0];  // all five: the hold below needs them
    return outward * ((f.r.transpose() * lowest)[axis] - faceOther) >= -sinkAllowed;
  };
  if (alongside && (a.invMass == 0.0 || restsOnContacts(a, sign, faceB)) && (b.invMass == 0.0 || restsOnContacts(b, -sign, faceA)))
    return false;
  // A contact between onA and onB (frame coordinates), one of them on `face`'s box face. That
  // face is there only within its box: a point past it (a box's corner past a table's edge) is
  // not held, or the hold would be a table the box tips over onto.
  auto hold = [&](const Vec3& onA, const Vec3& onB, const Aabb& face) {
    for (const int k : {(axis + 1) % 3, (axis + 2) % 3})
      if (onA[k] < face.min[k] || onA[k] > face.max[k]) return;
    const Vec3 worldA = f.r * onA, worldB = f.r * onB;
    for (std::size_t k = first; k < out.size(); ++k)  // the same point found along two directions
      if ((out[k].c.point - 0.5 * (worldA + worldB)).squaredNorm() <= 1e-18 * diag * diag) return;
    SolverContact cp;
    cp.c.normal = n;
    cp.c.point = 0.5 * (worldA + worldB);
    cp.c.depth = (worldB - worldA).dot(n);
    // Boxes that overlap a little (bodies resting, or sunk within the slop) are held, not pushed.
    cp.c.errorBound = std::max(0.0, cp.c.depth);
    cp.c.featureKind = ContactFeature::kNone;
    cp.hold = true;
    cp.anchorA = a.q.conjugate() * (worldA - a.x);
    cp.anchorB = b.q.conjugate() * (worldB - b.x);
    out.push_back(cp);
  };
  if (!alongside) {
    Vec3 onA = 0.5 * (ba.min.cwiseMax(bb.min) + ba.max.cwiseMin(bb.max));  // across the axis
    Vec3 onB = onA;
    onA[axis] = faceA;
    onB[axis] = faceB;
    hold(onA, onB, bb);
  }
  // A support point past the other box's face across the axis is moved onto the face's nearest
  // point, and the body's surface above it taken where it is known (a convex body's face planes):
  // there the face ends, at the edge a box overhanging a table's pivots on. (The hull's corner
  // past the edge says nothing: a box turning off a coarse contact inside the edge, with its
  // centre of mass between that contact and the edge, fell off the table.)
  auto onFaceOf = [&](const Body& body, const Vec3& support, const Aabb& face, const Vec3& toward) -> std::optional<Vec3> {
    Vec3 p = f.r.transpose() * support;
    bool past = false;
    for (const int k : {(axis + 1) % 3, (axis + 2) % 3}) {
      const double inside = std::clamp(p[k], face.min[k], face.max[k]);
      past = past || inside != p[k];
      p[k] = inside;
    }
    if (!past) return p;
    const std::optional<Vec3> surface = firstPointAlong(body, f.r * p, toward);
    if (!surface) return std::nullopt;
    return f.r.transpose() * *surface;
  };
  if (a.invMass > 0.0) {
    const std::array<Vec3, 5> supports = supportsOf(a, -sign, directions);
    for (std::size_t k = 0; k < directions; ++k) {
      const std::optional<Vec3> onA = onFaceOf(a, supports[k], bb, n);
      if (!onA) continue;
      Vec3 onB = *onA;
      onB[axis] = faceB;
      hold(*onA, onB, bb);
    }
  }
  if (b.invMass > 0.0) {
    const std::array<Vec3, 5> supports = supportsOf(b, sign, directions);
    for (std::size_t k = 0; k < directions; ++k) {
      const std::optional<Vec3> onB = onFaceOf(b, supports[k], ba, -n);
      if (!onB) continue;
      Vec3 onA = *onB;
      onA[axis] = faceA;
      hold(onA, *onB, ba);
    }
  }
  return out.size() > first;
}

// holdAtBoxes for a pair, each new hold warm-started with the impulses of last substep's hold at
// its point. A hold lives one substep; without them a box at rest over a table's edge, whose
// coarse contacts (warm-started) lie inside the edge and whose centre of mass lies beyond them,
// met its edge hold at zero impulse every substep, and the iterations left it turning outward a
// little each time until it fell.
bool holdPair(PairState& p, const Body& a, const Body& b, double sinkAllowed) {
  const std::size_t first = p.contacts.size();
  if (!holdAtBoxes(a, b, sinkAllowed, p.contacts)) return false;
  const double near = 1e-3 * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
  for (std::size_t k = first; k < p.contacts.size(); ++k) {
    SolverContact& cp = p.contacts[k];
    for (SolverContact& old : p.heldBefore)
      if (!old.matched && old.c.normal.dot(cp.c.normal) > 0.999 && (old.c.point - cp.c.point).squaredNorm() <= near * near) {
        old.matched = true;
        cp.lambdaN = old.lambdaN;
        cp.frictionImpulse = old.frictionImpulse;
        break;
      }
  }
  return true;
}

// The plane in which a patch pair's bodies touch, for patch friction (patchCentre in solve): where
// their hull boxes meet on the hold frame's axis (chooseHoldFrame), midway between the two faces,
// when that axis is within 30 deg of the patch's normal and the boxes do not interlock (overlap by
// at most kHoldOverlapRel of the smaller diagonal). Else none, and the friction acts at the load's
// centre itself.
void patchInterface(PairState& p, const Body& a, const Body& b) {
  const double diag = std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
  const HoldFrame f = chooseHoldFrame(a, b, kHoldOverlapRel * diag);
  const Vec3 u = f.r.col(f.axis);
  p.patchHasInterface = f.gap >= -kHoldOverlapRel * diag && std::abs(u.dot(p.patchNormal)) >= 0.8660254037844386;
  if (!p.patchHasInterface) return;
  const double faceA = f.aAbove ? f.a.min[f.axis] : f.a.max[f.axis];
  const double faceB = f.aAbove ? f.b.max[f.axis] : f.b.min[f.axis];
  p.patchInterfaceAxis = u;
  p.patchInterfaceAt = 0.5 * (faceA + faceB);
}

// One step of a two-axis dissipative constraint in the plane (u1, u2): an impulse against the
// velocity (v1, v2) that stops its component along that velocity -- its size 1 / (d^T K d) per
// unit speed, d the velocity's direction, K the constraint's 2 x 2 inverse mass -- added to the
// accumulated impulse (l1, l2), and the sum clamped to the disc of radius `limit`. Why the step
// is along the velocity: projected iterations settle where the step is parallel to the
// accumulated impulse, so a slipping constraint's impulse ends anti-parallel to its velocity
// (Coulomb's maximal dissipation). A step scaled per axis (mass_1 v1, mass_2 v2) settles parallel
// to that scaled velocity instead, and a box whose corners have different tangent masses (any box
// sliding off the world axes) was pushed sideways and spun: it slid 7 % too far and turned 5 deg
// off its heading. Clamping each axis on its own (a friction pyramid) is worse still: up to sqrt 2
// times the limit, along the diagonal. Returns false when there is nothing to stop.
bool coneStep(double& l1, double& l2, double v1, double v2, const TangentInverseMass& k, double limit) {
  const double speedSq = v1 * v1 + v2 * v2;
  const double kAlong = speedSq > 0.0 ? (v1 * (k.k11 * v1 + k.k12 * v2) + v2 * (k.k12 * v1 + k.k22 * v2)) / speedSq : 0.0;
  if (!(kAlong > 0.0)) return false;  // no motion, or nothing that can move
  l1 -= v1 / kAlong;
  l2 -= v2 / kAlong;
  const double length = std::hypot(l1, l2);
  if (length > limit) {
    const double scale = limit > 0.0 ? limit / length : 0.0;
    l1 *= scale;
    l2 *= scale;
  }
  return true;
}

// One friction update of a contact (coneStep on its tangents t1, t2 with the Coulomb cone
// |lambdaT| <= limit, mu times the normal impulse). Returns the impulse change (world).
Vec3 frictionStep(SolverContact& cp, double v1, double v2, const TangentInverseMass& k, double limit) {
  const double old1 = cp.lambdaT1, old2 = cp.lambdaT2;
  if (!coneStep(cp.lambdaT1, cp.lambdaT2, v1, v2, k, limit)) return Vec3::Zero();
  return (cp.lambdaT1 - old1) * cp.t1 + (cp.lambdaT2 - old2) * cp.t2;
}

void tangents(const Vec3& n, Vec3& t1, Vec3& t2) {
  // Any unit vector orthogonal to n, chosen from the axis least aligned with n (stable).
  const Vec3 a = std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : (std::abs(n.y()) < 0.57735 ? Vec3::UnitY() : Vec3::UnitZ());
  t1 = n.cross(a).normalized();
  t2 = n.cross(t1);
}

// K in the tangent plane (t1, t2) for the given total inverse mass and lever arms r with their
// bodies' world inverse inertia: k_ij = invMass t_i . t_j + sum (r x t_i) . I^-1 (r x t_j).
struct LeverArm {
  Vec3 r;
  const Mat3* invInertia;
};
TangentInverseMass tangentInverseMass(double invMass, const Vec3& t1, const Vec3& t2, std::initializer_list<LeverArm> arms) {
  TangentInverseMass k{invMass, 0.0, invMass};
  for (const LeverArm& arm : arms) {
    const Vec3 r1 = arm.r.cross(t1), r2 = arm.r.cross(t2);
    const Vec3 i1 = *arm.invInertia * r1, i2 = *arm.invInertia * r2;
    k.k11 += r1.dot(i1);
    k.k12 += r1.dot(i2);
    k.k22 += r2.dot(i2);
  }
  return k;
}

// Outward unit direction of body `fixed`'s oriented bounding box (its mesh bounds, turned and
// placed with the body) from the box point nearest `p` to `p`; zero for p inside the box.
Vec3 outwardFromBox(const Body& fixed, const Vec3& p) {
  const Vec3 local = fixed.q.conjugate() * (p - fixed.x) + fixed.comLocal;  // mesh coordinates
  const Vec3 d = local - local.cwiseMax(fixed.localBox.min).cwiseMin(fixed.localBox.max);
  const double length = d.norm();
  return length > 0.0 ? Vec3(fixed.q * (d / length)) : Vec3::Zero();
}

// Patch friction (docs/dynamics.md, "Patch friction"). A pair's contacts are one patch when their
// normals agree within kPatchConeCos; they stand for it rather than lie on it when every contact
// of the answer (the holds aside) is a sphere pair's (ContactFeature::kSphere) and coarse, its
// error bound above `coarseAbove`: a coarse level's points (D&O points between bounding spheres,
// deep inside both bodies) say that the surfaces touch, not where. Friction at such points is a
// force wherever they are not symmetric about the load: a box spinning on the floor on the D&O
// points of its level-1 spheres was pushed 8-20 cm aside while it stopped (dos and average at 16
// tests per frame). (A contact tree's coarse sample lies on one body's surface, where the
// projection put it; its bound is its depth's. Its contacts keep their own friction.)
constexpr double kPatchConeCos = 0.99984769515639127;  // cos 1 deg
bool standsForAPatch(const std::vector<SolverContact>& contacts, double coarseAbove) {
  if (contacts.empty()) return false;
  const Vec3& n = contacts.front().c.normal;
  bool coarse = false;
  for (const SolverContact& cp : contacts) {
    if (cp.c.normal.dot(n) < kPatchConeCos) return false;
    if (cp.hold) continue;
    if (cp.c.featureKind != ContactFeature::kSphere || !(cp.c.errorBound > coarseAbove)) return false;
    coarse = true;
  }
  return coarse;
}

}  // namespace

struct World::Impl {
  WorldSettings settings;
  std::vector<Body> bodies;
  std::map<std::uint64_t, PairState> pairs;  // ordered: deterministic iteration
  StepReport report;
  std::vector<Aabb> boxes;
  std::vector<std::uint8_t> active;
  std::vector<BodyPair> candidates;
  std::size_t stepPairs = 0;  // broad-phase pairs of the step's boxes (grown by its travel)
  BroadPhaseScratch bpScratch;
  QueryScratch scratch;
  QueryResult result;
  detail::ContainmentScratch fieldScratch;  // exact-field queries: putContactsOnBall, supports' normals
  std::vector<std::pair<PairState*, std::array<BodyId, 2>>> order;
  std::vector<std::pair<PairState*, std::array<BodyId, 2>>> solveOrder;
  std::vector<Vec3> savedV, savedW, dV, dW;
  std::map<std::uint64_t, PairReport> pairReports;
  std::uint32_t velocityIterationsNow = 20;
  bool impactNow = false;  // whether a pair of solveOrder has an impact (PairState::impact)
  // Narrow-phase microseconds per budget unit (test or charged frontier pair), measured with
  // WorldSettings::clock over the time-budgeted steps (exponential average); converts
  // WorldSettings::budgetMicros to units. Starts at 0.5: the 200-body bin's cfm and exact rows
  // at 1,024 tests took 0.54 / 0.77 ms of narrow phase per frame (docs/benchmarks/world.md).
  double microsPerUnit = 0.5;
  std::vector<double> stepTravel;
  // Each shape's hull points, shared by its bodies; the map keeps the shape alive, so an address
  // is never reused by another shape while its entry lives.
  std::map<std::shared_ptr<const CollisionBody>, std::unique_ptr<const detail::HullPoints>> hulls;
  const detail::HullPoints* hullPointsOf(const std::shared_ptr<const CollisionBody>& shape) {
    auto& entry = hulls[shape];
    if (!entry) entry = std::make_unique<const detail::HullPoints>(*shape);
    return entry.get();
  }

  // How far a body may reach into the other's hull box beside an interrupted answer before it is
  // held there (holdAtBoxes): the slop, the depth the solver leaves in place anyway.
  double sinkAllowed(const Body& a, const Body& b) const {
    return settings.slopRel * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
  }

  // The broad phase, refused past WorldSettings::maxPairs before the pairs' state is allocated.
  void findPairsWithinLimit(const std::vector<Aabb>& bodyBoxes, const std::vector<std::uint8_t>& isActive,
                            std::vector<BodyPair>& out) {
    const std::uint64_t limit = settings.maxPairs;
    if (!findOverlappingPairs(bodyBoxes, isActive.data(), out, bpScratch,
                              static_cast<std::size_t>(std::min<std::uint64_t>(limit, SIZE_MAX)))) {
      out.clear();
      throw Error(ErrorCode::kResourceLimit, "the broad phase found more than " + std::to_string(limit) +
                                                 " overlapping body pairs (WorldSettings::maxPairs, scene key "
                                                 "\"max_pairs\"); are bodies piled at one point?");
    }
  }

  void validateSettings() const {
    const WorldSettings& s = settings;
    auto bad = [](const std::string& m) { throw Error(ErrorCode::kInvalidArgument, "world settings: " + m); };
    if (!finite(s.gravity)) bad("gravity must be finite");
    if (s.maxContacts == 0) bad("maxContacts must be >= 1");
    if (s.velocityIterations == 0) bad("velocityIterations must be >= 1");
    if (!(s.correctionFactor > 0.0 && s.correctionFactor <= 1.0)) bad("correctionFactor must be in (0, 1]");
    if (!(s.slopRel >= 0.0 && std::isfinite(s.slopRel))) bad("slopRel must be >= 0 and finite");
    if (!(s.rollingResistanceRel >= 0.0 && std::isfinite(s.rollingResistanceRel)))
      bad("rollingResistanceRel must be >= 0 and finite");
    if (!(s.reuseMotionRel >= 0.0 && s.reuseMotionRel < 1.0)) bad("reuseMotionRel must be in [0, 1)");
    if (!(s.restitutionThreshold >= 0.0 && std::isfinite(s.restitutionThreshold))) bad("restitutionThreshold must be >= 0");
    if (!(s.convergenceRel >= 0.0)) bad("convergenceRel must be >= 0");
    if (s.maxSubsteps == 0) bad("maxSubsteps must be >= 1");
    if (s.minSubsteps == 0 || s.minSubsteps > s.maxSubsteps) bad("minSubsteps must be in [1, maxSubsteps]");
    if (s.frontierPairCost > 1024) bad("frontierPairCost must be in [0, 1024]");
    if (!(s.budgetMicros >= 0.0 && std::isfinite(s.budgetMicros))) bad("budgetMicros must be >= 0 and finite");
    if (s.clock == nullptr) bad("clock must not be null");
    if (s.maxPairs == 0) bad("maxPairs must be >= 1");
  }

  // limited == false: unlimited budget; else at most `allowance` budget units this substep (0:
  // none), except that a sphere-model pair may borrow from the rest of the step (`stepLeft`
  // units, allowance included) the tests one expansion, or a re-test, of its front needs; the
  // later substeps' allowances shrink by as much. `nominal` = ceil(budget / substeps), a
  // substep's even share of the step; `substepsLeft` of the step's substeps are left, this one
  // included.
  // timeAllowance: narrow-phase seconds this substep may take (WorldSettings::budgetMicros);
  // negative = no time limit.
  void substep(double h, bool limited, std::uint64_t allowance, std::uint64_t stepLeft, std::uint64_t nominal,
               std::uint32_t substepsLeft, double timeAllowance);
  void solve(double h);
  // Shock propagation (docs/dynamics.md, "Mass ratios"): support layers of the bodies over this
  // substep's contact graph and the pairs between different layers, bottom-up.
  void orderSupportLayers();
  std::vector<std::uint32_t> supportLayer, layerQueue, adjacencyStart, adjacency;
  std::uint32_t tallestSupport = 0;  // the highest support layer of the last substep (World::step)
  std::vector<std::uint8_t> carries;  // a body is the lower one of some pair between two layers
  std::vector<std::uint32_t> shockPairs;  // indices into solveOrder, by lower layer
  void persistContacts(PairState& p, const Body& a, const Body& b, double diag);
  bool keepFinerManifold(PairState& p, const Body& a, const Body& b, double drift, double slop);
  double arrivalTravel(const BodyPair& c, double dt) const;
  bool reuseManifold(const PairState& p, const Body& a, const Body& b) const;
  double motionSinceQuery(const PairState& p, const Body& a, const Body& b) const;
  void forgetPairsApart();
  double reachSinceQuery(const PairState& p, const Body& a, const Body& b) const;
  double reachSince(const Pose& bInAThen, const Body& a, const Body& b) const;
  void carryValidContacts(PairState& p, const Body& a, const Body& b, double matchDistance, double drift);
  void reduceCarried(std::vector<SolverContact>& contacts, std::size_t keep);
  std::vector<double> spread;  // reduceCarried's farthest-point distances
  std::vector<double> supportRoom;  // carryValidContacts' support polygon of the fresh contacts
  double kineticEnergyOfDynamicBodies() const;
  // Second-order positions along the directions no contact constrains (integrate): each body's
  // velocity at the start of the substep, and an orthonormal basis of its pressing or touching
  // contacts' normals.
  std::vector<Vec3> substepStartVelocity;
  // Per body, the velocity change this substep's normal impulses made (integrate keeps it out of
  // the trapezoid).
  std::vector<Vec3> normalVelocityChange;
  std::vector<std::array<Vec3, 3>> pressedNormals;
  std::vector<std::uint8_t> pressedNormalCount;
  std::vector<std::uint8_t> sticking;  // per body: a pressed contact inside its friction cone
  void collectPressedNormals();
  void integrate(double h);
  void checkFinite() const;

  // World editing and queries (world.h: removeBody ... separation; defined at the end of this
  // file). filtering: a body was removed or given a filter, so filterCandidates has work to do.
  bool filtering = false;
  bool forcesPending = false;
  ContactCallback contactCallback;
  std::vector<std::uint64_t> disabledPairs;  // sorted pair keys the callback disabled this step
  std::vector<Contact> callbackContacts;
  std::uint32_t substepIndex = 0;
  struct ScaledShape {
    std::shared_ptr<const CollisionBody> source;  // kept: the key's pointer cannot be reused
    double scale = 1.0;
    std::shared_ptr<const CollisionBody> scaled;
  };
  std::vector<ScaledShape> scaledShapes;
  mutable detail::SeparationHeap separationHeap;  // separation()'s working memory
  void filterCandidates(std::vector<BodyPair>& pairs) const;
  void applyExternalForces(double h);
  void runContactCallback();
  void forgetPairsOf(BodyId id);
  void beginStep();
  void endStep();
};

World::World(const WorldSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
  impl_->validateSettings();
}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

BodyId World::addBody(const RigidBodyDesc& d) {
  const std::string who = "body " + std::to_string(impl_->bodies.size()) + " '" + d.name + "': ";
  auto bad = [&](const std::string& m) { throw Error(ErrorCode::kInvalidArgument, who + m); };
  if (!d.shape) bad("no collision shape");
  if (!(d.restitution >= 0.0 && d.restitution <= 1.0)) bad("restitution must be in [0, 1]");
  if (!(d.friction >= 0.0 && std::isfinite(d.friction))) bad("friction must be >= 0 and finite");
  if (!finite(d.position) || !finite(d.velocity) || !finite(d.angularVelocity) || !d.orientation.coeffs().allFinite() ||
      !finite(d.centerOfMass))
    bad("state must be finite");
  if (!(d.ballRadius >= 0.0 && std::isfinite(d.ballRadius))) bad("ballRadius must be >= 0 and finite");
  if (d.ballRadius > 0.0) requireBallHull(d, bad);
  const Quat& q = d.orientation;
  const std::optional<Quat> orientation = unitQuaternion(q.w(), q.x(), q.y(), q.z());
  if (!orientation) bad("orientation quaternion is zero");
  Body b;
  b.desc = d;
  b.type = d.type;
  b.comLocal = d.centerOfMass;
  b.q = *orientation;
  b.desc.orientation = b.q;
  b.x = d.position + b.q * b.comLocal;
  b.localBox = d.shape->mesh().bounds();
  b.hullPoints = impl_->hullPointsOf(d.shape);
  b.hullLocalBox = hullBoxInMesh(*b.hullPoints, *d.shape);
  b.facePlaneCount = convexFacePlanes(*d.shape, b.facePlanes);
  b.minExtent = b.localBox.extent().minCoeff();
  b.frameReach = b.localBox.min.cwiseAbs().cwiseMax(b.localBox.max.cwiseAbs()).norm();
  for (std::uint32_t n : d.shape->sphereTree().childCount) b.maxChildren = std::max(b.maxChildren, n);
  if (d.type == BodyType::kDynamic) {
    if (!(d.mass > 0.0 && std::isfinite(d.mass))) bad("mass must be > 0 and finite");
    if (!d.inertia.allFinite()) bad("inertia must be finite");
    Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (d.inertia + d.inertia.transpose()));
    if (eig.eigenvalues().minCoeff() <= 0.0) bad("inertia must be positive definite");
    b.invMass = 1.0 / d.mass;
    b.inertiaLocal = d.inertia;
    b.invInertiaLocal = d.inertia.inverse();
  }
  if (d.type != BodyType::kStatic) {
    b.v = d.velocity;
    b.w = d.angularVelocity;
  }
  b.invInertiaWorld = worldInverseInertia(b.invInertiaLocal, b.q);
  impl_->bodies.push_back(std::move(b));
  return BodyId(impl_->bodies.size() - 1);
}

// Pairs that left the broad phase this substep lose their contacts (they are not solved), and
// their coherence caches too once their boxes are kPairKeepGapRel of the smaller diagonal apart
// or the bodies have moved that far against each other since the last query (the cached front
// describes the pose it was tested at: a body that bounced away and back in a pile is answered
// afresh from the roots, as before).
// Before, a pair was forgotten the substep it left: a 1 kg box on the ground that hopped a
// fraction of a millimetre just as a 100 kg box landed on it came back with its front at the
// roots, whose expansion (1 + 8 sphere tests) its 4-8 tests per substep at 16 tests per frame
// never covered, and the one D&O contact under its centre let the heavy box tip off it (dos and
// average; WorldMassRatio.SphereModelsKeepAHeavyBoxOnALightOneAtLimitedBudgets). Filtered pairs
// (their boxes still overlap) are forgotten at once, as are pairs of removed bodies.
void World::Impl::forgetPairsApart() {
  for (auto it = pairs.begin(); it != pairs.end();) {
    PairState& p = it->second;
    if (p.seen) {
      ++it;
      continue;
    }
    const std::size_t ia = it->first >> 32, ib = it->first & 0xffffffffu;  // pairKey's halves
    const Body& a = bodies[ia];
    const Body& b = bodies[ib];
    const Aabb& ba = boxes[ia];
    const Aabb& bb = boxes[ib];
    const double gap = std::max((ba.min - bb.max).maxCoeff(), (bb.min - ba.max).maxCoeff());
    const double near = kPairKeepGapRel * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
    if (gap > 0.0 && gap < near && motionSinceQuery(p, a, b) < near) {
      p.contacts.clear();
      p.previous.clear();
      p.reusable = false;
      ++it;
    } else {
      it = pairs.erase(it);
    }
  }
}

void World::Impl::checkFinite() const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    if (!finite(b.x) || !finite(b.v) || !finite(b.w) || !b.q.coeffs().allFinite())
      throw Error(ErrorCode::kSimulationDiverged,
                  "body " + std::to_string(i) + " '" + b.desc.name + "': state became NaN or infinite");
  }
}

void World::Impl::substep(double h, bool limited, std::uint64_t allowance, std::uint64_t stepLeft,
                          std::uint64_t nominal, std::uint32_t substepsLeft, double timeAllowance) {
  const WorldSettings& s = settings;
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  const auto tBroad = Clock::now();
  // Gravity first (semi-implicit Euler: the solver then sees the velocity contacts must stop).
  substepStartVelocity.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) substepStartVelocity[i] = bodies[i].v;
  for (Body& b : bodies)
    if (b.type == BodyType::kDynamic) b.v += s.gravity * h;
  applyExternalForces(h);

  // Broad phase: boxes grown by the distance a body moves this substep (speculative margin).
  boxes.resize(bodies.size());
  active.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const double reach = b.w.norm() * 0.5 * b.localBox.diagonal();
    boxes[i] = b.worldBox((b.v.norm() + reach) * h);
    active[i] = b.type == BodyType::kDynamic;
  }
  findPairsWithinLimit(boxes, active, candidates);
  filterCandidates(candidates);
  report.candidatePairs += candidates.size();

  for (auto& [key, p] : pairs) {
    p.seen = false;
    p.heldBefore.clear();
    if (p.holding) {  // a hold lasts one substep; it is no answer to keep
      for (const SolverContact& c : p.contacts)
        if (c.hold) {
          p.heldBefore.push_back(c);
          p.heldBefore.back().matched = false;
        }
      std::erase_if(p.contacts, [](const SolverContact& c) { return c.hold; });
    }
    p.holding = false;
  }
  order.clear();
  for (const BodyPair& c : candidates) {
    PairState& p = pairs[pairKey(c[0], c[1])];
    p.seen = true;
    p.fresh = false;
    order.push_back({&p, {c[0], c[1]}});
  }
  forgetPairsApart();

  // Budget division: round robin over staleness, then priority; stable on the pair order.
  std::stable_sort(order.begin(), order.end(), [](const auto& l, const auto& r) {
    if (l.first->stale != r.first->stale) return l.first->stale > r.first->stale;
    return l.first->priority > r.first->priority;
  });
  std::uint64_t remaining = allowance;
  std::size_t left = order.size();
  // What a pair may borrow from the later substeps: their units, less one test per substep for
  // each other pair the step may meet (its broad phase ran on boxes grown by the step's travel),
  // so that no pair goes unqueried for the rest of the step: a light box falling onto a heavy one
  // was skipped while the heavy one's ground pair borrowed the step, and sank 18 % of its side
  // into it (16 tests per frame, 1 cm boxes; 46 % with 1 mm boxes at 256 tests).
  const std::uint64_t laterReserve =
      std::uint64_t(substepsLeft - 1) * (std::max(order.size(), stepPairs) - std::min<std::size_t>(1, order.size()));
  std::uint64_t borrowable = stepLeft - std::min(stepLeft, allowance + laterReserve);
  const std::uint64_t cacheShare = std::max<std::uint64_t>(1, s.maxCachedNodePairs / std::max<std::size_t>(1, left));
  // The contact tree samples every cell pair of its answer frontier, cfm looks up both maps and
  // runs a separating-axis test per frontier sphere pair, and exact does the latter for the pairs
  // an interrupted query did not triangle-test: each frontier pair costs `perCell` budget units
  // (world.h). A query's frontier is at most max(F, T) pairs for a cached front of F pairs (F = 1
  // from the roots) and T tests: a retest keeps or drops a cached pair, and an expansion replaces
  // one pair by at most as many children as it made tests (an interrupted expansion keeps the
  // pair whole). So T is chosen with T + perCell * max(F, T) <= what the pair may spend.
  // dos and average answer one contact per frontier sphere pair (not charged; they need expansions).
  const bool sphereTreeModel = s.model == ContactModel::kDos || s.model == ContactModel::kAverage;
  const std::uint64_t perCell = sphereTreeModel ? 0 : s.frontierPairCost;
  QuerySettings qs;
  qs.model = s.model;
  qs.maxContacts = s.maxContacts;
  qs.maxLevel = s.maxLevel;
  report.broadPhaseSeconds += since(tBroad);
  const auto t0 = Clock::now();
  // Time budget (WorldSettings::budgetMicros): the step converted it to budget units; as a
  // backstop, no query starts after this substep's share of the time is gone.
  const bool timed = timeAllowance >= 0.0;
  const QueryBudget::TimePoint tTimed = timed ? s.clock() : QueryBudget::TimePoint{};
  const QueryBudget::TimePoint substepDeadline =
      timed ? tTimed + std::chrono::duration_cast<QueryBudget::Clock::duration>(
                           std::chrono::duration<double>(std::min(timeAllowance, 3600.0)))
            : QueryBudget::TimePoint::max();
  bool timeUp = false;
  for (auto& [p, ids] : order) {
    Body& a = bodies[ids[0]];
    Body& bb = bodies[ids[1]];
    PairReport& pr = pairReports[pairKey(ids[0], ids[1])];
    pr.a = ids[0];
    pr.b = ids[1];
    // A skipped pair keeps its contacts and is ranked first next substep (stale).
    auto skip = [&] {
      pr.skipped = true;
      ++report.pairsSkipped;
      ++p->stale;
      --left;
      if (p->contacts.empty() || p->interrupted) p->holding = holdPair(*p, a, bb, sinkAllowed(a, bb));
    };
    // Proven apart (QueryResult::separation, proveApart): no query, no budget, no contacts.
    auto provenApart = [&] {
      pr.provenApart = true;
      pr.skipped = pr.reused = false;
      ++report.pairsProvenApart;
      p->stale = 0;
      --left;
    };
    // While no point of B can have moved against A by the gap the last query proved, the
    // surfaces are still that far apart -- and under a time budget the pair needs no roots'
    // answer either (it cannot be arriving). In a pile most broad-phase pairs are neighbours a
    // little apart, and each was answered every substep.
    if (p->contacts.empty() && p->apartBy > 0.0 && reachSinceQuery(*p, a, bb) < p->apartBy) {
      provenApart();
      continue;
    }
    pr.provenApart = false;
    // What a pair's answer (`result`) leaves: its budget charged, the report, the pair's state
    // and its new contacts (the persistent manifold merges them below).
    auto recordAnswer = [&](std::uint64_t offeredShare) {
      // WorldSettings::maxCachedNodePairs: a new cache, not clear(), which would keep the memory.
      if (p->cache.frontSize() > cacheShare) p->cache = CoherenceCache();
      // Charged as far as the substep has it left (only the roots' answer above may cost more).
      const std::uint64_t fullCost = result.tests + perCell * result.frontier.size();
      const std::uint64_t cost = limited ? std::min(remaining, fullCost) : fullCost;
      report.unitsWorked += fullCost;
      remaining -= cost;
      report.budgetSpent += cost;
      report.testsSpent += result.tests;
      report.frontierPairs += result.frontier.size();
      report.rawContacts += result.rawContacts;
      pr.tests += result.tests;
      pr.level = result.maxLevel;
      pr.finished = result.finished;
      pr.fallbackPairs = result.fallbackPairs;
      report.fallbackPairs += result.fallbackPairs;
      pr.skipped = false;
      pr.reused = false;
      if (!result.finished) ++report.pairsInterrupted;
      p->interrupted = !result.finished;
      // Only a finished answer with contacts is reused: an empty one says nothing about how near
      // the bodies are, and a new contact region could open within any motion.
      p->reusable = result.finished && !result.contacts.empty() && s.reuseMotionRel > 0.0;
      p->apartBy = result.separation;
      p->queriedAt = a.pose().inverse() * bb.pose();
      p->share = offeredShare;
      p->keptFiner = false;
      p->stale = 0;
      p->fresh = true;
      p->previous.swap(p->contacts);
      p->contacts.clear();
      if ((a.desc.ballRadius > 0.0) != (bb.desc.ballRadius > 0.0)) {
        // A ball's contacts are the ball's, not its polyhedron's (docs/dynamics.md, "Balls").
        const bool ballIsA = a.desc.ballRadius > 0.0;
        const Body& ball = ballIsA ? a : bb;
        const Body& other = ballIsA ? bb : a;
        const std::uint32_t fieldQueries = detail::putContactsOnBall(
            result.contacts, ball.pose().translation, ball.desc.ballRadius, ballIsA, *other.desc.shape, other.pose(), fieldScratch);
        report.testsSpent += fieldQueries;
        report.unitsWorked += fieldQueries;
        pr.tests += fieldQueries;
      }
      for (const Contact& c : result.contacts) {
        SolverContact cp;
        cp.c = c;
        p->contacts.push_back(cp);
      }
    };
    if (a.desc.ballRadius > 0.0 && bb.desc.ballRadius > 0.0) {
      // Two balls: one exact contact, one test, no query (docs/dynamics.md, "Balls").
      detail::ballBallAnswer(a.pose().translation, a.desc.ballRadius, bb.pose().translation, bb.desc.ballRadius, result);
      recordAnswer(0);
      --left;
      continue;
    }
    // A pair's even share of what the substep has left (limited budgets).
    const std::uint64_t evenShare = limited ? std::max<std::uint64_t>(1, remaining / left) : 0;
    // A manifold is reused while the bodies have not moved against each other and a new query
    // could not do better: the last one finished, or it was interrupted at a share at least as
    // large as this one (a query is a function of the relative pose, the cached front and the
    // budget). A resting pair at a limited budget then stops re-deriving the same coarse answer
    // every substep -- a contact-tree stack at 1,024 tests per frame spent ~1 s of CPU per
    // simulated s doing so -- and the budget it leaves goes to the pairs that can use it, so a
    // resting pair is refined further whenever it is offered more than before.
    //
    // The sphere models (one contact per frontier sphere pair) may take beyond their even share
    // what re-testing their cached front and one expansion need, where the step has that left (what
    // this substep lacks is borrowed from the later ones): below it a query re-derives its last
    // answer. A root pair's expansion costs 1 + 8 tests; with 16 tests per frame, two pairs and
    // 20 substeps (a 1 cm stack at 60 Hz), the even shares were at most 8, and a 1 kg box stayed
    // on its ground pair's one D&O contact under its centre while a 1,000 kg box on it tipped
    // both through the ground (dos, average). Limited to the substep's own units, a bunny dropped
    // at 16 tests per frame met the ground in a step of 8 substeps (2 tests each) and turned 140
    // degrees about its root spheres' one contact; a 1 mm box sliding tipped over.
    // Short of that, it may take what re-testing its front needs: a query that re-tests part of
    // its front keeps the rest's statuses, and a box sliding down a slope at 16 tests per frame
    // passed over ground spheres its cache held apart, lost its leading contacts and tumbled.
    const std::uint64_t retestTests = std::max<std::uint64_t>(1, p->cache.frontSize());
    const std::uint64_t progressTests = retestTests + std::max(a.maxChildren, bb.maxChildren);
    std::uint64_t offered = evenShare;
    if (limited && sphereTreeModel) {
      // ... leaving one test to each pair after it in this substep.
      const std::uint64_t mayUse = remaining + borrowable;
      const std::uint64_t available = mayUse - std::min<std::uint64_t>(mayUse, left - 1);
      if (progressTests <= available) {
        offered = std::max(evenShare, progressTests);
      } else if (retestTests <= available) {
        offered = std::max(evenShare, retestTests);
      }
    }
    const bool improvable = p->interrupted && (!limited || offered > p->share);
    if ((p->reusable || (p->interrupted && !improvable && !p->contacts.empty() && s.reuseMotionRel > 0.0)) &&
        reuseManifold(*p, a, bb)) {
      pr.reused = true;
      pr.skipped = false;
      ++report.pairsReused;
      p->stale = 0;
      --left;
      // An interrupted answer carried on is held as when it was fresh (prepare): a box at rest
      // over a table's edge on its roots' contacts, held the substep they came and not the next,
      // turned off them and fell; a 1,000 : 1 plate of 1 mm on its thin edge on a light box
      // turned off its roots' one contact the same way (dos, average; seed 1429's `mass`).
      if (p->interrupted && !p->contacts.empty())
        p->holding = holdPair(*p, a, bb, sinkAllowed(a, bb));
      continue;
    }
    // Under a time budget a pair without contacts may be arriving (an empty answer, finished or
    // not, says nothing about the next substep), and skipping it leaves it without contacts while
    // it closes in: a mesh dropped at 60 Hz under 50 us per frame fell a whole frame into the
    // ground after the impact substep's one query used the frame's time. Such a pair is never
    // skipped but gets the roots' answer, whatever the substep has left: a time budget may run
    // over by one roots' answer per such pair and substep. (A test budget is a hard bound, and
    // its units are not an estimate: an equal share per substep reaches every arriving pair.)
    // So is a pair whose bodies have moved against each other since its last query by more than
    // the arrival rule lets them approach in a substep: its contacts describe where they were. A
    // bunny landing at 4 m/s under 50 us per frame at 60 Hz turned about its first contact for
    // 12 skipped substeps (the impact's answers had used the frame's time) and its other side
    // entered the floor 3.5 % of its diagonal, with every model.
    const double arrival = kArrivalTravelRel * std::min(a.desc.shape->diagonal(), bb.desc.shape->diagonal());
    const bool blind = timed && (p->contacts.empty() || motionSinceQuery(*p, a, bb) > arrival);
    if (blind && p->contacts.empty() && (!p->proofFailed || reachSince(p->proofFailedAt, a, bb) > arrival)) {
      // A pair without contacts under a time budget is answered whatever the budget has left (it
      // may be arriving); first try to prove it apart from the sphere-trees alone, which costs
      // ~1 us where the contact tree's roots' answer costs ~30: a pile's neighbours a little
      // apart were answered from the roots every substep (docs/dynamics.md, "Proven apart"). A
      // failed proof is not tried again before the pair has moved by the arrival travel (two
      // boxes 4 cm apart are closer than their leaf spheres are loose: 128 tests per substep
      // for nothing). Its tests are units of work like any test (the time conversion).
      std::uint64_t proofTests = 0;
      const double gap = proveApart(*a.desc.shape, a.pose(), *bb.desc.shape, bb.pose(), kProofTests, scratch, &proofTests);
      report.testsSpent += proofTests;
      report.unitsWorked += proofTests;
      p->proofFailed = !(gap > 0.0);
      if (p->proofFailed) p->proofFailedAt = a.pose().inverse() * bb.pose();
      if (gap > 0.0) {
        p->apartBy = gap;
        p->queriedAt = a.pose().inverse() * bb.pose();
        provenApart();
        continue;
      }
    }
    if (limited) {
      if (sphereTreeModel && offered > remaining) {
        // Borrowed: the step's later substeps get as much less (substepAllowance).
        const std::uint64_t borrowed = std::min(offered - remaining, borrowable);
        remaining += borrowed;
        borrowable -= borrowed;
      }
      if (remaining == 0 && !blind) {
        skip();
        continue;
      }
      // share >= 1 and share <= remaining, so the substep never spends more than its allowance
      // (and what it borrowed).
      std::uint64_t share = offered;
      if (perCell > 0) {
        // A cached front is an answer only where it is re-tested: an untested front pair keeps
        // last query's status (query.h), so a moving body sampled through a front it could not
        // re-test got the contacts of where it had been -- a spinning box on the bin's floor
        // re-sampled a 129-pair front with one test per substep, got no contact and fell
        // through. A pair therefore re-tests its whole front (T >= F) or starts from the roots,
        // whose answer is coarser but current.
        std::uint64_t front = std::max<std::uint64_t>(1, p->cache.frontSize());
        const std::uint64_t rootsCost = 1 + perCell;
        // What it may take and still leave the roots' answer to every pair after it.
        const std::uint64_t reserve = rootsCost * (left - 1);
        const std::uint64_t mayTake = remaining > reserve ? remaining - reserve : 0;
        const std::uint64_t retestFront = rootsCost * front;
        if (front > 1 && (retestFront > nominal || retestFront > mayTake)) {
          // Its front costs more than a substep's even share of the step (it could wait for its
          // turn forever), or more than the pairs after it leave: it coarsens, from the roots.
          p->cache.clear();
          front = 1;
        }
        if (rootsCost * front <= remaining) {
          // A pair may go over its share to re-test its front (round robin evens it out).
          const std::uint64_t grant = std::max(share, rootsCost * front);
          share = std::max(front, grant / rootsCost);  // T >= F, frontier <= T
        } else {
          // Not even the roots' answer (1 test + perCell) is affordable: a budget of 1-2 tests
          // per frame at the default cost would never query a pair, and every dropped mesh fell
          // through the ground. The roots' answer is given for what the substep has left.
          share = 1;
        }
      }
      qs.budget = QueryBudget::tests(share);
    } else {
      qs.budget = QueryBudget::unlimited();
    }
    bool pastTimeFallback = false;
    if (timed) {
      // Once the time is gone every remaining pair is skipped without reading the clock again.
      const QueryBudget::TimePoint now = timeUp ? substepDeadline : s.clock();
      if (now >= substepDeadline) {
        timeUp = true;
        if (!blind) {
          skip();
          continue;
        }
        p->cache.clear();
        qs.budget = QueryBudget::tests(1);
        // Past the time, a blind pair gets the cheapest answer that still has surface normals:
        // the contact tree's roots' answer samples whole root cells (~30 us a pair), the closest
        // feature maps' costs ~1 us. A pile keeps hundreds of pairs blind per substep, and the
        // contact tree's time budget of 0.5 ms per frame ran ~70 ms over (docs/benchmarks/world.md).
        if (qs.model == ContactModel::kContactTree && a.desc.shape->hasClosestFeatureMap() &&
            bb.desc.shape->hasClosestFeatureMap()) {
          qs.model = ContactModel::kCfm;
          pastTimeFallback = true;
        }
      }
    }
    --left;
    qs.contactSampling.marginAbs = kSampleMarginRel * std::min(a.desc.shape->diagonal(), bb.desc.shape->diagonal());
    queryContacts(*a.desc.shape, a.pose(), *bb.desc.shape, bb.pose(), qs, scratch, result, &p->cache);
    if (pastTimeFallback) {
      // Reported as a fallback (QueryResult's convention): every frontier pair was answered by cfm.
      result.fallbackPairs = result.frontier.size();
      result.fallbackModel = ContactModel::kCfm;
      qs.model = s.model;
      p->cache.clear();  // a sphere front; the next contact-tree query starts from the roots
    }
    recordAnswer(offered);
  }
  report.narrowPhaseSeconds += since(t0);
  if (timed) report.timeSpentMicros += std::chrono::duration<double, std::micro>(s.clock() - tTimed).count();
  const auto tPrepare = Clock::now();

  // The solver walks the pairs in a fixed order (by body ids), not in the budget's priority
  // order: Gauss-Seidel results depend on the order, and an order that changes from substep to
  // substep makes resting contact jitter (a stack then walks sideways).
  solveOrder.assign(order.begin(), order.end());
  std::sort(solveOrder.begin(), solveOrder.end(), [](const auto& l, const auto& r) { return l.second < r.second; });

  // Prepare constraints. Everything that depends on the velocities is read before any
  // warm-start impulse is applied, so it does not depend on the pair order.
  impactNow = false;
  for (auto& [p, ids] : solveOrder) {
    p->impact = false;
    Body& a = bodies[ids[0]];
    Body& b = bodies[ids[1]];
    const double restitution = std::max(a.desc.restitution, b.desc.restitution);
    const double diag = std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
    const bool aFixed = a.invMass == 0.0, bFixed = b.invMass == 0.0;
    if (sphereTreeModel && !(aFixed && bFixed) && (p->interrupted || s.maxLevel == UINT32_MAX)) {
      // A D&O contact's normal is the centre line of two bounding spheres, an average-model one
      // the mean normal of a sphere's triangles: from the big spheres a query stopped by the budget
      // leaves them at, neither carries a surface. Against an immovable body such a contact is the
      // moving body's whole support, and it leans toward the horizontal, the more the deeper the
      // body sinks: in the 200-body bin bodies slid down through the floor and fell until they left
      // the bounds (docs/dynamics.md, "Sphere models' interrupted contacts"). Between two moving
      // bodies the same lean under a heavy body squeezed the light one out or tipped the pair:
      // a 100 kg box dropped on a 1 kg box at 16 tests per frame slid off (dos, 0.77 m) or fell
      // through it and the ground (average). So an interrupted pair's sphere-model contacts take
      // the supporting body's own surface direction: the outward direction of its oriented
      // bounding box from the point nearest the other body's centre of mass. The supporting body
      // is the immovable one, else the heavier (what rests on it, or what it holds up); where the
      // other centre lies inside its box (a sunken body, a body inside a concave mesh's box) the
      // other body's box is asked, and where both say nothing the sphere normal stays. A query
      // that finished with no level cap (an unlimited budget) is answered this way too: its leaf
      // spheres still bound the faces, not follow them (dos at 60 Hz: a box sliding on the
      // ground stopped after 14 % of its distance, tilted 9.6 deg; one sliding down a 35 deg
      // slope stuck). A level cap (the experiments that compare the models' normals, e.g.
      // `clod experiment landing`) keeps the model's normals. Done before persistContacts, so the
      // anchors and the warm-start matching see the normal the solver uses. (The points stay where
      // D&O puts them: moved onto the support's face, friction there tipped sliding boxes whose
      // few coarse points do not reach the base's rim, 7-8 deg at 16 tests per frame.)
      const bool aSupports = aFixed || (!bFixed && a.desc.mass >= b.desc.mass);
      const Body& support = aSupports ? a : b;
      const Body& other = aSupports ? b : a;
      Vec3 outOfSupport = outwardFromBox(support, other.x);
      if (outOfSupport.squaredNorm() == 0.0 && support.invMass > 0.0) outOfSupport = -outwardFromBox(other, support.x);
      // The contact normal points out of B toward A.
      if (outOfSupport.squaredNorm() > 0.0) {
        for (SolverContact& cp : p->contacts)
          if (cp.c.errorBound > 0.0) cp.c.normal = aSupports ? Vec3(-outOfSupport) : outOfSupport;
      } else if (support.invMass == 0.0 && p->fresh) {
        // Inside an immovable body's box (a floor with a wall, a bin) that box says nothing, and
        // the sphere normals pushed bodies sideways: a box over a floor's edge beside a wall slid
        // off it and fell through (dos and average at 16 tests per frame), boxes sliding on that
        // floor stuck on its leaf spheres at every budget. There each new contact takes the
        // support's own surface normal nearest its point (its exact field within the contact's
        // depth and error bound), kept while the answer is carried on.
        const Pose pose = support.pose();
        for (SolverContact& cp : p->contacts) {
          if (!(cp.c.errorBound > 0.0)) continue;
          detail::FieldValue f;
          const double reach = std::abs(cp.c.depth) + cp.c.errorBound;
          if (!detail::exactBodyFieldWithin(*support.desc.shape, pose.applyInverse(cp.c.point), reach, fieldScratch, f)) continue;
          const Vec3 outward = pose.rotation * f.gradient;
          cp.c.normal = aSupports ? Vec3(-outward) : outward;
        }
      }
    }
    if (p->fresh) persistContacts(*p, a, b, diag);
    if (p->fresh && p->interrupted && !p->contacts.empty()) p->holding = holdPair(*p, a, b, sinkAllowed(a, b));
    double maxDepth = 0.0;
    double approach = 0.0;
    // A coarse contact (errorBound > 0: an interrupted sphere-model query) between a moving body
    // and an immovable one whose normal would push the moving body toward the immovable body's
    // box -- e.g. a map normal of a coarse sphere pair that points down into a floor -- can only
    // hold the body in while it falls through (the bin at low budgets, docs/dynamics.md: with
    // this guard the cfm model loses no body at 1,024 tests per frame, 30 without). Such a normal is
    // replaced by the outward direction of the immovable body's world box at the point nearest
    // the moving body's centre of mass (only when that centre is outside the box; inside, the
    // box says nothing). Exact and contact-tree contacts are trusted as they are.
    if (aFixed != bFixed) {
      const Body& moving = aFixed ? b : a;
      const Aabb box = (aFixed ? a : b).worldBox(0.0);
      const Vec3 outward = moving.x - moving.x.cwiseMax(box.min).cwiseMin(box.max);
      const double length = outward.norm();
      for (SolverContact& cp : p->contacts) {
        // The moving body is pushed along +n if it is A, along -n if it is B.
        const Vec3 push = aFixed ? Vec3(-cp.c.normal) : cp.c.normal;
        if (cp.c.errorBound > 0.0 && !cp.hold && length > 0.0 && push.dot(outward) < 0.0)
          cp.c.normal = (aFixed ? -1.0 : 1.0) * outward / length;
      }
    }
    for (SolverContact& cp : p->contacts) {
      const Vec3& n = cp.c.normal;
      // Both anchors moved with their bodies: their offset along the normal is this point's own
      // separation now (a tilt makes one side deeper and the other shallower), and their midpoint
      // is where the impulses act -- one point for both bodies, so impulses stay equal and
      // opposite about one point and momentum is conserved exactly. Against a ball they act at
      // the ball's point, under its centre: the other body's anchor lags behind a rolling ball,
      // and a push between the two would brake it (rolling resistance the ball does not have).
      const Vec3 pA = pointOnA(a, cp.anchorA, n);
      const Vec3 pB = pointOnB(b, cp.anchorB, n);
      cp.separation = (pA - pB).dot(n);
      cp.speculative = std::max(0.0, cp.separation) / h;
      const bool ballA = a.desc.ballRadius > 0.0, ballB = b.desc.ballRadius > 0.0;
      const Vec3 point = ballA == ballB ? Vec3(0.5 * (pA + pB)) : ballA ? pA : pB;
      cp.rA = point - a.x;
      cp.rB = point - b.x;
      tangents(n, cp.t1, cp.t2);
      auto effMass = [&](const Vec3& dir) {
        const Vec3 ra = cp.rA.cross(dir), rb = cp.rB.cross(dir);
        const double k = a.invMass + b.invMass + ra.dot(a.invInertiaWorld * ra) + rb.dot(b.invInertiaWorld * rb);
        return k > 0.0 ? 1.0 / k : 0.0;
      };
      cp.massN = effMass(n);
      cp.tangentK = tangentInverseMass(a.invMass + b.invMass, cp.t1, cp.t2,
                                       {{cp.rA, &a.invInertiaWorld}, {cp.rB, &b.invInertiaWorld}});
      const Vec3 vr = a.v + a.w.cross(cp.rA) - b.v - b.w.cross(cp.rB);
      const double vn = vr.dot(n);
      // Restitution by Poisson's hypothesis, applied after the velocity iterations: the solver
      // first stops the approach (compression impulse), then adds restitution x that impulse
      // (Stronge, "Impact Mechanics", 2000). Decided once, from the pre-solve approach speed.
      cp.restitution = vn < -s.restitutionThreshold ? restitution : 0.0;
      // A speculative contact (still open) that closes within this substep and bounces is
      // stopped now, up to its gap early, so that the whole approach bounces: the solve would
      // only slow it to what closes the gap, and the bodies met at that speed in the next
      // substep, below the bounce threshold -- a ball (whose hull meets the floor before the ball
      // does, docs/dynamics.md "Balls") dropped with restitution 0.5 did not bounce at all.
      if (cp.restitution > 0.0 && cp.separation > 0.0 && cp.separation + vn * h < 0.0) cp.speculative = 0.0;
      // Only the part of the depth that is certain is corrected, the same way for every model:
      // a contact's depth may be off by its errorBound (a coarse sphere pair's surfaces lie
      // somewhere inside both spheres), so correcting that part would push apart bodies that do
      // not touch (docs/dynamics.md).
      const double certain = -cp.separation - cp.c.errorBound - s.slopRel * diag;
      // Correction speed capped: a coarse contact's depth can be a large part of a body, and
      // removing a fifth of it per substep would teleport a small body through its neighbours.
      const double maxCorrection = kMaxCorrectionRel * diag;
      cp.targetPos = certain > 0.0 ? std::min(s.correctionFactor * certain, maxCorrection) / h : 0.0;
      maxDepth = std::max(maxDepth, cp.c.depth);
      approach = std::max(approach, -vn);
      p->impact = p->impact || -vn * h > s.slopRel * diag;
      // Warm start only resting contact: re-applying last substep's impulse to a pair that is now
      // separating or approaching fast (a bounce) adds energy the iterations may not remove.
      const bool resting = std::abs(vn) < s.restitutionThreshold;
      // (The impulses come from persistContacts for a queried pair, from the contact itself for
      // a pair the budget skipped; the friction impulse is kept as a world vector because the
      // tangent directions follow the normal.)
      if (resting) {
        cp.lambdaT1 = cp.frictionImpulse.dot(cp.t1);
        cp.lambdaT2 = cp.frictionImpulse.dot(cp.t2);
      } else {
        cp.lambdaN = cp.lambdaT1 = cp.lambdaT2 = 0.0;
      }
      cp.lambdaP = 0.0;
    }
    p->priority = approach + maxDepth / h;
    impactNow = impactNow || p->impact;
    report.solverContacts += p->contacts.size();
  }
  report.prepareSeconds += since(tPrepare);
  if (contactCallback) runContactCallback();
  solve(h);
  const auto tIntegrate = Clock::now();
  integrate(h);
  report.integrateSeconds += since(tIntegrate);
}

// Manifold reuse (docs/dynamics.md): true while B has moved in A's frame, since the pair's last
// finished query, by less than reuseMotionRel of the smaller diagonal -- translation plus the
// rotation angle times B's diagonal (the most a point of B can have moved by the turn).
// A resting contact is then not queried again: its anchored points already follow the bodies,
// and a new answer would be the same up to that motion (a contact-tree stack at an unlimited
// budget ran 8-15x slower than real time re-deriving it every substep).
bool World::Impl::reuseManifold(const PairState& p, const Body& a, const Body& b) const {
  const double limit = settings.reuseMotionRel * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
  return motionSinceQuery(p, a, b) < limit;
}

// How far a point of B can have moved in A's frame since the pair's last query: B's translation
// there plus the rotation angle times B's diagonal.
double World::Impl::motionSinceQuery(const PairState& p, const Body& a, const Body& b) const {
  const Pose moved = p.queriedAt.inverse() * (a.pose().inverse() * b.pose());
  const double angle = 2.0 * std::atan2(moved.rotation.vec().norm(), std::abs(moved.rotation.w()));
  return moved.translation.norm() + angle * b.desc.shape->diagonal();
}

// The farthest any point of B can have moved in A's frame since the pair's last query: B's
// translation there plus the rotation angle times B's farthest point from its mesh origin, a
// bound (|(R - I) p| <= angle |p|) that QueryResult::separation can be held against.
double World::Impl::reachSinceQuery(const PairState& p, const Body& a, const Body& b) const {
  return reachSince(p.queriedAt, a, b);
}

double World::Impl::reachSince(const Pose& bInAThen, const Body& a, const Body& b) const {
  const Pose moved = bInAThen.inverse() * (a.pose().inverse() * b.pose());
  const double angle = 2.0 * std::atan2(moved.rotation.vec().norm(), std::abs(moved.rotation.w()));
  return moved.translation.norm() + angle * b.frameReach;
}

// Persistent contacts (as Bullet's persistent manifold and Box2D's contact ids do it): each new
// contact of a freshly queried pair is matched one-to-one to the nearest unclaimed previous
// contact of the pair within 5 % of the smaller diagonal whose normal is within ~18 degrees. A
// match passes on its accumulated normal and friction impulses (warm starting) and -- if it came
// from the same narrow-phase level, its two anchors have neither slid apart nor opened by more
// than kAnchorDriftRel of the smaller diagonal, and they still stand for the new contact (their
// midpoint within that drift of its point, their separation its depth within its error bound
// plus the slop) -- its anchors too: the point stays where it was first found on both bodies,
// so its separation is measured from the bodies' motion since then, point by point: a box that
// tilts on another gets deeper anchors on one side and shallower (or open, speculative) ones on
// the other, so the correction acts on the deeper side and the velocity solve lets the open side
// come down. Anchors the new answer contradicts are dropped: the solver holds a matched pair
// together, so a rolling bunny pivoted about its anchors while its fresh, 9 mm deep contacts were
// held at 0. A new contact without kept anchors is anchored at its point, half its depth into
// each body. (A coarser or finer level re-anchors: its depth means something else.)
void World::Impl::persistContacts(PairState& p, const Body& a, const Body& b, double diag) {
  const double matchDistance = 0.05 * diag;
  const double drift = kAnchorDriftRel * diag;
  const double slop = settings.slopRel * diag;
  if (keepFinerManifold(p, a, b, drift, slop)) return;
  for (auto& old : p.previous) old.matched = false;
  for (SolverContact& cp : p.contacts) {
    const Vec3& n = cp.c.normal;
    double best = matchDistance;
    SolverContact* match = nullptr;
    for (SolverContact& old : p.previous) {
      if (old.matched || old.c.normal.dot(n) < kWarmStartNormalCos) continue;
      const Vec3 mid = 0.5 * (pointOnA(a, old.anchorA, old.c.normal) + pointOnB(b, old.anchorB, old.c.normal));
      const double d = (mid - cp.c.point).norm();
      if (d < best) {
        best = d;
        match = &old;
      }
    }
    cp.anchorA = a.q.conjugate() * (cp.c.point - 0.5 * cp.c.depth * n - a.x);
    cp.anchorB = b.q.conjugate() * (cp.c.point + 0.5 * cp.c.depth * n - b.x);
    if (!match) continue;
    match->matched = true;
    cp.lambdaN = match->lambdaN;
    cp.frictionImpulse = match->frictionImpulse;
    const Vec3 gap = pointOnA(a, match->anchorA, n) - pointOnB(b, match->anchorB, n);
    const double open = gap.dot(n);
    const bool held = open < drift && (gap - open * n).norm() < drift;
    const bool standsFor = best < drift && std::abs(-open - cp.c.depth) <= cp.c.errorBound + slop;
    if (match->c.level == cp.c.level && held && standsFor) {
      cp.anchorA = match->anchorA;
      cp.anchorB = match->anchorB;
    }
  }
  carryValidContacts(p, a, b, matchDistance, drift);
}

// The persistent manifold also keeps what the new answer did not repeat (Bullet's persistent
// manifold does the same): a previous contact that no new one matched, lies farther than the
// match distance from every new contact, and still holds -- its anchors have neither slid apart
// nor opened by more than `drift` -- stays, with its anchors and impulses, as long as its normal
// agrees with the new answer's (within the warm-start cone of some new contact). An answer
// interrupted at a coarse level often covers only part of the contact region (a contact tree's
// few frontier cells, a cfm patch pair meeting at one edge); carried over, the earlier points
// keep the support polygon whole. If the union has more than maxContacts points it is reduced as
// the narrow phase reduces (deepest by current separation first, then farthest-point sampling in
// the deepest contact's plane), so it never grows.
void World::Impl::carryValidContacts(PairState& p, const Body& a, const Body& b, double matchDistance, double drift) {
  const std::size_t fresh = p.contacts.size();
  // An empty answer ends the manifold when it is a finished one or proved the bodies apart. An
  // interrupted one that found nothing proved nothing: the contact tree's roots' answer (two
  // tests a substep) samples a few points, and a rolling bunny it had answered with one contact
  // elsewhere fell freely for three frames through such answers while 6 mm of it was inside the
  // floor. What is still pressed of the last manifold stays instead.
  const bool provedNothing = p.interrupted && !(p.apartBy > 0.0);
  if (fresh == 0 && !provedNothing) return;
  // A previous contact inside the fresh answer's support polygon, no deeper than it says, adds
  // nothing to the support (narrowphase/support_polygon.h): carried, it only takes a share of the
  // load where the answer has none (a box spinning on the floor kept its slow interior points while
  // the corners moved on).
  supportRoom.resize(3 * fresh);
  detail::SupportPolygon polygon(fresh > 0 ? p.contacts[0].c.normal : Vec3::UnitZ(), supportRoom);
  for (std::size_t i = 0; i < fresh; ++i) polygon.add(p.contacts[i].c);
  polygon.close();
  for (const SolverContact& old : p.previous) {
    if (old.matched) continue;
    const Vec3 pA = pointOnA(a, old.anchorA, old.c.normal), pB = pointOnB(b, old.anchorB, old.c.normal);
    const Vec3 gap = pA - pB;
    const double open = gap.dot(old.c.normal);
    if (open >= drift || (gap - open * old.c.normal).norm() >= drift) continue;
    const Vec3 mid = 0.5 * (pA + pB);
    bool near = false, agrees = false;
    for (std::size_t i = 0; i < fresh; ++i) {
      near = near || (p.contacts[i].c.point - mid).norm() < matchDistance;
      agrees = agrees || p.contacts[i].c.normal.dot(old.c.normal) >= kWarmStartNormalCos;
    }
    // With no fresh contact to agree with, only a still-pressed one is kept: one that has opened
    // no longer supports anything, and its warm-started impulse kept a rocking bunny rocking.
    if (fresh > 0 ? near || !agrees : open > 0.0) continue;
    Contact carried = old.c;
    carried.point = mid;
    carried.depth = -open;
    if (polygon.addsNothing(carried)) continue;
    p.contacts.push_back(old);
    p.contacts.back().c = carried;
  }
  if (p.contacts.size() > settings.maxContacts) reduceCarried(p.contacts, settings.maxContacts);
}

// Keeps `keep` well-spread contacts: the deepest (by depth, which carried contacts hold as their
// current separation), then repeatedly the one farthest, in the deepest contact's plane, from
// those kept. Order of the kept ones: selection order.
void World::Impl::reduceCarried(std::vector<SolverContact>& contacts, std::size_t keep) {
  std::size_t deepest = 0;
  for (std::size_t i = 1; i < contacts.size(); ++i)
    if (contacts[i].c.depth > contacts[deepest].c.depth) deepest = i;
  std::swap(contacts[0], contacts[deepest]);
  const Vec3 n = contacts[0].c.normal;
  auto planar = [&n](const Vec3& d) { return (d - d.dot(n) * n).squaredNorm(); };
  spread.assign(contacts.size(), std::numeric_limits<double>::infinity());
  for (std::size_t k = 1; k < keep; ++k) {
    std::size_t best = k;
    for (std::size_t i = k; i < contacts.size(); ++i) {
      spread[i] = std::min(spread[i], planar(contacts[i].c.point - contacts[k - 1].c.point));
      if (spread[i] > spread[best]) best = i;
    }
    std::swap(contacts[k], contacts[best]);
    std::swap(spread[k], spread[best]);
  }
  contacts.resize(keep);
}

// A coarser answer never replaces a finer manifold that still holds (the persistent manifold
// merged by error bound, docs/dynamics.md): when every previous contact of the pair has a smaller
// error bound than every new one, and each previous contact's anchors have neither slid apart
// nor opened by more than `drift` since they were found, the previous contacts stay -- measured
// from their anchors, with their impulses -- and the new, coarser ones are dropped. So a pair
// whose budget share shrank (more pairs in contact, a deadline) keeps the support its earlier,
// finer queries found while the bodies have not moved enough to make it wrong, and more budget
// can only make a pair's contacts finer, never replace them by coarser ones. An empty answer is
// left to carryValidContacts (it ends the manifold only if finished or proven apart).
bool World::Impl::keepFinerManifold(PairState& p, const Body& a, const Body& b, double drift, double slop) {
  // A finished answer is the model's finest at this pose, whatever its error bounds: the contact
  // tree's leaf samples carry their cells' field error, and an earlier contact with a smaller
  // bound (a sample on a flat cell, bound 0) would otherwise outrank every later answer. A
  // bunny pivoting on such a contact at an unlimited budget kept it for 12 steps while fresh
  // answers found its other side coming down, and sank 0.53 % of its diagonal (0.05 % at 1,024
  // tests, whose interrupted answers were not held back).
  if (!p.interrupted) return false;
  if (p.contacts.empty() || p.previous.empty()) return false;
  double newBound = std::numeric_limits<double>::infinity();
  double provenDepth = -std::numeric_limits<double>::infinity();  // the new answer's, at least
  for (const SolverContact& cp : p.contacts) {
    newBound = std::min(newBound, cp.c.errorBound);
    provenDepth = std::max(provenDepth, cp.c.depth - cp.c.errorBound);
  }
  double heldDepth = -std::numeric_limits<double>::infinity();  // the previous one's, at most
  for (const SolverContact& old : p.previous) {
    if (!(old.c.errorBound < newBound)) return false;
    const Vec3 gap = pointOnA(a, old.anchorA, old.c.normal) - pointOnB(b, old.anchorB, old.c.normal);
    const double open = gap.dot(old.c.normal);
    if (open >= drift || (gap - open * old.c.normal).norm() >= drift) return false;
    heldDepth = std::max(heldDepth, -open + old.c.errorBound);
  }
  // Anchors that still hold prove nothing when the solver is what holds them: a ball kept on a
  // floor by a finer contact found at its side rolled about that point, its anchors never moved
  // apart, and it sank 9 cm (a third of its diameter) into the floor through the coarse answers
  // that said so. So the coarse answer refutes the finer manifold when it proves the bodies
  // deeper (its depth less its bound) than the finer manifold allows (its deepest current
  // separation plus bound) by more than the slop. (A margin of the anchors' drift, 1 % of the
  // smaller diagonal, let a rolling spot sink 1.3 % of its diagonal on a stale contact at its
  // other end while every fresh answer found the deepest point.)
  if (provenDepth > heldDepth + slop) return false;
  p.contacts.swap(p.previous);
  p.keptFiner = true;
  return true;
}

// How far the two bodies of a candidate pair can move toward each other over dt (the part of
// the arrival rule that may take kMaxApproachSubsteps, World::step). A pair without contacts:
// both bodies' whole travel. A pair in contact: only the motion along its contacts' normals --
// the relative velocity's normal part plus each body's turn times its half diagonal, the most a
// point of it can approach -- since sliding along the contact plane arrives nowhere: a box
// sliding at 5 m/s keeps the rule's 8 substeps for its whole travel, while a tumbling fandisk's
// far corner, coming down at 4 m/s while its other end touched, gets up to 16.
double World::Impl::arrivalTravel(const BodyPair& c, double dt) const {
  const double both = stepTravel[c[0]] + stepTravel[c[1]];
  const auto found = pairs.find(pairKey(c[0], c[1]));
  if (found == pairs.end() || found->second.contacts.empty()) return both;
  const Body& a = bodies[c[0]];
  const Body& b = bodies[c[1]];
  const Vec3 relative = a.v - b.v;
  const double turning = a.w.norm() * 0.5 * a.localBox.diagonal() + b.w.norm() * 0.5 * b.localBox.diagonal();
  double approach = 0.0;
  for (const SolverContact& cp : found->second.contacts)
    approach = std::max(approach, std::abs(relative.dot(cp.c.normal)));
  return std::min(both, (approach + turning + settings.gravity.norm() * dt) * dt);
}

double World::Impl::kineticEnergyOfDynamicBodies() const {
  double e = 0.0;
  for (const Body& b : bodies)
    if (b.type == BodyType::kDynamic) {
      const Vec3 wl = b.q.conjugate() * b.w;
      e += 0.5 * b.desc.mass * b.v.squaredNorm() + 0.5 * wl.dot(b.inertiaLocal * wl);
    }
  return e;
}

// A contact slips, for the last friction sweep, while its points slide past each other faster
// than this fraction of the smaller body's diagonal per second (1 cm/s for a 1 m box).
constexpr double kSlipSpeedRel = 0.01;

void World::Impl::solve(double h) {
  (void)h;
  const auto t0 = std::chrono::steady_clock::now();
  const WorldSettings& s = settings;
  auto apply = [](Body& a, Body& b, const SolverContact& cp, const Vec3& impulse) {
    a.v += a.invMass * impulse;
    a.w += a.invInertiaWorld * cp.rA.cross(impulse);
    b.v -= b.invMass * impulse;
    b.w -= b.invInertiaWorld * cp.rB.cross(impulse);
  };
  // Velocities before the contact solve (gravity applied): the energy reference, and the state a
  // cold restart goes back to.
  const double energyBefore = kineticEnergyOfDynamicBodies();
  savedV.resize(bodies.size());
  savedW.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    savedV[i] = bodies[i].v;
    savedW[i] = bodies[i].w;
  }
  // Patch friction (standsForAPatch): the pair's friction as one impulse at the centre of its
  // normal impulses -- for a load at rest under a body's centre of mass, the point under it -- in
  // the Coulomb cone mu x the pair's normal impulse, and one angular impulse about the normal
  // within mu x that impulse x the load's mean lever about its centre (the torque of Coulomb
  // friction on a patch turning about its centre with that load). Each stepped as friction is
  // (coneStep; a clamp about the normal). With `slipping` >= 0 (the last sweep) only while the
  // centre slides, or the patch turns, faster than that. `held` (the shock sweep's lower body)
  // is held fixed. Returns the tangential impulse's change.
  static const Mat3 kNoTurn = Mat3::Zero();
  // Where a patch's friction acts: the centre of its contacts' normal impulses, moved along the
  // normal toward the plane where the bodies' hull boxes meet (patchInterface), where the surfaces
  // touch, but not past the contact nearest it. Coarse points lie at any height inside the two
  // bodies, and friction at a point high in a body tips it: a 79 m tall box spinning on the floor
  // on its leaf spheres' D&O points (dos, unlimited) ended tilted 2.1 deg with the centre itself,
  // 0.006 deg moved so. All the way to the plane, friction's lever there tipped what the coarse
  // points could not hold: a 1,000 : 1 stack of 1 mm boxes at 16 tests per frame moved 1.5-2.9 %
  // of a side (`WorldMassRatio.SphereModelsKeepAHeavyBoxOnALightOneAtLimitedBudgets`, 1 %
  // allowed). Nor past the answer's contacts to the holds (holdAtBoxes): a 1,000 : 1 plate of
  // 1 mm on its thin edge, resting on its roots' one D&O contact inside it and held at its boxes,
  // took friction at its base, below that pivot, and rocked there until it stood 1.1 deg tilted
  // (dos, 16 tests per frame). Returns the pair's normal impulse (0: no load, no centre).
  auto patchCentre = [&](const PairState& p, const Body& a, Vec3& rA, Vec3& rB) {
    double load = 0.0;
    rA.setZero();
    rB.setZero();
    for (const SolverContact& cp : p.contacts) {
      load += cp.lambdaN;
      rA += cp.lambdaN * cp.rA;
      rB += cp.lambdaN * cp.rB;
    }
    if (!(load > 0.0)) return 0.0;
    rA /= load;
    rB /= load;
    if (p.patchHasInterface) {
      const Vec3& n = p.patchNormal;
      double lo = 0.0, hi = 0.0;
      for (const SolverContact& cp : p.contacts) {
        if (cp.hold) continue;
        lo = std::min(lo, n.dot(cp.rA - rA));
        hi = std::max(hi, n.dot(cp.rA - rA));
      }
      const double toPlane = (p.patchInterfaceAt - p.patchInterfaceAxis.dot(a.x + rA)) / p.patchInterfaceAxis.dot(n);
      const double shift = std::clamp(toPlane, lo, hi);
      rA += shift * n;
      rB += shift * n;
    }
    return load;
  };
  auto patchFrictionStep = [&](PairState& p, Body& a, Body& b, double mu, double slipping, const Body* held = nullptr) {
    const double invMassA = &a == held ? 0.0 : a.invMass, invMassB = &b == held ? 0.0 : b.invMass;
    const Mat3& invInertiaA = &a == held ? kNoTurn : a.invInertiaWorld;
    const Mat3& invInertiaB = &b == held ? kNoTurn : b.invInertiaWorld;
    Vec3 rA, rB;
    const double load = patchCentre(p, a, rA, rB);
    if (!(load > 0.0)) return 0.0;
    const Vec3& n = p.patchNormal;
    double lever = 0.0;
    for (const SolverContact& cp : p.contacts) {
      const Vec3 d = cp.rA - rA;
      lever += cp.lambdaN * (d - d.dot(n) * n).norm();
    }
    lever /= load;
    const Vec3 vr = a.v + a.w.cross(rA) - b.v - b.w.cross(rB);
    const double v1 = vr.dot(p.patchT1), v2 = vr.dot(p.patchT2), spin = (a.w - b.w).dot(n);
    if (slipping >= 0.0 && std::hypot(v1, v2) <= slipping && std::abs(spin) * lever <= slipping) return 0.0;
    double change = 0.0;
    const TangentInverseMass k = tangentInverseMass(invMassA + invMassB, p.patchT1, p.patchT2,
                                                    {{rA, &invInertiaA}, {rB, &invInertiaB}});
    const double old1 = p.patchL1, old2 = p.patchL2;
    if (coneStep(p.patchL1, p.patchL2, v1, v2, k, mu * load)) {
      const Vec3 impulse = (p.patchL1 - old1) * p.patchT1 + (p.patchL2 - old2) * p.patchT2;
      a.v += invMassA * impulse;
      a.w += invInertiaA * rA.cross(impulse);
      b.v -= invMassB * impulse;
      b.w -= invInertiaB * rB.cross(impulse);
      change = impulse.norm();
    }
    const double kn = n.dot((invInertiaA + invInertiaB) * n);
    if (kn > 0.0) {
      const double old = p.patchTorsion, limit = mu * lever * load;
      p.patchTorsion = std::clamp(old - (a.w - b.w).dot(n) / kn, -limit, limit);
      const Vec3 turn = (p.patchTorsion - old) * n;
      a.w += invInertiaA * turn;
      b.w -= invInertiaB * turn;
    }
    return change;
  };
  // Shock propagation (Guendelman, Bridson & Fedkiw 2003; docs/dynamics.md, "Mass ratios"):
  // after the iterations, one pass up the support layers, each pair between two layers solved
  // with the lower body held fixed (infinite mass), so the residual approach the iterations left
  // between a heavy body and a light one under it is removed from the upper body alone. Projected
  // Gauss-Seidel converges like (M / (M + m))^k for a body of mass M resting on one of mass m --
  // about 700 iterations to halve the error at 1,000 : 1 -- so without it a heavy box pressed a
  // light one into the ground or squeezed it out sideways.
  auto shockSolve = [&](std::uint32_t k) {
    auto& [p, ids] = solveOrder[k];
    Body& a = bodies[ids[0]];
    Body& b = bodies[ids[1]];
    const bool aLower = supportLayer[ids[0]] < supportLayer[ids[1]];
    Body& upper = aLower ? b : a;
    const double sign = aLower ? -1.0 : 1.0;  // impulses act on A along +, on B along -
    const double mu = pairFriction(a, b);
    if (p->patch) patchFrictionStep(*p, a, b, mu, -1.0, aLower ? &a : &b);
    for (SolverContact& cp : p->contacts) {
      const Vec3& r = aLower ? cp.rB : cp.rA;
      auto relative = [&]() -> Vec3 { return a.v + a.w.cross(cp.rA) - b.v - b.w.cross(cp.rB); };
      auto push = [&](const Vec3& impulse) {
        upper.v += sign * upper.invMass * impulse;
        upper.w += sign * (upper.invInertiaWorld * r.cross(impulse));
      };
      const Vec3 vt = relative();
      if (!p->patch) push(frictionStep(cp, vt.dot(cp.t1), vt.dot(cp.t2), cp.shockTangentK, mu * cp.lambdaN));
      double old = cp.lambdaN;
      cp.lambdaN = std::max(0.0, old - cp.shockMassN * (relative().dot(cp.c.normal) + cp.speculative));
      push((cp.lambdaN - old) * cp.c.normal);
      cp.lambdaShock += cp.lambdaN - old;
      cp.shockOnA = !aLower;
    }
  };
  // Layer by layer, bottom-up; within a layer kShockPasses passes, since a pair's contacts are
  // coupled through the upper body's rotation and friction.
  auto shockPass = [&] {
    auto lowerLayer = [&](std::uint32_t k) {
      const auto& ids = solveOrder[k].second;
      return std::min(supportLayer[ids[0]], supportLayer[ids[1]]);
    };
    for (std::size_t first = 0, end = 0; first < shockPairs.size(); first = end) {
      while (end < shockPairs.size() && lowerLayer(shockPairs[end]) == lowerLayer(shockPairs[first])) ++end;
      for (std::uint32_t pass = 0; pass < kShockPasses; ++pass)
        for (std::size_t g = first; g < end; ++g) shockSolve(shockPairs[g]);
    }
  };
  // One friction sweep against the settled normal impulses, after every normal update.
  // Projected Gauss-Seidel clamps a contact's friction to mu times its normal impulse *before*
  // that impulse's update in the same sweep, and a face's contacts keep trading load from sweep to
  // sweep (most with near-duplicate points at one corner), so at the end some contacts hold more
  // than mu N and others less. A sliding box then braked by more than Coulomb allows: the contact
  // tree's 8-point manifold on a 48.6 deg slope took 3-5 % more than mu N, 15 cm over 2 s
  // (docs/dynamics.md, "Solver"). Here every slipping contact ends on its cone; the normal velocity
  // this disturbs (friction's torque about the body) is left to the next substep and the position
  // pass. Sticking contacts are left as the iterations solved them: swept too, a bunny at rest
  // on a box started rocking again and sank 1.1 % of its diagonal.
  auto finalFrictionSweep = [&] {
    for (auto& [p, ids] : solveOrder) {
      Body& a = bodies[ids[0]];
      Body& b = bodies[ids[1]];
      const double mu = pairFriction(a, b);
      const double slipping = kSlipSpeedRel * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal());
      if (p->patch) {
        patchFrictionStep(*p, a, b, mu, slipping);
        continue;
      }
      for (SolverContact& cp : p->contacts) {
        const Vec3 vr = a.v + a.w.cross(cp.rA) - b.v - b.w.cross(cp.rB);
        const Vec3 vt = vr - vr.dot(cp.c.normal) * cp.c.normal;
        if (vt.squaredNorm() <= slipping * slipping) continue;
        apply(a, b, cp, frictionStep(cp, vr.dot(cp.t1), vr.dot(cp.t2), cp.tangentK, mu * cp.lambdaN));
      }
    }
  };
  // Rolling resistance (WorldSettings::rollingResistanceRel): the bodies' relative turn about
  // the pair's tangent axes (those of its mean contact normal) is resisted by an angular impulse
  // of at most rollingResistanceRel x the smaller diagonal x the pair's normal impulse, stepped
  // along the turn as friction is (coneStep) and not warm-started (its limit follows the
  // normal impulses of the same sweep).
  const double rollingRel = s.rollingResistanceRel;
  auto rollingStep = [&](PairState& p, Body& a, Body& b) {
    // None where a ball is one side: the lever stands for a non-round body's rocking and a
    // deforming body's pressure shift, and a ball is a rigid round body (docs/dynamics.md, "Balls").
    if (a.desc.ballRadius > 0.0 || b.desc.ballRadius > 0.0) return;
    double lambdaN = 0.0;
    for (const SolverContact& cp : p.contacts) lambdaN += cp.lambdaN;
    const double limit = rollingRel * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal()) * lambdaN;
    const Vec3 w = a.w - b.w;
    const double old1 = p.rollingL1, old2 = p.rollingL2;
    if (!coneStep(p.rollingL1, p.rollingL2, w.dot(p.rollingU1), w.dot(p.rollingU2), p.rollingK, limit)) return;
    const Vec3 impulse = (p.rollingL1 - old1) * p.rollingU1 + (p.rollingL2 - old2) * p.rollingU2;
    a.w += a.invInertiaWorld * impulse;
    b.w -= b.invInertiaWorld * impulse;
  };
  if (rollingRel > 0.0)
    for (auto& [p, ids] : solveOrder) {
      p->rollingL1 = p->rollingL2 = 0.0;
      if (p->contacts.empty()) continue;
      Vec3 n = Vec3::Zero();
      for (const SolverContact& cp : p->contacts) n += cp.c.normal;
      if (n.squaredNorm() == 0.0) n = p->contacts.front().c.normal;
      n.normalize();
      tangents(n, p->rollingU1, p->rollingU2);
      const Mat3 kw = bodies[ids[0]].invInertiaWorld + bodies[ids[1]].invInertiaWorld;
      p->rollingK = {p->rollingU1.dot(kw * p->rollingU1), p->rollingU1.dot(kw * p->rollingU2), p->rollingU2.dot(kw * p->rollingU2)};
    }
  // Which pairs take patch friction this substep, their tangent frames, and their impulses of the
  // substep before in those frames; their contacts take none of their own.
  for (auto& [p, ids] : solveOrder) {
    const Body& a = bodies[ids[0]];
    const Body& b = bodies[ids[1]];
    const bool was = p->patch;
    p->patch = standsForAPatch(p->contacts, s.slopRel * std::min(a.desc.shape->diagonal(), b.desc.shape->diagonal()));
    if (!p->patch) continue;
    if (!was) p->patchImpulse.setZero(), p->patchTorsion = 0.0;
    p->patchNormal = p->contacts.front().c.normal;
    tangents(p->patchNormal, p->patchT1, p->patchT2);
    patchInterface(*p, a, b);
    p->patchL1 = p->patchImpulse.dot(p->patchT1);
    p->patchL2 = p->patchImpulse.dot(p->patchT2);
    for (SolverContact& cp : p->contacts) cp.lambdaT1 = cp.lambdaT2 = 0.0;
  }
  // The warm start of a patch's friction: its impulses at the centre of the warm-started load.
  auto warmStartPatch = [&](PairState& p, Body& a, Body& b) {
    Vec3 rA, rB;
    if (!(patchCentre(p, a, rA, rB) > 0.0)) {
      p.patchL1 = p.patchL2 = p.patchTorsion = 0.0;
      return;
    }
    const Vec3 impulse = p.patchL1 * p.patchT1 + p.patchL2 * p.patchT2;
    const Vec3 turn = p.patchTorsion * p.patchNormal;
    a.v += a.invMass * impulse;
    a.w += a.invInertiaWorld * (rA.cross(impulse) + turn);
    b.v -= b.invMass * impulse;
    b.w -= b.invInertiaWorld * (rB.cross(impulse) + turn);
  };
  auto iterate = [&](bool warm) {
    for (auto& [p, ids] : solveOrder)
      for (SolverContact& cp : p->contacts) cp.lambdaShock = 0.0;
    if (warm)
      for (auto& [p, ids] : solveOrder) {
        for (SolverContact& cp : p->contacts)
          apply(bodies[ids[0]], bodies[ids[1]], cp, cp.lambdaN * cp.c.normal + cp.lambdaT1 * cp.t1 + cp.lambdaT2 * cp.t2);
        if (p->patch) warmStartPatch(*p, bodies[ids[0]], bodies[ids[1]]);
      }
    // One Gauss-Seidel pass over a pair: friction first, limited by the current normal impulse;
    // then the normal, so that non-penetration, the more important constraint, is solved last
    // (Catto 2005).
    auto pairPass = [&](PairState& p, const std::array<BodyId, 2>& ids, double& maxChange, double& maxLambda) {
      Body& a = bodies[ids[0]];
      Body& b = bodies[ids[1]];
      const double mu = pairFriction(a, b);
      if (p.patch) maxChange = std::max(maxChange, patchFrictionStep(p, a, b, mu, -1.0));
      for (SolverContact& cp : p.contacts) {
        Vec3 vr = a.v + a.w.cross(cp.rA) - b.v - b.w.cross(cp.rB);
        if (!p.patch) {
          const Vec3 friction = frictionStep(cp, vr.dot(cp.t1), vr.dot(cp.t2), cp.tangentK, mu * cp.lambdaN);
          apply(a, b, cp, friction);
          maxChange = std::max(maxChange, friction.norm());
          vr = a.v + a.w.cross(cp.rA) - b.v - b.w.cross(cp.rB);
        }
        double old = cp.lambdaN;
        cp.lambdaN = std::max(0.0, old - cp.massN * (vr.dot(cp.c.normal) + cp.speculative));
        apply(a, b, cp, (cp.lambdaN - old) * cp.c.normal);
        maxChange = std::max(maxChange, std::abs(cp.lambdaN - old));
        maxLambda = std::max(maxLambda, cp.lambdaN);
      }
      if (rollingRel > 0.0 && !p.contacts.empty()) rollingStep(p, a, b);
    };
    // Passes over every pair until converged, at most `iterations`; `impactsOnly`: over the
    // pairs with an impact this substep (PairState::impact) alone.
    auto sweep = [&](std::uint32_t iterations, bool impactsOnly) {
      std::uint32_t used = 0;
      for (std::uint32_t it = 0; it < iterations; ++it) {
        ++used;
        double maxChange = 0.0, maxLambda = 0.0;
        for (auto& [p, ids] : solveOrder)
          if (!impactsOnly || p->impact) pairPass(*p, ids, maxChange, maxLambda);
        if (s.convergenceRel > 0.0 && maxChange <= s.convergenceRel * maxLambda) break;
      }
      return used;
    };
    std::uint32_t used = sweep(velocityIterationsNow, false);
    // A step of fast bodies spreads its iterations over its substeps (velocityIterationsNow,
    // WorldSettings::minSubstepIterations); the pairs of an impact get the rest of
    // velocityIterations on their own. In 4 iterations the four corners of a box hitting a wall
    // face-on, each taking the correction first in turn, left it spinning at 1.5 rad/s from
    // 20 m/s, and it fell 24 cm aside (under 1 mm with all 20). Over every pair, the 200-body
    // bin's landing frames would run 20 iterations over ~2,300 contacts again.
    if (impactNow && velocityIterationsNow < s.velocityIterations) used += sweep(s.velocityIterations - velocityIterationsNow, true);
    report.solverIterations += used;
    finalFrictionSweep();
    shockPass();
  };
  orderSupportLayers();
  iterate(true);
  double energyCompressed = kineticEnergyOfDynamicBodies();
  // A contact solve never adds kinetic energy at its solution (the impulses only stop approach,
  // friction only dissipates). An unconverged solve that started from warm-start impulses can:
  // then solve again from the pre-solve velocities without them (projected Gauss-Seidel from
  // zero impulses only lowers the energy).
  if (energyCompressed > energyBefore * (1.0 + 1e-12)) {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      bodies[i].v = savedV[i];
      bodies[i].w = savedW[i];
    }
    for (auto& [p, ids] : solveOrder) {
      for (SolverContact& cp : p->contacts) cp.lambdaN = cp.lambdaT1 = cp.lambdaT2 = 0.0;
      p->patchL1 = p->patchL2 = p->patchTorsion = 0.0;
    }
    iterate(false);
    energyCompressed = kineticEnergyOfDynamicBodies();
    ++report.coldRestarts;
  }

  // Restitution (Poisson): impulse e * lambda_c per bouncing contact. Exactly energy-safe only
  // for a converged solve; so the restitution phase is scaled down, if needed, to give back at
  // most e^2 times the energy the compression phase removed -- Stronge's energetic coefficient
  // of restitution (Stronge 1990; equal to Poisson's for a converged frictionless solve, where
  // the scale is 1).
  double eMax = 0.0;
  dV.assign(bodies.size(), Vec3::Zero());
  dW.assign(bodies.size(), Vec3::Zero());
  for (auto& [p, ids] : solveOrder)
    for (const SolverContact& cp : p->contacts)
      if (cp.restitution > 0.0 && cp.lambdaN > 0.0) {
        const Body& a = bodies[ids[0]];
        const Body& b = bodies[ids[1]];
        const Vec3 impulse = cp.restitution * cp.lambdaN * cp.c.normal;
        dV[ids[0]] += a.invMass * impulse;
        dW[ids[0]] += a.invInertiaWorld * cp.rA.cross(impulse);
        dV[ids[1]] -= b.invMass * impulse;
        dW[ids[1]] -= b.invInertiaWorld * cp.rB.cross(impulse);
        eMax = std::max(eMax, cp.restitution);
      }
  if (eMax > 0.0) {
    // Kinetic energy after adding scale * (dV, dW): E + lin * scale + quad * scale^2.
    double lin = 0.0, quad = 0.0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      if (b.type != BodyType::kDynamic) continue;
      const Mat3 r = b.q.toRotationMatrix();
      const Mat3 inertiaWorld = r * b.inertiaLocal * r.transpose();
      lin += b.desc.mass * b.v.dot(dV[i]) + b.w.dot(inertiaWorld * dW[i]);
      quad += 0.5 * b.desc.mass * dV[i].squaredNorm() + 0.5 * dW[i].dot(inertiaWorld * dW[i]);
    }
    const double allowed = eMax * eMax * std::max(0.0, energyBefore - energyCompressed);
    double scale = 1.0;
    if (lin + quad > allowed) {
      scale = quad > 0.0 ? (-lin + std::sqrt(std::max(0.0, lin * lin + 4.0 * quad * allowed))) / (2.0 * quad) : 0.0;
      scale = std::clamp(scale, 0.0, 1.0);
    }
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      bodies[i].v += scale * dV[i];
      bodies[i].w += scale * dW[i];
      dV[i] *= scale;
    }
  }
  // What the normal impulses did to each body's velocity: the accumulated impulses (warm start
  // included; the shock sweep's part went to the upper body only) and the restitution phase.
  normalVelocityChange.assign(bodies.size(), Vec3::Zero());
  for (auto& [p, ids] : solveOrder)
    for (const SolverContact& cp : p->contacts) {
      const double onA = cp.lambdaN - (cp.shockOnA ? 0.0 : cp.lambdaShock);
      const double onB = cp.lambdaN - (cp.shockOnA ? cp.lambdaShock : 0.0);
      normalVelocityChange[ids[0]] += bodies[ids[0]].invMass * onA * cp.c.normal;
      normalVelocityChange[ids[1]] -= bodies[ids[1]].invMass * onB * cp.c.normal;
    }
  if (eMax > 0.0)
    for (std::size_t i = 0; i < bodies.size(); ++i) normalVelocityChange[i] += dV[i];
  for (auto& [p, ids] : solveOrder)
    for (SolverContact& cp : p->contacts) {
      cp.restitution = 0.0;  // a contact bounces once
      cp.frictionImpulse = cp.lambdaT1 * cp.t1 + cp.lambdaT2 * cp.t2;
    }
  for (auto& [p, ids] : solveOrder) p->patchImpulse = p->patch ? Vec3(p->patchL1 * p->patchT1 + p->patchL2 * p->patchT2) : Vec3::Zero();

  // Split impulses: pseudo velocities that only move positions (never enter v, w).
  for (Body& b : bodies) {
    b.vp.setZero();
    b.wp.setZero();
  }
  for (std::uint32_t it = 0; it < s.positionIterations; ++it) {
    for (auto& [p, ids] : solveOrder) {
      Body& a = bodies[ids[0]];
      Body& b = bodies[ids[1]];
      for (SolverContact& cp : p->contacts) {
        if (cp.targetPos <= 0.0 && cp.lambdaP == 0.0) continue;
        const double vn = (a.vp + a.wp.cross(cp.rA) - b.vp - b.wp.cross(cp.rB)).dot(cp.c.normal);
        const double old = cp.lambdaP;
        cp.lambdaP = std::max(0.0, old + cp.massN * (cp.targetPos - vn));
        const Vec3 impulse = (cp.lambdaP - old) * cp.c.normal;
        a.vp += a.invMass * impulse;
        a.wp += a.invInertiaWorld * cp.rA.cross(impulse);
        b.vp -= b.invMass * impulse;
        b.wp -= b.invInertiaWorld * cp.rB.cross(impulse);
      }
    }
  }
  report.solverSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Support layers for shock propagation: 0 for immovable bodies (static, kinematic, frozen), then
// breadth-first over the pairs with contacts, so a body's layer is the fewest contacts between it
// and something immovable; bodies that touch nothing immovable, directly or through others, get
// none (kNoLayer) and their pairs no shock sweep (zero gravity, a pile in free fall). shockPairs
// lists the pairs of solveOrder between two different layers, ordered by the lower one, within a
// layer in the solver's fixed order by body ids. O(bodies + pairs log pairs), no allocation once
// the vectors have grown.
void World::Impl::orderSupportLayers() {
  constexpr std::uint32_t kNoLayer = std::numeric_limits<std::uint32_t>::max();
  const std::size_t n = bodies.size();
  supportLayer.assign(n, kNoLayer);
  adjacencyStart.assign(n + 1, 0);
  for (auto& [p, ids] : solveOrder)
    if (!p->contacts.empty()) {
      ++adjacencyStart[ids[0] + 1];
      ++adjacencyStart[ids[1] + 1];
    }
  for (std::size_t i = 0; i < n; ++i) adjacencyStart[i + 1] += adjacencyStart[i];
  adjacency.resize(adjacencyStart[n]);
  layerQueue.assign(adjacencyStart.begin(), adjacencyStart.end() - 1);  // fill cursors
  for (auto& [p, ids] : solveOrder)
    if (!p->contacts.empty()) {
      adjacency[layerQueue[ids[0]]++] = ids[1];
      adjacency[layerQueue[ids[1]]++] = ids[0];
    }
  layerQueue.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (bodies[i].invMass == 0.0 && adjacencyStart[i + 1] > adjacencyStart[i]) {
      supportLayer[i] = 0;
      layerQueue.push_back(std::uint32_t(i));
    }
  for (std::size_t head = 0; head < layerQueue.size(); ++head) {
    const std::uint32_t i = layerQueue[head];
    for (std::uint32_t e = adjacencyStart[i]; e < adjacencyStart[i + 1]; ++e) {
      const std::uint32_t j = adjacency[e];
      if (supportLayer[j] != kNoLayer || bodies[j].invMass == 0.0) continue;
      supportLayer[j] = supportLayer[i] + 1;
      layerQueue.push_back(j);
    }
  }
  tallestSupport = layerQueue.empty() ? 0 : supportLayer[layerQueue.back()];
  // A body on an immovable one that carries nothing is solved by the iterations exactly as the
  // sweep would solve it (the immovable side has no mass to share): such pairs are left out, so a
  // single body resting or sliding on the ground is solved as before.
  carries.assign(n, 0);
  for (auto& [p, ids] : solveOrder) {
    const std::uint32_t la = supportLayer[ids[0]], lb = supportLayer[ids[1]];
    if (p->contacts.empty() || la == lb || la == kNoLayer || lb == kNoLayer) continue;
    carries[la < lb ? ids[0] : ids[1]] = 1;
  }
  shockPairs.clear();
  for (std::size_t k = 0; k < solveOrder.size(); ++k) {
    const auto& [p, ids] = solveOrder[k];
    const std::uint32_t la = supportLayer[ids[0]], lb = supportLayer[ids[1]];
    if (p->contacts.empty() || la == lb || la == kNoLayer || lb == kNoLayer) continue;
    if (std::min(la, lb) == 0 && !carries[la < lb ? ids[1] : ids[0]]) continue;
    shockPairs.push_back(std::uint32_t(k));
  }
  // By lower layer, then by the solver's order (a total order: std::sort, which unlike
  // std::stable_sort needs no buffer, gives one result).
  std::sort(shockPairs.begin(), shockPairs.end(), [&](std::uint32_t l, std::uint32_t r) {
    const auto& il = solveOrder[l].second;
    const auto& ir = solveOrder[r].second;
    const std::uint32_t ll = std::min(supportLayer[il[0]], supportLayer[il[1]]);
    const std::uint32_t lr = std::min(supportLayer[ir[0]], supportLayer[ir[1]]);
    return ll != lr ? ll < lr : l < r;
  });
  // Effective masses of the upper body alone along the normal and the tangents.
  for (std::uint32_t k : shockPairs) {
    auto& [p, ids] = solveOrder[k];
    const bool aLower = supportLayer[ids[0]] < supportLayer[ids[1]];
    const Body& upper = bodies[aLower ? ids[1] : ids[0]];
    for (SolverContact& cp : p->contacts) {
      const Vec3& r = aLower ? cp.rB : cp.rA;
      auto massAlong = [&](const Vec3& dir) {
        const Vec3 rd = r.cross(dir);
        const double kUpper = upper.invMass + rd.dot(upper.invInertiaWorld * rd);
        return kUpper > 0.0 ? 1.0 / kUpper : 0.0;
      };
      cp.shockMassN = massAlong(cp.c.normal);
      cp.shockTangentK = tangentInverseMass(upper.invMass, cp.t1, cp.t2, {{r, &upper.invInertiaWorld}});
    }
  }
}

void World::Impl::collectPressedNormals() {
  pressedNormalCount.assign(bodies.size(), 0);
  pressedNormals.resize(bodies.size());
  auto add = [&](BodyId id, const Vec3& n) {
    std::uint8_t& count = pressedNormalCount[id];
    if (count == 3) return;
    Vec3 rest = n;
    for (std::uint8_t k = 0; k < count; ++k) rest -= rest.dot(pressedNormals[id][k]) * pressedNormals[id][k];
    // A normal within ~11 deg of the span so far adds no direction (Gram-Schmidt would blow up
    // its noise).
    if (rest.norm() > 0.2) pressedNormals[id][count++] = rest.normalized();
  };
  // Pressing: a normal or position impulse this substep, or touching (a contact the solver held
  // at zero impulse still bounds the velocity along its normal). Sticking: pressed, with the
  // friction impulse strictly inside the Coulomb cone (integrate says why it matters).
  sticking.assign(bodies.size(), 0);
  for (const auto& [p, ids] : solveOrder) {
    const double mu = pairFriction(bodies[ids[0]], bodies[ids[1]]);
    for (const SolverContact& cp : p->contacts) {
      if (!(cp.lambdaN > 0.0 || cp.lambdaP > 0.0 || cp.separation <= 0.0)) continue;
      add(ids[0], cp.c.normal);
      add(ids[1], cp.c.normal);
      if (cp.lambdaN > 0.0 && std::hypot(cp.lambdaT1, cp.lambdaT2) < (1.0 - 1e-6) * mu * cp.lambdaN)
        sticking[ids[0]] = sticking[ids[1]] = 1;
    }
  }
}

// Positions of a body that some contact presses: semi-implicit Euler (x += v_new h) along the
// normals of the contacts that press it -- the velocity the solver made consistent with them --
// and the trapezoid x += (v_old + v_new) h / 2 along every other direction, where the velocity
// changed under gravity, forces and friction alone: a constant acceleration then gives the exact a t^2 / 2
// instead of a t^2 / 2 + a t h / 2. (That overshoot, 13.5 mm after 2 s down issue 17's 35 deg
// slope at 60 Hz, is larger than the budget's effect on the slide: a run with more narrow-phase
// time, closer to the integrator's answer, ended farther from the analytic one.) Along a pressing
// normal the velocity is the solver's, so non-penetration keeps its first-order guarantee. A body
// that nothing presses (free flight) keeps semi-implicit Euler: with the trapezoid there too, the
// nut of scenes/nut_bolt_rest.json fell onto its flank 20 um deeper than the world's slop allows
// (121 um below the helix, NutBoltScene.NutAtRestScrewsDownUnderASmallTorque).
void World::Impl::integrate(double h) {
  collectPressedNormals();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    Body& b = bodies[i];
    if (b.type == BodyType::kStatic) continue;
    Vec3 change = Vec3::Zero();  // the velocity change along the unpressed directions
    if (b.type == BodyType::kDynamic && pressedNormalCount[i] > 0) {
      // Never a normal impulse's: its direction may lie outside the pressed span (normals within
      // ~11 deg of it add none), and the trapezoid on an impulse moves the body off the line its
      // momentum runs along (a frictionless collision lost 3e-4 of its angular momentum). Unless
      // a contact sticks: its static friction then balances the tangential parts of the normal
      // impulses, both constraint forces, and leaving out one of the two integrates the other as
      // if it were a smooth force (a 1 kg box pinched under a 1,000 kg one by normals 0.04 deg
      // apart crept 1 mm per step on the ground's friction against the upper normal's tangential
      // part). Their sum, the whole velocity change, is what the body felt.
      change = b.v - substepStartVelocity[i];
      if (!sticking[i]) change -= normalVelocityChange[i];
      for (std::uint8_t k = 0; k < pressedNormalCount[i]; ++k) change -= change.dot(pressedNormals[i][k]) * pressedNormals[i][k];
    }
    b.x += (b.v + b.vp - 0.5 * change) * h;
    const Vec3 w = b.w + b.wp;
    const Vec3 lWorld = b.type == BodyType::kDynamic ? Vec3(b.q * (b.inertiaLocal * (b.q.conjugate() * b.w))) : Vec3::Zero();
    const Quat dq(0.0, w.x() * 0.5 * h, w.y() * 0.5 * h, w.z() * 0.5 * h);
    Quat q = b.q;
    q.coeffs() += (dq * b.q).coeffs();
    b.q = q.normalized();
    // Keep the angular momentum of a freely rotating body exactly: the world inertia turned
    // with the body, so w = I_world^-1 L (a constant w would change L for non-spherical inertia).
    if (b.type == BodyType::kDynamic) {
      b.invInertiaWorld = worldInverseInertia(b.invInertiaLocal, b.q);
      b.w = b.invInertiaWorld * lWorld;
    }
    b.vp.setZero();
    b.wp.setZero();
    if (b.type == BodyType::kDynamic && finite(b.x) && ((b.x.array() < settings.bounds.min.array()).any() ||
                                                        (b.x.array() > settings.bounds.max.array()).any())) {
      report.leftBounds.push_back(BodyId(i));
      b.type = BodyType::kStatic;
      b.invMass = 0.0;
      b.invInertiaLocal.setZero();
      b.invInertiaWorld.setZero();
      b.v.setZero();
      b.w.setZero();
    }
  }
}

const StepReport& World::step(double dt) {
  if (!(dt > 0.0 && std::isfinite(dt)))
    throw Error(ErrorCode::kInvalidArgument, "step: dt must be > 0 and finite, got " + std::to_string(dt));
  Impl& m = *impl_;
  m.report = StepReport{};
  m.pairReports.clear();
  m.beginStep();
  // Substeps are for bodies that can touch something during the step: one whose box, grown by
  // the distance it can move in the whole step, overlaps no other body's grown box cannot meet
  // (or tunnel through) anything before the next step, however fast it is -- e.g. a body falling
  // alone, or one that fell out of the bin (docs/dynamics.md: such bodies kept the whole bin at
  // 13 substeps). The grown boxes are the substeps' broad-phase boxes over dt instead of h, so
  // every pair a substep can find is among these.
  double maxTravel = 0.0, minExtent = std::numeric_limits<double>::infinity();
  m.boxes.resize(m.bodies.size());
  m.active.resize(m.bodies.size());
  m.stepTravel.assign(m.bodies.size(), 0.0);
  for (std::size_t i = 0; i < m.bodies.size(); ++i) {
    const Body& b = m.bodies[i];
    minExtent = std::min(minExtent, std::max(b.minExtent, 1e-9));
    m.active[i] = b.type != BodyType::kStatic;
    if (m.active[i]) {
      const double speed = (b.v + m.settings.gravity * dt).norm() + b.w.norm() * 0.5 * b.localBox.diagonal();
      m.stepTravel[i] = speed * dt;
    }
    m.boxes[i] = b.worldBox(m.stepTravel[i]);
  }
  m.findPairsWithinLimit(m.boxes, m.active, m.candidates);
  m.filterCandidates(m.candidates);
  m.stepPairs = m.candidates.size();
  // Two rules, the larger wins: no body travels more than kTravelFraction of the thinnest
  // extent (no tunnelling), and two bodies that may touch this step travel together at most
  // kArrivalTravelRel of the smaller diagonal (no deep first contact; capped, see above).
  double arrivalSubsteps = 0.0;
  for (const BodyPair& c : m.candidates) {
    maxTravel = std::max({maxTravel, m.stepTravel[c[0]], m.stepTravel[c[1]]});
    const double diag = std::min(m.bodies[c[0]].desc.shape->diagonal(), m.bodies[c[1]].desc.shape->diagonal());
    const double unit = kArrivalTravelRel * diag;
    arrivalSubsteps = std::max({arrivalSubsteps, std::min((m.stepTravel[c[0]] + m.stepTravel[c[1]]) / unit, kMaxArrivalSubsteps),
                                approachSubsteps(m.arrivalTravel(c, dt), diag)});
  }
  // At least minSubsteps, and a substep per body of the tallest stack, up to kMaxStackSubsteps
  // (the support layers of the last substep's contact graph; docs/dynamics.md, "One step").
  const std::uint32_t leastSubsteps =
      std::clamp(std::min(m.tallestSupport, kMaxStackSubsteps), m.settings.minSubsteps, m.settings.maxSubsteps);
  std::uint32_t n = leastSubsteps;
  if (std::isfinite(minExtent) && maxTravel > 0.0) {
    const double want =
        std::ceil(std::max(arrivalSubsteps, maxTravel / (kTravelFraction * minExtent)));
    n = std::isfinite(want) ? std::uint32_t(std::clamp(want, double(n), double(m.settings.maxSubsteps))) : m.settings.maxSubsteps;
  }
  m.report.substeps = n;
  m.velocityIterationsNow = m.settings.velocityIterations;
  if (m.settings.minSubstepIterations > 0) {
    // velocityIterations per substep at the least substeps (minSubsteps, or a stack's); a step
    // that needs more substeps (fast bodies) spreads the same iterations over them, at least
    // minSubstepIterations each.
    const std::uint64_t perStep = std::uint64_t(m.settings.velocityIterations) * leastSubsteps;
    m.velocityIterationsNow = std::uint32_t(std::min<std::uint64_t>(
        m.settings.velocityIterations, std::max<std::uint64_t>(m.settings.minSubstepIterations, (perStep + n - 1) / n)));
  }
  // A time budget becomes budget units at the narrow phase's measured time per unit (an
  // exponential average over the previous steps), so it is divided exactly as a test budget is
  // (per-query deadlines instead starved the pairs late in the order: each query's fixed cost --
  // its first batch of tests, the manifold -- is a large part of a few-microsecond share).
  std::uint64_t budget = m.settings.budgetTests;
  const bool timedStep = m.settings.budgetMicros > 0.0;
  if (timedStep) {
    const double units = std::max(1.0, std::floor(m.settings.budgetMicros / m.microsPerUnit));
    const std::uint64_t fromTime = units >= 1e15 ? std::uint64_t(1e15) : std::uint64_t(units);
    budget = budget == 0 ? fromTime : std::min(budget, fromTime);
  }
  m.report.testsBudget = budget;
  const double h = dt / n;
  // The budget is per step: each substep may spend an equal share of what the step has left,
  // rounded up (so a substep with anything left gets at least one test), and what a substep
  // does not spend rolls over to the next. The step never spends more than `budget`.
  const bool limited = budget != 0;
  m.report.timeBudgetMicros = m.settings.budgetMicros;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint64_t substepsLeft = n - i;
    const std::uint64_t allowance = limited ? substepAllowance(budget, m.report.budgetSpent, i, n) : 0;
    // The time budget's backstop likewise: an equal share of what the step has left.
    const double timeLeft = std::max(0.0, m.settings.budgetMicros - m.report.timeSpentMicros) * 1e-6;
    const double timeAllowance = timedStep ? timeLeft / static_cast<double>(substepsLeft) : -1.0;
    const std::uint64_t stepLeft = limited ? budget - std::min(budget, m.report.budgetSpent) : 0;
    m.substep(h, limited, allowance, stepLeft, (budget + n - 1) / n, n - i, timeAllowance);
    m.checkFinite();
  }
  if (timedStep && m.report.unitsWorked > 0) {
    // Per unit of work done, not per unit charged: the time of the uncharged roots' answers
    // divided by the charged units fed back -- a higher estimate, fewer units, more pairs answered
    // uncharged -- until the 200-body bin's cfm at 1,000 us per frame had 1 unit per frame, skipped
    // 4,000 pairs per frame and ended with 76 bodies below the floor's top.
    const double measured = m.report.timeSpentMicros / static_cast<double>(m.report.unitsWorked);
    // A step the OS preempted measures milliseconds for a few units; clipped to 4x the estimate,
    // one such step cannot starve the next dozen (one 1 ms step made the estimate 8x too high).
    m.microsPerUnit = 0.75 * m.microsPerUnit + 0.25 * std::clamp(measured, 1e-6, 4.0 * m.microsPerUnit);
  }
  for (auto& [key, pr] : m.pairReports) {
    auto it = m.pairs.find(key);
    pr.contacts = it == m.pairs.end() ? 0
                                      : std::uint32_t(std::count_if(it->second.contacts.begin(), it->second.contacts.end(),
                                                                    [](const SolverContact& c) { return !c.hold; }));
    pr.keptFiner = it != m.pairs.end() && it->second.keptFiner;
    m.report.pairs.push_back(pr);
  }
  for (auto& [p, ids] : m.order)
    for (const SolverContact& cp : p->contacts) {
      if (cp.hold) continue;  // a bound the solver holds, no contact
      m.report.contacts.push_back(cp.c);
      m.report.contactBodies.push_back(ids);
      const Body& a = m.bodies[ids[0]];
      const Body& b = m.bodies[ids[1]];
      m.report.contactPoints.push_back({pointOnA(a, cp.anchorA, cp.c.normal), pointOnB(b, cp.anchorB, cp.c.normal)});
    }
  m.endStep();
  return m.report;
}

std::size_t World::bodyCount() const noexcept { return impl_->bodies.size(); }

namespace {
// An id comes from the caller (often from a file or a loop bound), so it is checked in Release
// too: one compare per call, against an out-of-bounds read.
const Body& bodyAt(const std::vector<Body>& bodies, BodyId id, const char* accessor) {
  if (id >= bodies.size()) {
    throw Error(ErrorCode::kInvalidArgument, std::string("World::") + accessor + ": body id " + std::to_string(id) +
                                                 " out of range (the world has " + std::to_string(bodies.size()) +
                                                 " bodies)");
  }
  if (bodies[id].removed)
    throw Error(ErrorCode::kInvalidArgument,
                std::string("World::") + accessor + ": body " + std::to_string(id) + " was removed");
  return bodies[id];
}
}  // namespace

RigidBodyState World::state(BodyId id) const {
  const Body& b = bodyAt(impl_->bodies, id, "state");
  return RigidBodyState{b.x - b.q * b.comLocal, b.q, b.v, b.w};
}
const RigidBodyDesc& World::desc(BodyId id) const { return bodyAt(impl_->bodies, id, "desc").desc; }
BodyType World::type(BodyId id) const { return bodyAt(impl_->bodies, id, "type").type; }
double World::mass(BodyId id) const {
  const Body& b = bodyAt(impl_->bodies, id, "mass");
  return b.type == BodyType::kDynamic ? b.desc.mass : 0.0;
}

Vec3 World::linearMomentum() const {
  Vec3 p = Vec3::Zero();
  for (const Body& b : impl_->bodies)
    if (b.type == BodyType::kDynamic) p += b.desc.mass * b.v;
  return p;
}
Vec3 World::angularMomentum() const {
  Vec3 l = Vec3::Zero();
  for (const Body& b : impl_->bodies)
    if (b.type == BodyType::kDynamic)
      l += b.desc.mass * b.x.cross(b.v) + b.q * (b.inertiaLocal * (b.q.conjugate() * b.w));
  return l;
}
double World::kineticEnergy() const {
  double e = 0.0;
  for (const Body& b : impl_->bodies)
    if (b.type == BodyType::kDynamic) {
      const Vec3 wl = b.q.conjugate() * b.w;
      e += 0.5 * b.desc.mass * b.v.squaredNorm() + 0.5 * wl.dot(b.inertiaLocal * wl);
    }
  return e;
}
double World::potentialEnergy() const {
  double e = 0.0;
  for (const Body& b : impl_->bodies)
    if (b.type == BodyType::kDynamic) e -= b.desc.mass * impl_->settings.gravity.dot(b.x);
  return e;
}
const WorldSettings& World::settings() const noexcept { return impl_->settings; }
void World::setBudgetTests(std::uint64_t tests) { impl_->settings.budgetTests = tests; }
void World::setModel(ContactModel model) {
  if (model != impl_->settings.model) impl_->pairs.clear();
  impl_->settings.model = model;
}

std::uint64_t World::stateHash() const {
  // FNV-1a over the raw bits of every state component.
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&](double d) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    for (int i = 0; i < 8; ++i) {
      hash ^= (bits >> (8 * i)) & 0xffu;
      hash *= 1099511628211ull;
    }
  };
  for (const Body& b : impl_->bodies) {
    for (int k = 0; k < 3; ++k) {
      mix(b.x[k]);
      mix(b.v[k]);
      mix(b.w[k]);
    }
    for (int k = 0; k < 4; ++k) mix(b.q.coeffs()[k]);
  }
  return hash;
}

// ---- World editing and queries (world.h). Kept apart from the step above: they only set state
// that the step reads at three points (filterCandidates after each broad phase,
// applyExternalForces after gravity, runContactCallback between constraint preparation and the
// solver). -------------------------------------------------------------------------------------

namespace {
Body& editableBody(std::vector<Body>& bodies, BodyId id, const char* call) {
  return const_cast<Body&>(bodyAt(bodies, id, call));
}
void requireFinite(const Vec3& v, BodyId id, const char* call, const char* what) {
  if (!v.allFinite())
    throw Error(ErrorCode::kInvalidArgument,
                std::string("World::") + call + ": body " + std::to_string(id) + ": " + what + " must be finite");
}
}  // namespace

BodyId World::addBody(const RigidBodyDesc& desc, double scale) {
  if (!(scale > 0.0 && std::isfinite(scale)))
    throw Error(ErrorCode::kInvalidArgument, "body " + std::to_string(impl_->bodies.size()) + " '" + desc.name +
                                                 "': scale must be > 0 and finite, got " + std::to_string(scale));
  if (!desc.shape || scale == 1.0) return addBody(desc);
  std::shared_ptr<const CollisionBody> scaled;
  for (const Impl::ScaledShape& s : impl_->scaledShapes)
    if (s.source == desc.shape && s.scale == scale) scaled = s.scaled;
  if (!scaled) {
    scaled = scaleCollisionBody(*desc.shape, scale);
    impl_->scaledShapes.push_back({desc.shape, scale, scaled});
  }
  RigidBodyDesc d = desc;
  d.shape = std::move(scaled);
  return addBody(d);
}

bool World::contains(BodyId id) const noexcept { return id < impl_->bodies.size() && !impl_->bodies[id].removed; }

void World::Impl::forgetPairsOf(BodyId id) {
  for (auto it = pairs.begin(); it != pairs.end();) {
    const BodyId a = BodyId(it->first >> 32), b = BodyId(it->first & 0xffffffffu);
    it = a == id || b == id ? pairs.erase(it) : std::next(it);
  }
}

void World::removeBody(BodyId id) {
  Body& b = editableBody(impl_->bodies, id, "removeBody");
  // A static body with no extent that the broad phase's candidates are filtered against: it
  // neither moves (integrate skips static bodies) nor counts in the momenta and energies, and an
  // infinite extent keeps it out of the step's thinnest-body substep rule. The shape stays: a
  // removed id keeps a small record (ids are not reused), and the step never reads it.
  b.removed = true;
  b.type = BodyType::kStatic;
  b.invMass = 0.0;
  b.invInertiaLocal.setZero();
  b.invInertiaWorld.setZero();
  b.v.setZero();
  b.w.setZero();
  b.force.setZero();
  b.torque.setZero();
  b.minExtent = std::numeric_limits<double>::infinity();
  impl_->filtering = true;
  impl_->forgetPairsOf(id);
}

void World::setState(BodyId id, const RigidBodyState& state) {
  Body& b = editableBody(impl_->bodies, id, "setState");
  requireFinite(state.position, id, "setState", "position");
  requireFinite(state.velocity, id, "setState", "velocity");
  requireFinite(state.angularVelocity, id, "setState", "angular velocity");
  if (!state.orientation.coeffs().allFinite())
    throw Error(ErrorCode::kInvalidArgument, "World::setState: body " + std::to_string(id) + ": orientation must be finite");
  const double norm = state.orientation.norm();
  if (!(std::abs(norm - 1.0) <= 1e-3))
    throw Error(ErrorCode::kInvalidArgument, "World::setState: body " + std::to_string(id) +
                                                 ": orientation must be a unit quaternion (|q| = " + std::to_string(norm) + ")");
  if (b.type == BodyType::kStatic && (!state.velocity.isZero(0.0) || !state.angularVelocity.isZero(0.0)))
    throw Error(ErrorCode::kInvalidArgument,
                "World::setState: body " + std::to_string(id) + " is static: its velocities must be zero");
  b.q = state.orientation.normalized();
  b.x = state.position + b.q * b.comLocal;
  b.v = state.velocity;
  b.w = state.angularVelocity;
  b.invInertiaWorld = worldInverseInertia(b.invInertiaLocal, b.q);
  impl_->forgetPairsOf(id);
}

void World::applyForce(BodyId id, const Vec3& force) {
  Body& b = editableBody(impl_->bodies, id, "applyForce");
  requireFinite(force, id, "applyForce", "force");
  if (b.type != BodyType::kDynamic) return;
  b.force += force;
  impl_->forcesPending = true;
}

void World::applyForce(BodyId id, const Vec3& force, const Vec3& pointWorld) {
  Body& b = editableBody(impl_->bodies, id, "applyForce");
  requireFinite(force, id, "applyForce", "force");
  requireFinite(pointWorld, id, "applyForce", "point");
  if (b.type != BodyType::kDynamic) return;
  b.force += force;
  b.torque += (pointWorld - b.x).cross(force);
  impl_->forcesPending = true;
}

void World::applyTorque(BodyId id, const Vec3& torque) {
  Body& b = editableBody(impl_->bodies, id, "applyTorque");
  requireFinite(torque, id, "applyTorque", "torque");
  if (b.type != BodyType::kDynamic) return;
  b.torque += torque;
  impl_->forcesPending = true;
}

void World::applyImpulse(BodyId id, const Vec3& impulse, const Vec3& pointWorld) {
  Body& b = editableBody(impl_->bodies, id, "applyImpulse");
  requireFinite(impulse, id, "applyImpulse", "impulse");
  requireFinite(pointWorld, id, "applyImpulse", "point");
  if (b.type != BodyType::kDynamic) return;
  b.v += b.invMass * impulse;
  b.w += b.invInertiaWorld * (pointWorld - b.x).cross(impulse);
}

void World::setFilter(BodyId id, const CollisionFilter& filter) {
  editableBody(impl_->bodies, id, "setFilter").filter = filter;
  impl_->filtering = true;
}
CollisionFilter World::filter(BodyId id) const { return bodyAt(impl_->bodies, id, "filter").filter; }

void World::setContactCallback(ContactCallback callback) { impl_->contactCallback = std::move(callback); }

Separation World::separation(BodyId a, BodyId b, double maxDistance) const {
  const Body& ba = bodyAt(impl_->bodies, a, "separation");
  const Body& bb = bodyAt(impl_->bodies, b, "separation");
  if (a == b)
    throw Error(ErrorCode::kInvalidArgument, "World::separation: bodies a and b are both " + std::to_string(a));
  if (!(maxDistance >= 0.0))
    throw Error(ErrorCode::kInvalidArgument, "World::separation: maxDistance must be >= 0, got " + std::to_string(maxDistance));
  return detail::separationBetween(*ba.desc.shape, ba.pose(), *bb.desc.shape, bb.pose(), maxDistance,
                                   impl_->separationHeap);
}

// Drops the candidate pairs of removed bodies, pairs their filters keep apart, and pairs the
// contact callback disabled this step: before budget division and narrow phase, so they cost
// nothing. A pair that leaves the candidates forgets its contacts and caches (forgetPairsApart).
void World::Impl::filterCandidates(std::vector<BodyPair>& candidatePairs) const {
  if (!filtering && disabledPairs.empty()) return;
  std::erase_if(candidatePairs, [&](const BodyPair& c) {
    const Body& a = bodies[c[0]];
    const Body& b = bodies[c[1]];
    if (a.removed || b.removed) return true;
    if ((a.filter.group & b.filter.mask) == 0 || (b.filter.group & a.filter.mask) == 0) return true;
    return std::binary_search(disabledPairs.begin(), disabledPairs.end(), pairKey(c[0], c[1]));
  });
}

// Like gravity: each substep's velocities get force / m * h and I^-1 torque * h.
void World::Impl::applyExternalForces(double h) {
  if (!forcesPending) return;
  for (Body& b : bodies)
    if (b.type == BodyType::kDynamic) {
      b.v += b.invMass * h * b.force;
      b.w += b.invInertiaWorld * (h * b.torque);
    }
}

// The contact callback, per pair with contacts in body-id order (the solver's order), so the
// calls are deterministic. A pair it disables loses its contacts now and its candidacy for the
// rest of the step (filterCandidates); its manifold, warm start and coherence cache go with it.
void World::Impl::runContactCallback() {
  for (auto& [p, ids] : solveOrder) {
    if (p->contacts.empty()) continue;
    callbackContacts.clear();
    for (const SolverContact& cp : p->contacts)
      if (!cp.hold) callbackContacts.push_back(cp.c);
    if (callbackContacts.empty()) continue;  // holds only (holdAtBoxes): no contact to show
    const ContactPairEvent event{ids[0], ids[1], callbackContacts, substepIndex};
    if (contactCallback(event)) continue;
    const std::uint64_t key = pairKey(ids[0], ids[1]);
    disabledPairs.insert(std::lower_bound(disabledPairs.begin(), disabledPairs.end(), key), key);
    p->contacts.clear();
    p->previous.clear();
    p->reusable = false;
    p->cache.clear();
  }
  ++substepIndex;
}

void World::Impl::beginStep() {
  disabledPairs.clear();
  substepIndex = 0;
}

void World::Impl::endStep() {
  if (!forcesPending) return;
  for (Body& b : bodies) {
    b.force.setZero();
    b.torque.setZero();
  }
  forcesPending = false;
}

}  // namespace clod
