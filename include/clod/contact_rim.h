#pragma once
// Contact-tree manifolds pushed out to the rim of their contact area.
//
// The contact tree's contacts are samples on a lattice (contact_sampling.h): the outermost sample
// of a face-on-face overlap lies up to one spacing inside the overlap's rim, and the manifold
// reduction keeps a spread of samples, not the corners, so the support polygon is smaller than
// the true one (two aligned unit cubes: the nearest contact up to 27 cm from a corner of their
// overlap). Exact polygon clipping (the exact model) puts them at the corners; here each kept
// contact walks outward from the manifold's centroid, in its contact plane, for as long as both
// fields stay as they were at the contact (the point stays on the one surface and under the
// other), then along the rim it met, to a corner.

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

/// Moves the contacts (world frame, normals from B toward A) out to the rim of their contact area
/// and along it, where they form one face-on-face patch: the touching contacts whose normals lie
/// within 2 deg of the deepest one's walk, if their points lie on two parallel planes (within the
/// deepest depth and eps_s; the samples lie on either face). A probe point holds when each field
/// is within half its tree's errorAbs (and 1e-9 of the diagonals) of its value at the contact:
/// the walk neither leaves the surface the contact lies on nor changes its depth under the other
/// body. A walk that met a rim steps back by the fields' change there plus that tolerance. A moved
/// contact keeps its normal and depth; its error bound grows by the fields' change. Contacts
/// shallower than -marginAbs stay. Returns the field queries made (at most 1 + 2 (steps +
/// halvings) per contact, each query sampling both trees).
std::uint32_t extendContactsToRim(const ContactTree& a, const Pose& xfWorldFromA, const ContactTree& b,
                                  const Pose& xfWorldFromB, std::span<Contact> contacts, double marginAbs,
                                  const ContactRimSettings& settings = {});

}  // namespace clod
