#include "clod/contact_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>

#include "clod/error.h"

namespace clod {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A half-space fits its cell "flat" when its fit error is below this fraction of the cell size
// (exactly 0 on a face, ~0.3 of the size for a cell holding a right-angled edge).
constexpr double kFlatFitRel = 0.1;

// True when `hs` (may be null: no surface in the cell) fits a cell of side `size` flat.
bool fitsFlat(const ContactHalfSpace* hs, double size) { return hs && double(hs->fitError) <= kFlatFitRel * size; }

void checkSettings(const ContactSamplingSettings& s) {
  auto bad = [](const std::string& what) { throw Error(ErrorCode::kInvalidArgument, "contact sampling settings: " + what); };
  if (!(std::isfinite(s.marginAbs) && s.marginAbs >= 0.0)) bad("marginAbs must be finite and >= 0");
  if (s.samplesPerCellAxis < 1 || s.samplesPerCellAxis > 16) bad("samplesPerCellAxis must be in 1..16");
  if (!(s.offSurfaceDepthRel >= 0.0 && s.offSurfaceDepthRel <= 1.0)) bad("offSurfaceDepthRel must be in 0..1");
  if (!(s.normalConflictDeg >= 0.0 && s.normalConflictDeg <= 180.0)) bad("normalConflictDeg must be in 0..180");
  if (!(s.patchAngleDeg >= 0.0 && s.patchAngleDeg <= 180.0)) bad("patchAngleDeg must be in 0..180");
  if (s.maxContactsPerPatch < 1) bad("maxContactsPerPatch must be >= 1");
}

bool insideCell(const ContactTree& tree, const ContactCell& cell, const Vec3& p) {
  const Vec3 t = (p - tree.cellMin(cell)) / tree.cellSize(cell.depth);
  return (t.array() >= 0.0).all() && (t.array() < 1.0).all();
}

// Direction of the edge the field of `tree` shows around p (body frame), if it shows one: near
// a straight edge the distance field is constant along the edge, so every gradient around it is
// perpendicular to the edge and the gradients span a plane (a face gives one direction, a
// corner all three). The gradients are taken at p and at p +- rho along each axis; the edge is
// the eigenvector of the smallest eigenvalue of sum g g^T when that eigenvalue is small and
// the middle one is not.
bool edgeDirection(const ContactTree& tree, const Vec3& p, double rho, std::uint32_t maxDepth, Vec3& edge) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  int count = 0;
  for (int k = 0; k < 7; ++k) {
    Vec3 q = p;
    if (k > 0) q[(k - 1) / 2] += (k % 2 ? rho : -rho);
    const Vec3 g = tree.sample(q, maxDepth).gradient;
    const double length = g.norm();
    if (!(length > 1e-12)) continue;
    scatter += (g / length) * (g / length).transpose();
    ++count;
  }
  if (count < 3) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(scatter);
  const Vec3 lambda = solver.eigenvalues();  // ascending
  // Two unit gradients 30 degrees apart already give lambda1 / lambda2 ~ 0.07 (of 7 samples);
  // a third face (a corner) lifts lambda0 toward lambda1.
  if (!(lambda[1] > 0.05 * lambda[2]) || lambda[0] > 0.2 * lambda[1]) return false;
  edge = solver.eigenvectors().col(0).normalized();
  return true;
}

// Normal out of O toward S at world point pWorld where both bodies show an edge: perpendicular
// to both edges (the common normal of two crossing segments), oriented along gO - gS (the
// fields' world gradients: out of O, and into S). False when either field shows no clean edge
// or the edges are within 15 degrees of parallel. Parallel edges have no common perpendicular,
// and the probes cannot tell a touching parallel pair from a face overhanging the other body's
// edge with its own parallel edge a few cells away (both fields "show an edge" within the probe
// radius): there the bisector of the two gradients tilted the face contact's normal by up to
// 26 degrees (commit 44f3c53 broke NarrowPhaseCubeOnCube that way), so the existing rules
// (face wins, else the field gradient) decide instead.
bool edgeEdgeNormal(const ContactTree& treeS, const Vec3& pS, const Pose& xfWorldFromS, double rhoS,
                    const ContactTree& treeO, const Vec3& pO, const Pose& xfWorldFromO, double rhoO,
                    std::uint32_t maxDepth, Vec3& normal) {
  Vec3 edgeS, edgeO;
  if (!edgeDirection(treeS, pS, rhoS, maxDepth, edgeS) || !edgeDirection(treeO, pO, rhoO, maxDepth, edgeO)) return false;
  const Vec3 cross = (xfWorldFromS.rotation * edgeS).cross(xfWorldFromO.rotation * edgeO);
  constexpr double kParallelSin = 0.26;  // edges within 15 degrees count as parallel
  if (!(cross.norm() > kParallelSin)) return false;
  const Vec3 gO = xfWorldFromO.rotation * treeO.sample(pO, maxDepth).gradient.normalized();
  const Vec3 gS = xfWorldFromS.rotation * treeS.sample(pS, maxDepth).gradient.normalized();
  normal = cross.normalized();
  if (normal.dot(gO - gS) < 0.0) normal = -normal;
  return true;
}

// True when both bodies have a face through `pWorld` with outward normal +m or -m (the same
// sign for both, within 10 degrees): coplanar faces facing the same way, i.e. flush. Probed one
// probe radius rho out along +m and -m: outside both bodies there, both fields point along the
// probe's direction.
bool flushAlong(const ContactTree& treeS, const Pose& xfWorldFromS, const ContactTree& treeO, const Pose& xfWorldFromO,
                const Vec3& pWorld, const Vec3& m, double rho, std::uint32_t maxDepth) {
  constexpr double kSameWayCos = 0.98480775301220806;  // cos 10 deg
  for (double sign : {1.0, -1.0}) {
    const Vec3 q = pWorld + (sign * rho) * m;
    const Vec3 gS = xfWorldFromS.rotation * treeS.sample(xfWorldFromS.applyInverse(q), maxDepth).gradient;
    const Vec3 gO = xfWorldFromO.rotation * treeO.sample(xfWorldFromO.applyInverse(q), maxDepth).gradient;
    if (gS.dot(sign * m) >= kSameWayCos * gS.norm() && gO.dot(sign * m) >= kSameWayCos * gO.norm() && gS.norm() > 1e-12 &&
        gO.norm() > 1e-12)
      return true;
  }
  return false;
}

// Where a sample of S lies on S's surface: S's outward normal there (S frame), whether the
// surface is flat there (the half-space of the cell it lies in fits within kFlatFitRel of the
// cell's size), that cell's size, and how far from the zero level the sample may lie.
struct SurfacePoint {
  Vec3 normal;
  bool flat;
  double size;
  double residual;  // |offset|
  double offset;    // S's field at the point: how far outside S's zero level it lies (signed)
  double error;     // the error bound of S's field there
};

// O's distance at the point of S's surface nearest p: p lies `offset` outside S's zero level
// along S's normal, so to first order it is f_O(p) - offset (grad f_O . n_S). The descent below
// compares its steps by it: a step that lands within the projection's tolerance below S's face
// is not deeper into O than where it started, though O's field there says so (a box's corner
// descended 2 mm below its face into a slab and its contact read 4 mm for the overlap's 2). A
// sample reports it as its depth only on a flat leaf: near an edge or a corner S's zero level is
// rounded inside the mesh, and the correction made interrupted answers shallower than the mesh
// there (a random fandisk drop sank 1.7 % at 16 tests).
double distanceAtSurface(const ContactFieldSample& f, const SurfacePoint& s, const Eigen::Matrix3d& sFromO) {
  const double length = f.gradient.norm();
  if (s.offset == 0.0 || !(length > 1e-12)) return f.distance;
  return f.distance - s.offset * (sFromO * f.gradient).dot(s.normal) / length;
}

// True when the two fields prove that S's surface near the sample lies outside O by more than
// the margin and S's error target eps_s: O's distance corrected to S's surface
// (distanceAtSurface) exceeds both fields' error bounds there by that much. A point that the
// projection accepted off S's surface (within its tolerance, outside S) can lie on or inside O
// while S itself stays clear of O: spot, 2 mm above the floor, got zero-depth contacts on its
// hind feet 4.4 mm outside them at 62 tests per query, stopped there on two feet and toppled.
// (Gaps below eps_s are not resolved by the fields; rejecting those too cost a landing bunny the
// contacts on one side of its base, and it tipped over.)
bool provenApart(const ContactFieldSample& f, const SurfacePoint& s, const Eigen::Matrix3d& sFromO, double marginAbs,
                 double epsS) {
  return distanceAtSurface(f, s, sFromO) - s.error - double(f.errorBound) > marginAbs + epsS;
}

// The surface data of S at p from S's field there: normal (the gradient), flatness and size of
// the cell p lies in. False where the gradient vanishes.
bool describeSurface(const ContactTree& tree, const ContactFieldSample& f, SurfacePoint& at) {
  const double length = f.gradient.norm();
  if (!(length > 1e-12)) return false;
  at.normal = f.gradient / length;
  const ContactHalfSpace* hs = tree.halfSpace(f.node);
  at.size = tree.cellSize(f.depth);
  at.flat = fitsFlat(hs, at.size);
  at.offset = f.distance;
  at.residual = std::abs(f.distance);
  at.error = f.errorBound;
  return true;
}

// Moves p (S frame) onto the zero level of S's field by Newton steps along the gradient (one
// step lands on a face, a second settles an edge or a corner). False when it does not get within
// twice the field's error of the surface in four steps (a point near the medial axis, a
// vanishing gradient): such a lattice point has no surface point to stand for. The error counted
// is eps_s, or the cell's bound up to the finest cell's size (cells at the depth limit near
// edges and feet bound theirs above eps_s; with eps_s alone their points failed to land, and spot
// lost the samples under its feet and toppled at 256 tests). Not more: a coarse cell far from the
// surface bounds its error by up to half its diagonal, and a point accepted within twice that lay
// 19 cm off a 1.4 m fandisk -- a contact where the body is not, on which it rocked while its real
// lowest point sank 12 % of its diagonal into the floor.
bool projectOntoSurface(const ContactTree& tree, std::uint32_t maxDepth, Vec3& p, SurfacePoint& at) {
  const double finest = tree.cellSize(tree.maxDepth);
  for (int step = 0; step < 4; ++step) {
    const ContactFieldSample f = tree.sample(p, maxDepth);
    if (!describeSurface(tree, f, at)) return false;
    if (at.residual <= 2.0 * std::max(tree.errorAbs, std::min(f.errorBound, finest))) return true;
    p -= f.distance * at.normal / f.gradient.norm();
  }
  return false;
}

// A point of S's mesh (a support point): on the surface by construction, so its residual is 0
// and the contact's error is O's field's alone.
bool surfacePointAt(const ContactTree& tree, std::uint32_t maxDepth, const Vec3& p, SurfacePoint& at) {
  if (!describeSurface(tree, tree.sample(p, maxDepth), at)) return false;
  at.residual = 0.0;
  at.offset = 0.0;
  at.error = 0.0;
  return true;
}

// An interrupted query's coarse pair spreads its samples evenly over the two cells' overlap,
// which misses a contact region smaller than the spacing: a bunny's base on a box met no sample
// at 16-64 tests per frame until it had sunk 30 % of its diagonal. So a sample of S that lies
// outside O there slides along S's surface down O's field -- the tangential part of O's gradient,
// a Newton step toward O's zero level, at most one spacing per step, kSlideSteps steps -- to
// where S enters O: the local search for the deepest points of Macklin et al. 2020 ("Local
// optimization for robust signed distance field collision"), started from the lattice. On an
// inner non-flat cell each step lands back on S's surface (projectOntoSurface); on a flat one the
// step is in its plane. False when the sample leaves either cell or does not get inside O.
constexpr int kSlideSteps = 4;
// Support points tested per coarse cell: those within this fraction of the cell size of the
// farthest toward the other body (cell_support.h).
constexpr double kSupportBandRel = 0.05;
constexpr int kDescentSteps = 4;  // after entering: on down to the deepest point
// A finished answer's inner cell pair samples its lattice only where a support point of S within
// kGateReachRel of O's cell size of O's cell lies within kGateNearRel of S's cell size of O
// (sampleUnchecked).
constexpr double kGateReachRel = 0.25;
constexpr double kGateNearRel = 0.5;
constexpr double kDescentGainRel = 0.01;  // a descent step must gain this fraction of eps_O

struct SlideFrame {
  const ContactTree& treeS;
  const ContactCell& cellS;
  const ContactTree& treeO;
  const ContactCell& cellO;
  const Pose& xfOFromS;
  Eigen::Matrix3d sFromO;  // rotation of O's frame into S's (for O's gradients)
  std::uint32_t maxDepth;
  double marginAbs;
  bool project;     // land each step on S's surface (inner non-flat cell)
  double maxStep;   // one sample spacing
};

bool slideIntoOther(const SlideFrame& fr, Vec3& pS, SurfacePoint& surface, Vec3& pO, ContactFieldSample& f, bool inside) {
  // Entering is not the answer: a small footprint (a leg, a bunny's base) pierces O's surface, and
  // the point where S enters has depth ~0 while the body is deeper -- the solver then let spot
  // rest 1.4 % of its diagonal inside the ground. So once inside, the slide goes on downhill
  // along S's surface while O's distance keeps falling (each step as long as the depth so far,
  // at most one spacing), and keeps the deepest point it reached (curved surfaces only). A point
  // that starts `inside` O only descends.
  bool entered = inside;
  Vec3 bestS = pS, bestO = pO;
  SurfacePoint bestSurface = surface;
  ContactFieldSample best = f;
  double bestAtSurface = distanceAtSurface(f, surface, fr.sFromO);
  for (int step = 0; step < kSlideSteps + kDescentSteps; ++step) {
    if (!entered && step >= kSlideSteps) break;
    // On a flat face the bottom is the cell's border: descending would pile a tilted box's samples
    // onto its lowest edge and lose the support area (a box sliding down a slope slowed 14 %).
    if (entered && surface.flat) break;
    const Vec3 g = fr.sFromO * f.gradient;
    const Vec3 tangent = g - g.dot(surface.normal) * surface.normal;
    const double slope = tangent.norm();
    if (!(slope > 1e-6)) break;  // O's field does not fall along S's surface here (a local minimum)
    const double length = entered ? std::abs(f.distance) / slope : f.distance / slope;
    pS -= std::min(length, fr.maxStep) * (tangent / slope);
    if (fr.project && !projectOntoSurface(fr.treeS, fr.maxDepth, pS, surface)) break;
    if (!insideCell(fr.treeS, fr.cellS, pS)) break;
    pO = fr.xfOFromS.apply(pS);
    if (!insideCell(fr.treeO, fr.cellO, pO)) break;
    f = fr.treeO.sample(pO, fr.maxDepth);
    const double atSurface = distanceAtSurface(f, surface, fr.sFromO);
    // Past the bottom, or on a plane O's field is level along (a box's corner on a floor, where
    // rounding alone made each step "deeper" and walked the corner's contact 2 cm inward).
    if (entered && atSurface > bestAtSurface - kDescentGainRel * fr.treeO.errorAbs) break;
    if (f.distance <= fr.marginAbs && !provenApart(f, surface, fr.sFromO, fr.marginAbs, fr.treeS.errorAbs)) {
      entered = true;
      bestS = pS, bestO = pO, bestSurface = surface, best = f, bestAtSurface = atSurface;
    }
  }
  if (!entered) return false;
  pS = bestS, pO = bestO, surface = bestSurface, f = best;
  return true;
}

void sampleUnchecked(const ContactTree& treeS, const ContactCell& cellS, const Pose& xfWorldFromS,
                     const ContactTree& treeO, const ContactCell& cellO, const Pose& xfWorldFromO,
                     const ContactSamplingSettings& settings, std::vector<ContactPoint>& out,
                     std::uint64_t* edgeEdgeCount) {
  const ContactHalfSpace* hs = treeS.halfSpace(cellS.node);
  if (!hs) return;
  const double h = treeS.cellSize(cellS.depth);
  const double hO = treeO.cellSize(cellO.depth);
  const Vec3 n(hs->normal[0], hs->normal[1], hs->normal[2]);
  const Vec3 onPlane = treeS.cellCenter(cellS) + double(hs->offset) * n;
  const Vec3 u = n.cross(std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).normalized();
  const Vec3 v = n.cross(u);
  // Samples only count inside both cells, so the spacing follows the smaller one: a coarse
  // cell of a large flat body against a small body's cell (an interrupted query's frontier, a
  // big flat leaf against a small one) would otherwise put only a sample or two into the small
  // cell, all on one side of the small body (a box dropped on a slab at 16 tests got its first
  // contacts under one quarter of its face and tipped over). No two samples closer than 4 eps_s:
  // the field cannot tell such points apart.
  // Only for an interrupted query's coarse (inner) cell: at leaves the finer lattice puts samples
  // right beside the other body's edges, whose field there points out of its side faces (the
  // box-on-box tests' normals turned 90 degrees), and leaves are small enough on their own.
  const double hMin = treeS.isLeaf(cellS.node) ? h : std::min(h, hO);
  const double perAxis = std::clamp(std::floor(hMin / (4.0 * treeS.errorAbs)), 1.0, double(settings.samplesPerCellAxis));
  const double spacing = hMin / perAxis;
  // The plane meets the smaller cell within a disc of radius half its diagonal around the
  // projection of its centre (samples stay on a lattice anchored at onPlane, the same for every
  // partner cell of cellS).
  const double radiusMin = 0.8660254037844386 * hMin;
  int i0 = 0, j0 = 0;
  if (hMin < h) {
    const Vec3 centreO = xfWorldFromS.applyInverse(xfWorldFromO.apply(treeO.cellCenter(cellO)));
    i0 = static_cast<int>(std::lround(u.dot(centreO - onPlane) / spacing));
    j0 = static_cast<int>(std::lround(v.dot(centreO - onPlane) / spacing));
  }
  int reach = static_cast<int>(std::ceil(radiusMin / spacing));
  // A pair of an interrupted query's frontier (a coarse inner cell on either side; a slab's big
  // flat leaf against a box's root cell): spread the samples over the part of the plane that
  // lies in both cells instead of over a lattice anchored at S's plane point. (Leaf pairs keep
  // the anchored lattice: spread over the overlap of two leaves it puts samples right beside the
  // other body's edges, whose field there points out of its side faces.) The
  // anchored lattice met a small partner cell in at most a sample or two, often on a cell
  // border: a box on a slab whose frontier held the slab's eight 2.6 m cells against the box's
  // root cell got one contact from all eight pairs (the stack then toppled at 256 tests per
  // frame). The overlap of the two cells' boxes (O's as a box in S's frame), projected onto
  // the plane, gets perAxis x perAxis samples at the centres of an even grid over it.
  bool spread = false;
  Vec3 spreadOrigin = Vec3::Zero();
  double spreadStepU = 0.0, spreadStepV = 0.0;
  if (!treeS.isLeaf(cellS.node) || !treeO.isLeaf(cellO.node)) {
    const Pose xfSFromO = xfWorldFromS.inverse() * xfWorldFromO;
    const Vec3 minO = treeO.cellMin(cellO), sizeO = Vec3::Constant(hO);
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner = minO + Vec3((k & 1) ? sizeO.x() : 0.0, (k & 2) ? sizeO.y() : 0.0, (k & 4) ? sizeO.z() : 0.0);
      const Vec3 inS = xfSFromO.apply(corner);
      lo = lo.cwiseMin(inS);
      hi = hi.cwiseMax(inS);
    }
    const Vec3 minS = treeS.cellMin(cellS);
    lo = lo.cwiseMax(minS);
    hi = hi.cwiseMin(minS + Vec3::Constant(h));
    if ((lo.array() <= hi.array()).all()) {
      double uLo = std::numeric_limits<double>::infinity(), uHi = -uLo, vLo = uLo, vHi = -uLo;
      for (int k = 0; k < 8; ++k) {
        const Vec3 corner((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
        uLo = std::min(uLo, u.dot(corner - onPlane));
        uHi = std::max(uHi, u.dot(corner - onPlane));
        vLo = std::min(vLo, v.dot(corner - onPlane));
        vHi = std::max(vHi, v.dot(corner - onPlane));
      }
      spread = true;
      spreadStepU = (uHi - uLo) / perAxis;
      spreadStepV = (vHi - vLo) / perAxis;
      spreadOrigin = onPlane + (uLo + 0.5 * spreadStepU) * u + (vLo + 0.5 * spreadStepV) * v;
      i0 = j0 = 0;
      reach = static_cast<int>(perAxis) - 1;
    }
  }
  const double conflictCos = std::cos(settings.normalConflictDeg * kPi / 180.0);
  const std::size_t firstOut = out.size();
  const bool flatS = fitsFlat(hs, h);
  // The plane of an inner cell that holds edges, corners or several faces is no surface (a
  // slab's 5 m cell fits a plane through the slab's middle, standing on end): its lattice points
  // would be phantom surface points, and a box sliding over the slab at 256 tests per frame
  // met such a wall and was thrown back. There the lattice points are moved onto S's surface
  // along S's own field first (projectOntoSurface), and the normal, flatness and probe radius
  // are those of the surface where they land. Leaves keep their plane: within a leaf's size
  // the plane is the surface up to its fit error, and the edge rules below handle the rest.
  const bool project = !flatS && !treeS.isLeaf(cellS.node);
  const int layers = settings.offSurfaceDepthRel > 0.0 ? 2 : 1;
  const int iFirst = spread ? 0 : i0 - reach, jFirst = spread ? 0 : j0 - reach;
  const Pose xfOFromS = xfWorldFromO.inverse() * xfWorldFromS;
  const SlideFrame slide{treeS, cellS, treeO, cellO, xfOFromS, xfOFromS.rotation.conjugate().toRotationMatrix(),
                         settings.maxDepth, settings.marginAbs, project,
                         spread ? std::max(spreadStepU, spreadStepV) : spacing};
  // One starting point on S's surface: its off-surface layers, the test against O's field, the
  // slide into O, the normal rules, the contact.
  // support: a support point inside O (on S's cell's closed boundary, so not tested against
  // it) rather than a lattice point: it descends to its deepest. flatO: O's cell is one plane (the
  // flat-partner path below), whose field is exact to its cell's own bound and shows no edge.
  auto samplePoint = [&](const Vec3& onSurface, SurfacePoint surface, int pointLayers, bool support, bool flatO) {
    Vec3 normalWorldS = xfWorldFromS.rotation * surface.normal;
    for (int layer = 0; layer < pointLayers; ++layer) {
      Vec3 pS = onSurface - (layer * settings.offSurfaceDepthRel * hMin) * surface.normal;
      if (!support && !insideCell(treeS, cellS, pS)) continue;
      // The layer below the surface must lie in S: half a coarse cell below one face of a thin
      // body is past its far face (a 0.45 m box's root cell is 1.1 m), where O's field would
      // report a phantom penetration -- a box resting on a slab got 5-10 cm deep contacts
      // from points outside it, was lifted and tipped 14 degrees.
      if (layer > 0 && !(treeS.sample(pS, settings.maxDepth).distance < 0.0)) continue;
      Vec3 pWorld = xfWorldFromS.apply(pS);
      Vec3 pO = xfWorldFromO.applyInverse(pWorld);
      if (!insideCell(treeO, cellO, pO)) continue;
      ContactFieldSample f = treeO.sample(pO, settings.maxDepth);
      if (f.distance > settings.marginAbs) {
        Vec3 slidS = pS, slidO = pO;
        SurfacePoint slidSurface = surface;
        if (!spread || layer > 0 || !slideIntoOther(slide, slidS, slidSurface, slidO, f, false)) continue;
        pS = slidS;
        pO = slidO;
        surface = slidSurface;
        pWorld = xfWorldFromS.apply(pS);
        normalWorldS = xfWorldFromS.rotation * surface.normal;
      } else if (support && slideIntoOther(slide, pS, surface, pO, f, true)) {
        pWorld = xfWorldFromS.apply(pS);
        normalWorldS = xfWorldFromS.rotation * surface.normal;
      }
      if (provenApart(f, surface, slide.sFromO, settings.marginAbs, treeS.errorAbs)) continue;
      const double gradientLength = f.gradient.norm();
      if (!(gradientLength > 1e-12)) continue;  // flat interpolant: no direction to push
      // (The off-surface layer lies inside S on purpose: its depth is O's field there.)
      const double distance = layer == 0 && surface.flat ? distanceAtSurface(f, surface, slide.sFromO) : f.distance;
      Vec3 normal = xfWorldFromO.rotation * (f.gradient / gradientLength);
      const bool conflict = normal.dot(-normalWorldS) < conflictCos;
      // Where our cell holds an edge, or the other field disagrees with our plane, two edges
      // may be crossing: if both fields show an edge around the sample, neither gradient
      // alone is the contact normal (each leans toward one of its faces), the common
      // perpendicular of the edges is. The gradients must be probed on both sides of each
      // edge's kink (the leaves there may lie on one side), so the probe radius is twice the
      // larger of the two cells.
      const double rho = 2.0 * std::max(surface.size, treeO.cellSize(f.depth));
      // A sample that only grazes the other body (depth within the field's error) where the
      // other field turns away from our surface: a flush side face seen from the face or the
      // edge beside it (a box on an equal box: the upper box's bottom edge lies in the lower
      // box's side plane, and the lower field there points out of that side). It would push
      // sideways along a face that nothing presses on; the cfm model drops such contacts
      // too. Two crossing edges also touch at shallow depths with conflicting fields, so the
      // drop comes after the edge-edge rule has had its say (on our edge).
      // (O's eps_s is no bound of a flat leaf's field, which interpolates its plane exactly: a
      // box's corner 2 mm into a 10 m slab, whose eps_s is 1 cm, would count as grazing. The
      // leaf the sample lies in decides, not only O's cell: a bunny's lowest support point,
      // 0.6 mm into a ground box answered from the two root cells, was dropped as grazing,
      // and the bunny sank with no contact for four frames.)
      const ContactHalfSpace* leafPlaneO = treeO.halfSpace(f.node);
      const bool leafFlatO = fitsFlat(leafPlaneO, treeO.cellSize(f.depth));
      const bool flatLeafO = flatO || leafFlatO;
      const double fieldError = flatLeafO ? double(f.errorBound) : std::max(double(f.errorBound), treeO.errorAbs);
      const bool shallow = -distance <= fieldError + surface.residual;
      const bool grazing = conflict && shallow;
      if (grazing && surface.flat) continue;
      // Within that error band the other field's direction is its rounding, not a surface: next
      // to its edges the interpolated gradient leans toward the side face, if less than the
      // conflict angle (a box sliding down a slope met a zero-depth contact under its front edge
      // tilted 9 degrees back, tipped and lost 12 % of its travel). Our flat face is the one
      // surface known there, so a shallow sample on it pushes along its normal.
      if (shallow && surface.flat) normal = -normalWorldS;
      if (settings.edgeEdgeNormals && !flatO && (conflict || !surface.flat) &&
          edgeEdgeNormal(treeS, pS, xfWorldFromS, rho, treeO, pO, xfWorldFromO, rho, settings.maxDepth, normal)) {
        // Two edges that cross inside a plane both bodies have a face in (the upper box's
        // top edge and the lower box's vertical edge, both in their flush side plane) have
        // that plane's normal as their common perpendicular: a grazing sample there is a
        // flush face too.
        if (grazing && flushAlong(treeS, xfWorldFromS, treeO, xfWorldFromO, pWorld, normal, rho, settings.maxDepth)) continue;
        if (edgeEdgeCount) ++*edgeEdgeCount;
      } else if (grazing && settings.edgeEdgeNormals) {
        continue;  // (with the edge-edge rule off, crossing edges keep their gradient contacts)
      } else if (conflict && surface.flat) {
        // The other body shows an edge or corner here while our cell is a flat face: an edge
        // or vertex on a face pushes along the face normal, not along the rounded field.
        if (leafPlaneO && !leafFlatO) normal = -normalWorldS;
      }
      out.push_back({pWorld, normal, -distance, f.errorBound + surface.residual, 0});
      break;  // the off-surface sample below a contact would only repeat it, deeper
    }
  };
  // O's cell is one plane (a flat cell): S's surface enters it where S reaches farthest toward
  // that plane, so the support points of S's cell that lie below it are the deepest points of
  // the pair -- a box face's cell gives the corners of its piece of the face, which span the
  // contact polygon exactly, where a lattice gave a grid of interior points (more samples, not
  // more answer: a box sliding on a slab met 249 such pairs per query, 2 ms). Each descends
  // along S's surface to its deepest point (curved cells). Where S's cell has no support points
  // (below kCellSupportMaxDepth), the lattice below answers.
  const std::span<const Vec3> supports = treeS.cellSupports(cellS.node);
  // A support point p of S's cell that lies in O's cell and inside O becomes a sample.
  auto sampleSupport = [&](const Vec3& p, bool flatO) {
    const Vec3 pO = xfOFromS.apply(p);
    if (!insideCell(treeO, cellO, pO)) return;
    if (treeO.sample(pO, settings.maxDepth).distance > settings.marginAbs) return;
    SurfacePoint surface;
    if (surfacePointAt(treeS, settings.maxDepth, p, surface)) samplePoint(p, surface, 1, true, flatO);
  };
  const bool flatPartner = settings.flatPartnerSupports && !supports.empty() && treeO.isFlatSurface(cellO.node);
  if (flatPartner) {
    for (const Vec3& p : supports) sampleSupport(p, true);
    // A finished answer stops here. An interrupted one samples its coarse pair's lattice too:
    // a coarse cell's support points along 386 directions can all miss the lowest part of a
    // nearly flat face resting on the floor (a random fandisk drop rested 0.98 % of its
    // diagonal deep at 64 tests with support points alone, 0.61 % with the lattice beside them).
    if (!settings.supportPoints) return;
  }
  // A finished answer's inner cell pair (the traversal stops at resolved cells, not at leaves)
  // samples its lattice only where S's surface may come near O: where a support point of S's
  // cell within a quarter of O's cell of it lies within half of S's cell of O, counting its
  // distance to O's cell on top of O's field there (1-Lipschitz). Elsewhere every lattice point
  // would have cost up to five field queries -- four to move it onto S's surface, one for O --
  // for nothing: most resolved pairs of two deep bodies hold no contact (bunny-1500's deep pair:
  // 824 pairs with a plane on both sides, 263 contacts). A heuristic, not a proof (S's surface
  // can cross O's cell between its support points); measured on 2 x 1,000 touching poses
  // (bench_narrowphase --accuracy=1000 --accuracy-models=contact-tree --accuracy-meshes=bunny,fandisk)
  // every accuracy figure and the poses without a contact are unchanged, and the unlimited query
  // takes 4.56 -> 1.53 ms (bunny-1500) and 3.10 -> 1.68 ms (fandisk). Interrupted answers sample
  // support points and lattice alike (above and below).
  if (!settings.supportPoints && !supports.empty() && !treeS.isLeaf(cellS.node)) {
    const Vec3 lowO = treeO.cellMin(cellO), highO = lowO + Vec3::Constant(hO);
    const double gateReach = kGateReachRel * hO, gateNear = kGateNearRel * h;
    bool comesNear = false;
    for (std::size_t k = 0; k < supports.size() && !comesNear; ++k) {
      const Vec3 pO = xfOFromS.apply(supports[k]);
      const double away = (lowO - pO).cwiseMax(pO - highO).cwiseMax(0.0).norm();
      comesNear = away <= gateReach && treeO.sample(pO, settings.maxDepth).distance + away <= gateNear;
    }
    if (!comesNear) return;
  }
  for (int i = iFirst; i <= i0 + reach; ++i) {
    for (int j = jFirst; j <= j0 + reach; ++j) {
      Vec3 onSurface = spread ? Vec3(spreadOrigin + (i * spreadStepU) * u + (j * spreadStepV) * v)
                              : Vec3(onPlane + (i * spacing) * u + (j * spacing) * v);
      SurfacePoint surface{n, flatS, h, 0.0, 0.0, 0.0};
      if (project && !projectOntoSurface(treeS, settings.maxDepth, onSurface, surface)) continue;
      samplePoint(onSurface, surface, layers, false, false);
    }
  }
  // An interrupted query's coarse cell also offers its support points (cell_support.h): the
  // points of its surface that reach farthest in 386 directions, among them the deepest point
  // of a body entering O where the lattice's spacing is larger than the contact region (a
  // fandisk's corner, a bunny's lowest bump). Where O is flat near the cell, S's deepest point
  // is its support point along minus O's normal, so the points that reach within
  // kSupportBandRel of the cell size as far as any along it are tested: O's gradient where the
  // lattice found its deepest contact, else at the cell's centre (not that contact's normal,
  // which the edge rules may have turned: spot's lowest foot was missed along a normal 21
  // degrees off the floor's). Each tested point inside O descends along S's surface to its
  // deepest (slideIntoOther). They lie on the cell's closed boundary, so the own-cell test is
  // skipped; the test against O's cell keeps one frontier pair from repeating another's. Only
  // for interrupted answers (ContactSamplingSettings::supportPoints), and not where O's cell is
  // flat: the flat-partner test above has tested every support point already.
  if (spread && settings.supportPoints && !flatPartner) {
    if (!supports.empty()) {
      Vec3 probe = xfOFromS.apply(treeS.cellCenter(cellS));
      for (std::size_t i = firstOut, deepest = firstOut; i < out.size(); ++i)
        if (out[i].depth >= out[deepest].depth) deepest = i, probe = xfWorldFromO.applyInverse(out[i].point);
      const Vec3 towardO = -(slide.sFromO * treeO.sample(probe, settings.maxDepth).gradient);
      double farthest = -std::numeric_limits<double>::infinity();
      for (const Vec3& p : supports) farthest = std::max(farthest, towardO.dot(p));
      const double band = kSupportBandRel * h * towardO.norm();
      for (const Vec3& p : supports)
        if (towardO.dot(p) >= farthest - band) sampleSupport(p, false);
    }
  }
}

struct Traversal {
  const ContactTree& a;
  const ContactTree& b;
  const Pose& xfA;
  const Pose& xfB;
  const ContactSamplingSettings& settings;
  std::vector<ContactPoint>& out;
  ContactQueryStats& stats;

  bool leafA(const ContactCell& c) const { return a.isLeaf(c.node) || c.depth >= settings.maxDepth; }
  bool leafB(const ContactCell& c) const { return b.isLeaf(c.node) || c.depth >= settings.maxDepth; }

  // True when the sphere (world centre, radius) lies on the outer side of the half-space of
  // `leaf` farther than the margin plus the plane's fit error: then neither the leaf's samples
  // (on or below the plane) nor its field (>= plane distance - fitError in the cell, see the
  // setting's documentation) can produce a contact inside the sphere. The 1e-6 h slack covers
  // the float rounding of the stored plane.
  bool outsideLeafPlane(const ContactTree& tree, const ContactCell& leaf, const Pose& xf, const Vec3& centreWorld,
                        double radius) const {
    const ContactHalfSpace* hs = tree.halfSpace(leaf.node);
    if (!hs) return false;
    const Vec3 n(hs->normal[0], hs->normal[1], hs->normal[2]);
    const double h = tree.cellSize(leaf.depth);
    const double above = n.dot(xf.applyInverse(centreWorld) - tree.cellCenter(leaf)) - double(hs->offset);
    return above > radius + double(hs->fitError) + settings.marginAbs + 1e-6 * h;
  }

  void visit(const ContactCell& ca, const ContactCell& cb) {
    ++stats.cellPairsVisited;
    // Every sample lies in one cell of each tree, so only sphere pairs that touch can share one.
    const Vec3 centreA = xfA.apply(a.cellCenter(ca));
    const Vec3 centreB = xfB.apply(b.cellCenter(cb));
    const double radiusA = a.cellRadius(ca.depth), radiusB = b.cellRadius(cb.depth);
    const double radii = radiusA + radiusB;
    if ((centreA - centreB).squaredNorm() > radii * radii) return;
    const bool la = leafA(ca), lb = leafB(cb);
    // Paper B: leaf spheres are loose over flat regions, so a leaf's half-space keeps pruning.
    if (settings.leafHalfSpacePruning &&
        ((la && outsideLeafPlane(a, ca, xfA, centreB, radiusB)) || (lb && outsideLeafPlane(b, cb, xfB, centreA, radiusA)))) {
      ++stats.halfSpacePrunes;
      return;
    }
    if (la && lb) {
      if (a.halfSpace(ca.node)) {
        ++stats.cellPairsSampled;
        sampleUnchecked(a, ca, xfA, b, cb, xfB, settings, out, &stats.edgeEdgeNormals);
      }
      if (b.halfSpace(cb.node)) {
        ++stats.cellPairsSampled;
        const std::size_t first = out.size();
        sampleUnchecked(b, cb, xfB, a, ca, xfA, settings, out, &stats.edgeEdgeNormals);
        for (std::size_t i = first; i < out.size(); ++i) {
          out[i].normal = -out[i].normal;  // the convention is "out of B toward A"
          out[i].sampledBody = 1;
        }
      }
      return;
    }
    const bool splitA = !la && (lb || a.cellRadius(ca.depth) >= b.cellRadius(cb.depth));
    for (std::uint32_t o = 0; o < 8; ++o) {
      if (splitA) {
        const ContactCell child = a.childCell(ca, o);
        if (a.minDistance(child) <= settings.marginAbs) visit(child, cb);
      } else {
        const ContactCell child = b.childCell(cb, o);
        if (b.minDistance(child) <= settings.marginAbs) visit(ca, child);
      }
    }
  }
};

// Area of triangle (p1, p2, p) projected along n, signed: which side of line p1-p2 p lies on.
double signedArea(const Vec3& p1, const Vec3& p2, const Vec3& p, const Vec3& n) { return (p2 - p1).cross(p - p1).dot(n); }

}  // namespace

void sampleCellPair(const ContactTree& treeS, const ContactCell& cellS, const Pose& xfWorldFromS,
                    const ContactTree& treeO, const ContactCell& cellO, const Pose& xfWorldFromO,
                    const ContactSamplingSettings& settings, std::vector<ContactPoint>& out) {
  checkSettings(settings);
  sampleUnchecked(treeS, cellS, xfWorldFromS, treeO, cellO, xfWorldFromO, settings, out, nullptr);
}

void findContacts(const ContactTree& treeA, const Pose& xfWorldFromA, const ContactTree& treeB,
                  const Pose& xfWorldFromB, const ContactSamplingSettings& settings,
                  std::vector<ContactPoint>& out, ContactQueryStats* stats) {
  checkSettings(settings);
  out.clear();
  ContactQueryStats local;
  Traversal traversal{treeA, treeB, xfWorldFromA, xfWorldFromB, settings, out, local};
  const ContactCell rootA = treeA.rootCell(), rootB = treeB.rootCell();
  if (treeA.minDistance(rootA) <= settings.marginAbs && treeB.minDistance(rootB) <= settings.marginAbs)
    traversal.visit(rootA, rootB);
  local.rawContacts = out.size();
  reduceContacts(out, settings);
  if (stats) *stats = local;
}

void reduceContacts(std::vector<ContactPoint>& contacts, const ContactSamplingSettings& settings) {
  checkSettings(settings);
  std::sort(contacts.begin(), contacts.end(), [](const ContactPoint& x, const ContactPoint& y) { return x.depth > y.depth; });
  const double patchCos = std::cos(settings.patchAngleDeg * kPi / 180.0);
  const std::size_t keep = settings.maxContactsPerPatch;
  std::size_t write = 0;
  std::size_t begin = 0;
  while (begin < contacts.size()) {
    // The deepest remaining contact founds a patch; gather its members at [begin, end).
    const Vec3 n = contacts[begin].normal;
    const auto endIt = std::partition(contacts.begin() + begin + 1, contacts.end(),
                                      [&](const ContactPoint& c) { return c.normal.dot(n) >= patchCos; });
    const std::size_t end = static_cast<std::size_t>(endIt - contacts.begin());
    std::size_t chosen = begin;  // [begin, chosen) are kept
    auto pick = [&](auto score) {
      if (chosen >= end) return;
      std::size_t best = chosen;
      double bestScore = score(contacts[chosen].point);
      for (std::size_t i = chosen + 1; i < end; ++i) {
        const double s = score(contacts[i].point);
        if (s > bestScore) bestScore = s, best = i;
      }
      std::swap(contacts[chosen], contacts[best]);
      ++chosen;
    };
    if (end - begin <= keep) {
      chosen = end;
    } else {
      Vec3 centroid = Vec3::Zero();
      for (std::size_t i = begin; i < end; ++i) centroid += contacts[i].point;
      centroid /= double(end - begin);
      pick([&](const Vec3& p) { return (p - centroid).squaredNorm(); });
      const Vec3 p1 = contacts[begin].point;
      if (keep >= 2) pick([&](const Vec3& p) { return (p - p1).squaredNorm(); });
      const Vec3 p2 = contacts[begin + 1].point;
      if (keep >= 3) pick([&](const Vec3& p) { return signedArea(p1, p2, p, n); });
      if (keep >= 4) pick([&](const Vec3& p) { return -signedArea(p1, p2, p, n); });
      if (keep >= 5) {
        // Beyond the four that span the patch: the deepest remaining, then farthest-point picks.
        std::size_t deepest = chosen;
        for (std::size_t i = chosen; i < end; ++i)
          if (contacts[i].depth > contacts[deepest].depth) deepest = i;
        std::swap(contacts[chosen], contacts[deepest]);
        ++chosen;
        while (chosen - begin < keep && chosen < end) {
          pick([&](const Vec3& p) {
            double nearest = std::numeric_limits<double>::infinity();
            for (std::size_t k = begin; k < chosen; ++k) nearest = std::min(nearest, (p - contacts[k].point).squaredNorm());
            return nearest;
          });
        }
      }
    }
    for (std::size_t i = begin; i < chosen; ++i) contacts[write++] = contacts[i];
    begin = end;
  }
  contacts.resize(write);
}

}  // namespace clod
