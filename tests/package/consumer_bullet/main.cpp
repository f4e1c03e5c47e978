// A program outside the clod tree using the installed clod_bullet: a baked unit cube as a
// clod::bullet::MeshShape resting on a btStaticPlaneShape in a Bullet world, clod installed as
// the collider. Prints the cube's resting height (0.5 expected) and the contacts of the last
// substep.
#include <cmath>
#include <cstdio>
#include <memory>

#include <btBulletDynamicsCommon.h>

#include "clod/bake.h"
#include "clod/bullet/collider.h"
#include "clod/primitives.h"

int main() {
  clod::BakeSettings settings;
  settings.sphereTree.depth = 2;
  settings.measureFit = false;
  settings.buildContactTree = false;
  auto cube = std::make_shared<clod::CollisionBody>(
      clod::CollisionBody::fromBake(clod::bakeMesh(clod::makeBox(clod::Vec3(0.5, 0.5, 0.5)), settings).contents));
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, 0, -9.81f));
  btStaticPlaneShape planeShape(btVector3(0, 0, 1), 0);
  btRigidBody ground(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &planeShape));
  world.addRigidBody(&ground);
  clod::bullet::MeshShape shape(cube);
  btVector3 inertia;
  shape.calculateLocalInertia(1, inertia);
  btDefaultMotionState motion(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, 0.55f)));
  btRigidBody body(btRigidBody::btRigidBodyConstructionInfo(1, &motion, &shape, inertia));
  world.addRigidBody(&body);
  int contacts = 0;
  {
    clod::bullet::Collider collider;
    collider.install(world);
    for (int i = 0; i < 60; ++i) world.stepSimulation(btScalar(1.0 / 60), 4, btScalar(1.0 / 240));
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) contacts += dispatcher.getManifoldByIndexInternal(m)->getNumContacts();
    collider.uninstall();
  }
  const double z = double(body.getWorldTransform().getOrigin().z());
  std::printf("clod_bullet: cube at z %.4f on the plane, contacts %d\n", z, contacts);
  world.removeRigidBody(&body);
  world.removeRigidBody(&ground);
  return std::abs(z - 0.5) < 1e-3 && contacts > 0 ? 0 : 1;
}
