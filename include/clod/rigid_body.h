#pragma once
// A rigid body of the world (world.h): its collision shape (a CollisionBody, shared), its mass
// properties and its material, and its state. Units are the scene's (SI in the shipped scenes:
// metres, kilograms, seconds).
//
// Frames: the body's mesh coordinates are its own frame; `position` is where the MESH ORIGIN is
// in the world and `orientation` rotates mesh coordinates into the world (Pose, math.h). The
// centre of mass is RigidBodyDesc::centerOfMass in mesh coordinates; velocity is the velocity of
// the centre of mass, angularVelocity is in the world frame (rad/s).

#include <cstdint>
#include <memory>
#include <string>

#include "clod/collision_body.h"
#include "clod/math.h"

namespace clod {

/// How a body moves. Values are stable (files use them).
enum class BodyType : std::uint8_t {
  kDynamic = 0,    ///< moved by gravity and contacts
  kStatic = 1,     ///< never moves: infinite mass
  kKinematic = 2,  ///< moves with its prescribed (constant) velocity; infinite mass to contacts
};

/// Everything needed to add a body to a World.
struct RigidBodyDesc {
  std::string name;  ///< for reports and error messages
  /// The collision shape; non-null, shared by every body using this mesh.
  std::shared_ptr<const CollisionBody> shape;
  BodyType type = BodyType::kDynamic;
  /// Mass (> 0, finite) and inertia tensor about the centre of mass, mesh axes (symmetric
  /// positive definite) of a dynamic body; ignored for static and kinematic bodies.
  double mass = 1.0;
  Mat3 inertia = Mat3::Identity();
  Vec3 centerOfMass = Vec3::Zero();  ///< mesh coordinates
  /// Coefficient of restitution in [0, 1] and Coulomb friction coefficient >= 0. A pair uses
  /// the larger restitution and the geometric mean of the frictions (Box2D's mixing rules).
  double restitution = 0.0;
  double friction = 0.5;
  Vec3 position = Vec3::Zero();      ///< world position of the mesh origin
  Quat orientation = Quat::Identity();  ///< normalised by World::addBody
  Vec3 velocity = Vec3::Zero();         ///< centre-of-mass velocity
  Vec3 angularVelocity = Vec3::Zero();  ///< world frame, rad/s
  /// When > 0, the body is a ball of this radius about its mesh origin, which must be its centre
  /// of mass; its mesh encloses the ball (every face's plane at least this far from the origin,
  /// makeBallHull). The world keeps each contact's normal and the other body's surface point and
  /// puts the ball's side on the ball (docs/dynamics.md, "Balls"): a ball rolls as a ball, not
  /// as its polyhedron, which rests on a facet. Two balls touch analytically, without a query.
  double ballRadius = 0.0;
};

/// A body's state as the world reports it (same frames as RigidBodyDesc).
struct RigidBodyState {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();
  Vec3 angularVelocity = Vec3::Zero();
};

}  // namespace clod
