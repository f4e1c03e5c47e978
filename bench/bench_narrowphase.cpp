// The anytime narrow phase: time per query and contacts returned, per model and budget, side by
// side with FCL's mesh-mesh collide (OBBRSS, contacts on) and Bullet's GImpact mesh-mesh, plus an
// accuracy harness (normal and point error against the exact model over random touching poses).
//
//   BM_NarrowPhase_Query/<mesh>/<pose>/<model>/<budget>   clod queryContacts, scratch reused
//   BM_NarrowPhase_Deadline/<mesh>/deep/<model>/<T>us     a deadline T µs from the call instead of a test
//                                                         count: overrun past the deadline (counters);
//                                                         ".../answer_after_deadline": with
//                                                         QueryBudget::answerWithinDeadline off
//   BM_NarrowPhase_Fcl/<mesh>/<pose>                      fcl::collide, OBBRSS, all contacts
//   BM_NarrowPhase_Bullet/<mesh>/<pose>                   btCollisionWorld with two GImpact shapes
//
// Meshes: bunny (bunny-1500.obj), fandisk (fandisk.obj), box; each scaled to unit bounding-box
// diagonal and baked in-process (medial sphere-tree, 8-ary, 4 levels below the root; closest
// feature maps, 10 root stacks; contact tree, errorRel 2e-3, depth <= 7). Body B is A's mesh
// turned by a fixed rotation; poses move B along a fixed direction: "touching" is the last
// distance at which the exact model still reports an intersection (bisection), "shallow" is 0.5 %
// of the diagonal deeper, "deep" 15 % deeper, "separated" 5 % beyond touching.
// Counters: contacts, tests (clod), finished (clod).
//
// Accuracy harness: run with --accuracy[=N] (N random touching poses per mesh, default 2000), and
// --accuracy-data=FILE to also write the medians as whitespace-separated columns for gnuplot
// (docs/benchmarks/narrowphase_accuracy.gp).
// For every pose (random rotation of B, random direction, bisection to touching, then 0.5 % of the
// diagonal deeper) every model and budget, FCL and Bullet are timed once and compared with the
// exact model at full budget: normal error = angle between depth-weighted resultant normals;
// depth error = |deepest contact's depth - the exact depth|; point error = distance between the
// manifolds' centroids; lengths in units of the diagonal (1). Times are this thread's CPU time of
// the one call. Prints a markdown table of medians and 95th percentiles.
// --reference=volume compares with the independent volume-gradient reference of tests/support/overlap_reference.h
// instead of the exact model (which then becomes one row like the others; poses unchanged), and
// --reference-resolution=R sets its leaf radius in diagonals (default 2.5e-4, 1/20 of the overlap).
// --accuracy-models=cfm,exact and --accuracy-meshes=bunny,fandisk restrict the rows (names
// as printed, comma-separated; FCL and Bullet are the models "fcl" and "bullet"); the poses stay the
// same (same seeds), so restricted runs compare row by row with full ones.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "clod/bake.h"
#include "clod/contact_tree_builder.h"
#include "clod/mesh_io.h"
#include "clod/primitives.h"
#include "clod/proximity.h"
#include "clod/query.h"
#include "support/overlap_reference.h"

#if defined(CLOD_BENCH_HAVE_FCL)
#include <fcl/narrowphase/collision.h>
#include <fcl/geometry/bvh/BVH_model.h>
#endif
#if defined(CLOD_BENCH_HAVE_BULLET)
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletCollisionCommon.h>
#endif

namespace {

using namespace clod;

const char* const kMeshNames[] = {"bunny", "fandisk", "box"};
const char* const kPoseNames[] = {"deep", "shallow", "separated"};
const std::uint64_t kBudgets[] = {16, 64, 256, 1024, kUnlimitedTests};

TriangleMesh unitMesh(int index) {
  TriangleMesh mesh;
  if (index == 0) mesh = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/bunny-1500.obj").mesh;
  if (index == 1) mesh = loadMesh(std::string(CLOD_SHARED_MESH_DIR) + "/fandisk.obj").mesh;
  if (index == 2) mesh = makeBox(Vec3(1.0, 0.7, 0.5));
  const Aabb box = mesh.bounds();
  for (Vec3& v : mesh.vertices) v = (v - box.center()) / box.diagonal();
  return mesh;
}

#if defined(CLOD_BENCH_HAVE_BULLET)
struct BulletMesh {
  std::vector<int> indices;
  std::vector<btScalar> vertices;
  std::unique_ptr<btTriangleIndexVertexArray> array;
  std::unique_ptr<btGImpactMeshShape> shape;
};
#endif

struct Body {
  std::unique_ptr<CollisionBody> body;
  std::unique_ptr<MeshDistance> distance;  // the mesh's exact distance field (contact tree, reference)
#if defined(CLOD_BENCH_HAVE_FCL)
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fcl;
#endif
#if defined(CLOD_BENCH_HAVE_BULLET)
  BulletMesh bullet;
#endif
};

const Body& body(int index) {
  static std::unique_ptr<Body> cache[3];
  if (cache[index]) return *cache[index];
  auto b = std::make_unique<Body>();
  const TriangleMesh mesh = unitMesh(index);
  BakeSettings settings;
  settings.measureFit = false;
  settings.sphereTree.medialSamples = 5000;
  BakeResult baked = bakeMesh(mesh, settings);
  b->body = std::make_unique<CollisionBody>(CollisionBody::fromBake(baked.contents));
  ContactTreeSettings ct;
  ct.errorRel = 2e-3;
  ct.maxDepth = 7;
  b->distance = std::make_unique<MeshDistance>(mesh);
  b->body->setContactTree(buildContactTree(*b->distance, ct));
#if defined(CLOD_BENCH_HAVE_FCL)
  b->fcl = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  b->fcl->beginModel();
  for (const Triangle& t : mesh.triangles) {
    b->fcl->addTriangle(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
  }
  b->fcl->endModel();
#endif
#if defined(CLOD_BENCH_HAVE_BULLET)
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) b->bullet.indices.push_back(static_cast<int>(t[k]));
  for (const Vec3& v : mesh.vertices)
    for (int k = 0; k < 3; ++k) b->bullet.vertices.push_back(static_cast<btScalar>(v[k]));
  b->bullet.array = std::make_unique<btTriangleIndexVertexArray>(
      static_cast<int>(mesh.triangleCount()), b->bullet.indices.data(), 3 * static_cast<int>(sizeof(int)),
      static_cast<int>(mesh.vertexCount()), b->bullet.vertices.data(), 3 * static_cast<int>(sizeof(btScalar)));
  b->bullet.shape = std::make_unique<btGImpactMeshShape>(b->bullet.array.get());
  b->bullet.shape->updateBound();
#endif
  cache[index] = std::move(b);
  return *cache[index];
}

bool exactColliding(const CollisionBody& a, const Pose& pa, const CollisionBody& b, const Pose& pb,
                    QueryScratch& scratch, QueryResult& result) {
  QuerySettings s;
  s.model = ContactModel::kExact;
  queryContacts(a, pa, b, pb, s, scratch, result);
  return result.colliding;
}

// B's pose at distance t along `dir`, turned by `rotation`.
Pose poseAt(const Quat& rotation, const Vec3& dir, double t) {
  Pose p;
  p.rotation = rotation;
  p.translation = t * dir;
  return p;
}

// Largest t in [0, 2] at which A and B (moved by t along dir) still intersect (bisection, 30 steps).
double touchingDistance(const CollisionBody& a, const CollisionBody& b, const Quat& rotation, const Vec3& dir) {
  QueryScratch scratch;
  QueryResult result;
  double lo = 0.0, hi = 2.0;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (exactColliding(a, Pose{}, b, poseAt(rotation, dir, mid), scratch, result)) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

const Quat& fixedRotation() {
  static const Quat q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  return q;
}
const Vec3& fixedDirection() {
  static const Vec3 d = Vec3(0.3, 1.0, 0.2).normalized();
  return d;
}

Pose benchPose(int mesh, int pose) {
  static double touching[3] = {-1, -1, -1};
  if (touching[mesh] < 0) {
    touching[mesh] = touchingDistance(*body(mesh).body, *body(mesh).body, fixedRotation(), fixedDirection());
  }
  const double offsets[] = {-0.15, -0.005, 0.05};
  return poseAt(fixedRotation(), fixedDirection(), touching[mesh] + offsets[pose]);
}

void BM_NarrowPhase_Query(benchmark::State& state, int mesh, int pose, ContactModel model, std::uint64_t budget) {
  const CollisionBody& a = *body(mesh).body;
  const Pose pb = benchPose(mesh, pose);
  QuerySettings s;
  s.model = model;
  s.budget.maxTests = budget;
  QueryScratch scratch;
  QueryResult result;
  for (auto _ : state) {
    queryContacts(a, Pose{}, a, pb, s, scratch, result);
    benchmark::DoNotOptimize(result.contacts.data());
  }
  state.counters["contacts"] = static_cast<double>(result.contacts.size());
  state.counters["tests"] = static_cast<double>(result.tests);
  state.counters["finished"] = result.finished ? 1.0 : 0.0;
}

// A 1 m box resting 2 mm deep on a 10 x 3 x 0.5 m slab (the world's sliding and resting boxes,
// issue 17): face on a larger face, where the contact tree's flat cells answer with the other
// cell's support points (docs/contact-tree.md). Bodies as the world bakes them (octree spheres,
// contact tree to depth 6).
const CollisionBody& restingBody(bool slab) {
  static std::unique_ptr<CollisionBody> cache[2];
  std::unique_ptr<CollisionBody>& b = cache[slab ? 1 : 0];
  if (b) return *b;
  const TriangleMesh mesh = slab ? makeBox(Vec3(5.0, 1.5, 0.25)) : makeBox(Vec3::Constant(0.5));
  BakeSettings settings;
  settings.measureFit = false;
  settings.sphereTree.method = SphereTreeMethod::kOctree;
  settings.sphereTree.depth = 3;
  settings.buildContactTree = false;
  b = std::make_unique<CollisionBody>(CollisionBody::fromBake(bakeMesh(mesh, settings).contents));
  ContactTreeSettings ct;
  ct.maxDepth = 6;
  b->setContactTree(buildContactTree(MeshDistance(mesh), ct));
  return *b;
}

// supports = false: the contact tree samples every pair's lattice (flatPartnerSupports off).
void BM_NarrowPhase_RestingBox(benchmark::State& state, ContactModel model, std::uint64_t budget, bool supports) {
  const CollisionBody& box = restingBody(false);
  const CollisionBody& slab = restingBody(true);
  const Pose boxPose{Quat::Identity(), Vec3(0.37, 0.1, 0.748)};
  QuerySettings s;
  s.model = model;
  s.budget.maxTests = budget;
  s.contactSampling.flatPartnerSupports = supports;
  QueryScratch scratch;
  QueryResult result;
  for (auto _ : state) {
    queryContacts(box, boxPose, slab, Pose{}, s, scratch, result);
    benchmark::DoNotOptimize(result.contacts.data());
  }
  state.counters["contacts"] = static_cast<double>(result.contacts.size());
  state.counters["raw"] = static_cast<double>(result.rawContacts);
  state.counters["tests"] = static_cast<double>(result.tests);
  state.counters["finished"] = result.finished ? 1.0 : 0.0;
}

double percentile(std::vector<double> v, double q);  // accuracy harness, below

// A deadline instead of a test count: the query must return by the deadline plus at most one
// batch of work (budget.h). Counters: overrun_us_p50 / _p99 (return time - deadline, wall clock,
// over the iterations), tests, frontier and pairs_answered (last iteration), contacts.
void BM_NarrowPhase_Deadline(benchmark::State& state, int mesh, int pose, ContactModel model, double micros,
                             bool answerWithinDeadline) {
  const CollisionBody& a = *body(mesh).body;
  const Pose pb = benchPose(mesh, pose);
  QuerySettings s;
  s.model = model;
  QueryScratch scratch;
  QueryResult result;
  std::vector<double> overruns;
  overruns.reserve(1 << 16);
  for (auto _ : state) {
    s.budget = QueryBudget::microsecondsFromNow(micros);
    s.budget.answerWithinDeadline = answerWithinDeadline;
    queryContacts(a, Pose{}, a, pb, s, scratch, result);
    overruns.push_back(std::chrono::duration<double, std::micro>(QueryBudget::Clock::now() - s.budget.deadline).count());
    benchmark::DoNotOptimize(result.contacts.data());
  }
  state.counters["overrun_us_p50"] = percentile(overruns, 0.5);
  state.counters["overrun_us_p99"] = percentile(overruns, 0.99);
  state.counters["pairs_answered"] = static_cast<double>(result.pairsAnswered);
  state.counters["frontier"] = static_cast<double>(result.frontier.size());
  state.counters["contacts"] = static_cast<double>(result.contacts.size());
  state.counters["tests"] = static_cast<double>(result.tests);
}

#if defined(CLOD_BENCH_HAVE_FCL)
fcl::Transform3d toFcl(const Pose& p) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = p.rotation.toRotationMatrix();
  t.translation() = p.translation;
  return t;
}

std::size_t fclCollide(int mesh, const Pose& pb, fcl::CollisionResultd& result) {
  const auto& geometry = body(mesh).fcl;
  fcl::CollisionObjectd oa(geometry, fcl::Transform3d::Identity());
  fcl::CollisionObjectd ob(geometry, toFcl(pb));
  fcl::CollisionRequestd request(1000000, true);  // all contacts, with contact points and normals
  result.clear();
  fcl::collide(&oa, &ob, request, result);
  return result.numContacts();
}

void BM_NarrowPhase_Fcl(benchmark::State& state, int mesh, int pose) {
  const Pose pb = benchPose(mesh, pose);
  fcl::CollisionResultd result;
  std::size_t contacts = 0;
  for (auto _ : state) {
    contacts = fclCollide(mesh, pb, result);
    benchmark::DoNotOptimize(contacts);
  }
  state.counters["contacts"] = static_cast<double>(contacts);
}
#endif

#if defined(CLOD_BENCH_HAVE_BULLET)
// One collision world per (mesh, pose), as an engine would keep it; a query is one
// performDiscreteCollisionDetection (broad phase of two objects + GImpact narrow phase).
struct BulletScene {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
  btCollisionObject a, b;
  BulletScene(int mesh, const Pose& pb) {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
    btCollisionShape* shape = body(mesh).bullet.shape.get();
    a.setCollisionShape(shape);
    b.setCollisionShape(shape);
    btTransform tb;
    tb.setOrigin(btVector3(pb.translation.x(), pb.translation.y(), pb.translation.z()));
    tb.setRotation(btQuaternion(pb.rotation.x(), pb.rotation.y(), pb.rotation.z(), pb.rotation.w()));
    b.setWorldTransform(tb);
    world.addCollisionObject(&a);
    world.addCollisionObject(&b);
  }
  // Returns the number of manifold points; fills the depth-weighted normal (B -> A) and centroid.
  int step(Vec3* normal = nullptr, Vec3* centroid = nullptr, double* depth = nullptr) {
    world.performDiscreteCollisionDetection();
    int points = 0;
    Vec3 n = Vec3::Zero(), c = Vec3::Zero();
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
      // Bullet's normal on B points from B toward A when body0 = A (m_normalWorldOnB).
      const bool flipped = manifold->getBody0() != &a;
      for (int i = 0; i < manifold->getNumContacts(); ++i) {
        const btManifoldPoint& p = manifold->getContactPoint(i);
        if (p.getDistance() > 0) continue;
        ++points;
        const btVector3 nb = p.m_normalWorldOnB * (flipped ? -1 : 1);
        const double w = std::max(-static_cast<double>(p.getDistance()), 1e-12);
        if (depth) *depth = std::max(*depth, -static_cast<double>(p.getDistance()));
        n += w * Vec3(nb.x(), nb.y(), nb.z());
        const btVector3 pos = p.getPositionWorldOnB();
        c += Vec3(pos.x(), pos.y(), pos.z());
      }
    }
    if (normal && points > 0) *normal = n.normalized();
    if (centroid && points > 0) *centroid = c / points;
    return points;
  }
};

void BM_NarrowPhase_Bullet(benchmark::State& state, int mesh, int pose) {
  BulletScene scene(mesh, benchPose(mesh, pose));
  int points = 0;
  for (auto _ : state) {
    points = scene.step();
    benchmark::DoNotOptimize(points);
  }
  state.counters["contacts"] = points;
}
#endif

// ---------------------------------------------------------------------------------------------
// Accuracy harness.

Vec3 resultantNormal(const std::vector<Contact>& contacts) {
  Vec3 sum = Vec3::Zero();
  for (const Contact& c : contacts) sum += std::max(c.depth, 1e-12) * c.normal;
  return sum.normalized();
}
Vec3 centroid(const std::vector<Contact>& contacts) {
  Vec3 sum = Vec3::Zero();
  for (const Contact& c : contacts) sum += c.point;
  return sum / static_cast<double>(contacts.size());
}

struct Samples {
  std::vector<double> angle, point, depth, micros;
  int missed = 0;
};

// CPU time of this thread: under the shared machine's load, wall time measures the neighbours.
double threadSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double maxDepth(const std::vector<Contact>& contacts) {
  double d = 0.0;
  for (const Contact& c : contacts) d = std::max(d, c.depth);
  return d;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

// Row filter of the accuracy harness: empty = all; else a comma-separated list of names.
bool selected(const char* list, const std::string& name) {
  if (list == nullptr || *list == 0) return true;
  const std::string l = std::string(",") + list + ",";
  return l.find("," + name + ",") != std::string::npos;
}

// What the accuracy harness compares against: clod's exact model at full budget, or the
// independent volume-gradient reference of tests/support/overlap_reference.h (--reference=volume).
struct Reference {
  bool volume = false;
  double resolution = 2.5e-4;  // leaf radius of the volume reference (diag): 1/20 of the 0.005 overlap
};

void runAccuracy(int poses, const char* dataPath, const char* models, const char* meshes, const Reference& reference) {
  std::FILE* data = dataPath != nullptr ? std::fopen(dataPath, "w") : nullptr;
  if (data != nullptr) {
    std::fprintf(data, "# budget 0 = unlimited; FCL/Bullet rows have budget -\n# mesh method budget time_us_median normal_deg_median normal_deg_p95 depth_err_median point_err_median\n");
  }
  std::printf("| mesh | method | budget | median CPU time (us) | normal error median (deg) | p95 (deg) | depth error median (diag) | p95 (diag) | point error median (diag) | p95 (diag) | no contact |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int mesh = 0; mesh < 3; ++mesh) {
    if (!selected(meshes, kMeshNames[mesh])) continue;
    const CollisionBody& a = *body(mesh).body;
    std::mt19937_64 rng(1234 + mesh);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    // methods: 5 models x 5 budgets, then FCL, Bullet
    std::vector<Samples> samples(27);
    std::vector<double> consistency, referenceMicros;  // volume reference: its own accuracy and cost
    int noOverlap = 0;
    QueryScratch scratch;
    QueryResult exact, r;
    for (int k = 0; k < poses; ++k) {
      const Quat rotation = Quat(uni(rng), uni(rng), uni(rng), uni(rng)).normalized();
      const Vec3 dir = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
      const double touching = touchingDistance(a, a, rotation, dir);
      const Pose pb = poseAt(rotation, dir, touching - 0.005);
      QuerySettings s;
      s.model = ContactModel::kExact;
      queryContacts(a, Pose{}, a, pb, s, scratch, exact);
      if (exact.contacts.empty()) continue;
      Vec3 nRef = resultantNormal(exact.contacts);
      Vec3 cRef = centroid(exact.contacts);
      double dRef = maxDepth(exact.contacts);
      if (reference.volume) {
        const MeshDistance& distance = *body(mesh).distance;
        const double t0 = threadSeconds();
        const test::OverlapReference volume = test::overlapReference(distance, Pose{}, distance, pb, reference.resolution);
        referenceMicros.push_back((threadSeconds() - t0) * 1e6);
        if (volume.area == 0 || volume.normal().norm() == 0) {
          ++noOverlap;
          continue;
        }
        consistency.push_back(volume.selfConsistencyDegrees());
        nRef = volume.normal();
        cRef = volume.centroid;
        dRef = volume.depth;
      }
      auto record = [&](Samples& out, double seconds, bool any, const Vec3& n, const Vec3& c, double depth) {
        out.micros.push_back(seconds * 1e6);
        if (!any) {
          ++out.missed;
          return;
        }
        out.angle.push_back(std::acos(std::clamp(n.dot(nRef), -1.0, 1.0)) * 180.0 / 3.14159265358979323846);
        out.point.push_back((c - cRef).norm());
        out.depth.push_back(std::abs(depth - dRef));
      };
      int m = 0;
      for (ContactModel model : allContactModels()) {
        for (std::uint64_t budget : kBudgets) {
          if (!selected(models, std::string(contactModelName(model)))) {
            ++m;
            continue;
          }
          s.model = model;
          s.budget.maxTests = budget;
          const double t0 = threadSeconds();
          queryContacts(a, Pose{}, a, pb, s, scratch, r);
          const double seconds = threadSeconds() - t0;
          record(samples[m++], seconds, !r.contacts.empty(), r.contacts.empty() ? Vec3::Zero() : resultantNormal(r.contacts),
                 r.contacts.empty() ? Vec3::Zero() : centroid(r.contacts), maxDepth(r.contacts));
        }
      }
#if defined(CLOD_BENCH_HAVE_FCL)
      if (selected(models, "fcl")) {
        fcl::CollisionResultd fr;
        const double t0 = threadSeconds();
        const std::size_t n = fclCollide(mesh, pb, fr);
        const double seconds = threadSeconds() - t0;
        Vec3 normal = Vec3::Zero(), c = Vec3::Zero();
        double depth = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
          const auto& contact = fr.getContact(i);
          // FCL's normal points from o1 (A) to o2 (B); ours from B to A. Unweighted: FCL's
          // mesh-mesh contacts carry no meaningful depth (its penetration_depth is per
          // triangle pair; the largest is reported as its depth).
          normal -= contact.normal;
          c += contact.pos;
          depth = std::max(depth, contact.penetration_depth);
        }
        record(samples[25], seconds, n > 0 && normal.norm() > 0, normal.normalized(), n > 0 ? Vec3(c / double(n)) : c, depth);
      }
#endif
#if defined(CLOD_BENCH_HAVE_BULLET)
      if (selected(models, "bullet")) {
        BulletScene scene(mesh, pb);
        Vec3 normal = Vec3::Zero(), c = Vec3::Zero();
        double depth = 0.0;
        const double t0 = threadSeconds();
        const int n = scene.step(&normal, &c, &depth);
        const double seconds = threadSeconds() - t0;
        record(samples[26], seconds, n > 0, normal, c, depth);
      }
#endif
    }
    int m = 0;
    auto row = [&](const std::string& method, const std::string& budget, const Samples& x) {
      if (x.micros.empty()) return;
      std::printf("| %s | %s | %s | %.1f | %.2f | %.2f | %.4f | %.4f | %.4f | %.4f | %d of %zu |\n", kMeshNames[mesh],
                  method.c_str(), budget.c_str(), percentile(x.micros, 0.5), percentile(x.angle, 0.5),
                  percentile(x.angle, 0.95), percentile(x.depth, 0.5), percentile(x.depth, 0.95), percentile(x.point, 0.5),
                  percentile(x.point, 0.95), x.missed, x.micros.size());
      if (data != nullptr) {
        std::string tag = method;
        std::replace(tag.begin(), tag.end(), ' ', '_');
        std::fprintf(data, "%s %s %s %.3f %.3f %.3f %.5f %.5f\n", kMeshNames[mesh], tag.c_str(),
                     budget == "unlimited" ? "0" : budget.c_str(), percentile(x.micros, 0.5), percentile(x.angle, 0.5),
                     percentile(x.angle, 0.95), percentile(x.depth, 0.5), percentile(x.point, 0.5));
      }
    };
    for (ContactModel model : allContactModels()) {
      for (std::uint64_t budget : kBudgets) {
        row(std::string(contactModelName(model)), budget == kUnlimitedTests ? "unlimited" : std::to_string(budget), samples[m++]);
      }
    }
    row("FCL OBBRSS", "-", samples[25]);
    row("Bullet GImpact", "-", samples[26]);
    if (reference.volume) {
      std::printf("\n%s: volume-gradient reference (leaf radius %.1e) on %zu poses (%d without overlap skipped): "
                  "self-consistency (angle between the two surface integrals) median %.2f deg, p95 %.2f deg; "
                  "%.0f ms CPU per pose (median)\n\n",
                  kMeshNames[mesh], reference.resolution, consistency.size(), noOverlap, percentile(consistency, 0.5),
                  percentile(consistency, 0.95), percentile(referenceMicros, 0.5) / 1e3);
    }
  }
  if (data != nullptr) std::fclose(data);
}

}  // namespace

int main(int argc, char** argv) {
  const char* dataPath = nullptr;
  const char* models = nullptr;
  const char* meshes = nullptr;
  Reference reference;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--reference=volume") == 0) reference.volume = true;
    if (std::strncmp(argv[i], "--reference-resolution=", 23) == 0) {
      reference.resolution = std::clamp(std::atof(argv[i] + 23), 1e-6, 1.0);
    }
    if (std::strncmp(argv[i], "--accuracy-data=", 16) == 0) dataPath = argv[i] + 16;
    if (std::strncmp(argv[i], "--accuracy-models=", 18) == 0) models = argv[i] + 18;
    if (std::strncmp(argv[i], "--accuracy-meshes=", 18) == 0) meshes = argv[i] + 18;
  }
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--accuracy", 10) == 0 && (argv[i][10] == '=' || argv[i][10] == 0)) {
      const int poses = argv[i][10] == '=' ? std::atoi(argv[i] + 11) : 2000;
      runAccuracy(std::max(1, poses), dataPath, models, meshes, reference);
      return 0;
    }
  }
  for (int mesh = 0; mesh < 3; ++mesh) {
    for (int pose = 0; pose < 3; ++pose) {
      const std::string prefix = std::string(kMeshNames[mesh]) + "/" + kPoseNames[pose];
      for (ContactModel model : allContactModels()) {
        for (std::uint64_t budget : kBudgets) {
          const std::string name = "BM_NarrowPhase_Query/" + prefix + "/" + std::string(contactModelName(model)) + "/" +
                                   (budget == kUnlimitedTests ? std::string("unlimited") : std::to_string(budget));
          benchmark::RegisterBenchmark(name.c_str(), BM_NarrowPhase_Query, mesh, pose, model, budget)
              ->Unit(benchmark::kMicrosecond);
        }
      }
      if (pose == 0) {
        for (ContactModel model : {ContactModel::kCfm, ContactModel::kContactTree, ContactModel::kExact}) {
          for (double micros : {10.0, 30.0, 100.0}) {
            for (bool within : {true, false}) {
              const std::string name = "BM_NarrowPhase_Deadline/" + prefix + "/" + std::string(contactModelName(model)) +
                                       "/" + std::to_string(static_cast<int>(micros)) + "us" +
                                       (within ? "" : "/answer_after_deadline");
              benchmark::RegisterBenchmark(name.c_str(), BM_NarrowPhase_Deadline, mesh, pose, model, micros, within)
                  ->Unit(benchmark::kMicrosecond);
            }
          }
        }
      }
#if defined(CLOD_BENCH_HAVE_FCL)
      benchmark::RegisterBenchmark(("BM_NarrowPhase_Fcl/" + prefix).c_str(), BM_NarrowPhase_Fcl, mesh, pose)
          ->Unit(benchmark::kMicrosecond);
#endif
#if defined(CLOD_BENCH_HAVE_BULLET)
      benchmark::RegisterBenchmark(("BM_NarrowPhase_Bullet/" + prefix).c_str(), BM_NarrowPhase_Bullet, mesh, pose)
          ->Unit(benchmark::kMicrosecond);
#endif
    }
  }
  for (ContactModel model : {ContactModel::kCfm, ContactModel::kContactTree, ContactModel::kExact}) {
    for (std::uint64_t budget : {std::uint64_t(16), kUnlimitedTests}) {
      const std::string name = "BM_NarrowPhase_RestingBox/" + std::string(contactModelName(model)) + "/" +
                               (budget == kUnlimitedTests ? std::string("unlimited") : std::to_string(budget));
      benchmark::RegisterBenchmark(name.c_str(), BM_NarrowPhase_RestingBox, model, budget, true)
          ->Unit(benchmark::kMicrosecond);
      if (model == ContactModel::kContactTree)
        benchmark::RegisterBenchmark((name + "/lattice").c_str(), BM_NarrowPhase_RestingBox, model, budget, false)
            ->Unit(benchmark::kMicrosecond);
    }
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
