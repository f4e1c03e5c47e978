#pragma once
// Contact-tree manifolds pushed out to the rim of their contact area.
//
// The contact tree's contacts are samples on a lattice (contact_sampling.h): the outermost sample
// of a face-on-face overlap lies up to one spacing inside the overlap's rim, so the manifold's
// support polygon is smaller than the true one (a 0.45 m wide box sliding on a slab had its
// contacts 1-3 cm inside its bottom face's edges and tipped over on them). Exact polygon
// clipping (the exact model) puts them at the corners; here each kept contact walks outward from
// the manifold's centroid, in its contact plane, for as long as both fields stay as they were at
// the contact (the point stays on the one surface and under the other), and stops at the rim.

#include <cstdint>
#include <span>

#include "clod/contact.h"
#include "clod/contact_tree.h"
#include "clod/math.h"

namespace clod {

struct ContactRimSettings {
  /// How far a contact may walk, as a fraction of the manifold's radius (largest distance of a
  /// contact from the centroid, in the contact plane). The lattice inset is at most a sample
  /// spacing, a small part of the patch.
  double reachRel = 0.5;
  /// Probes along the walk (equal steps), then halvings between the last probe that held and the
  /// first that did not.
  std::uint32_t steps = 4;
  std::uint32_t halvings = 5;
};

/// Moves the contacts (world frame, normals from B toward A) outward to the rim of their contact
/// area, where the contacts form one face-on-face patch (normals within 2 deg, points in one
/// plane within their depths' spread and eps_s). A probe point q holds when each field is within
/// half its tree's errorAbs (and 1e-9 of the diagonals) of its value at the contact: the walk neither leaves the surface the contact lies
/// on nor changes its depth under the other body, so the configuration -- and the depth -- are
/// the contact's within that error. A moved contact keeps its normal and depth; its error bound
/// grows by the two fields' change between the contact and where it ends.
/// Contacts deeper than -marginAbs take part; fewer than two such: nothing moves. Returns the
/// field queries made (1 + steps + halvings at most per contact).
std::uint32_t extendContactsToRim(const ContactTree& a, const Pose& xfWorldFromA, const ContactTree& b,
                                  const Pose& xfWorldFromB, std::span<Contact> contacts, double marginAbs,
                                  const ContactRimSettings& settings = {});

}  // namespace clod
