// BulletCharacters (mm/world/bullet_character.hpp): a game's capsules walked by Bullet's
// kinematic character controller over a level.

#include "mm/world/bullet_character.hpp"

#include <BulletCollision/CollisionDispatch/btGhostObject.h>
#include <BulletDynamics/Character/btKinematicCharacterController.h>
#include <btBulletCollisionCommon.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "level_mesh.hpp"
#include "mm/runtime/assert.hpp"

namespace mm {
namespace {

// One capsule: its shape, the ghost object Bullet's controller moves, and the controller.
struct Capsule {
  CapsuleSettings settings;
  std::unique_ptr<btCapsuleShape> shape;
  std::unique_ptr<btPairCachingGhostObject> ghost;
  std::unique_ptr<btKinematicCharacterController> controller;
};

}  // namespace

// Declared so that the collision world goes first (it removes the objects' proxies from the
// broadphase), then the broadphase, the objects and the shapes they point to.
struct BulletCharacters::State {
  glm::dvec3 origin{0.0};
  LevelMesh mesh;
  std::unique_ptr<btCollisionObject> mesh_object;
  std::vector<Capsule> capsules;
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  // Keeps each ghost object's list of the objects it overlaps, which the character controller
  // sweeps against and recovers from.
  btGhostPairCallback ghost_pairs;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};

  ~State() {
    for (Capsule& capsule : capsules) world.removeCollisionObject(capsule.ghost.get());
    if (mesh_object) world.removeCollisionObject(mesh_object.get());
  }

  glm::dvec3 feet(const Capsule& capsule) const {
    const btVector3& centre = capsule.ghost->getWorldTransform().getOrigin();
    return origin + glm::dvec3(centre.x(), centre.y() - 0.5 * capsule.settings.height, centre.z());
  }
};

BulletCharacters::BulletCharacters(std::unique_ptr<State> state) : state_(std::move(state)) {}
BulletCharacters::BulletCharacters(BulletCharacters&&) noexcept = default;
BulletCharacters& BulletCharacters::operator=(BulletCharacters&&) noexcept = default;
BulletCharacters::~BulletCharacters() = default;

Result<BulletCharacters> BulletCharacters::create(const Level& level) {
  if (Status valid = level.validate(); !valid) {
    return Error{"the level is not valid: " + valid.message()};
  }
  if (level.triangle_count() == 0) return Error{"the level has no triangles to walk on"};
  auto state = std::make_unique<State>();
  state->origin = level.origin;
  state->broadphase.getOverlappingPairCache()->setInternalGhostPairCallback(&state->ghost_pairs);
  // The character controller's sweeps allow this much penetration: by default the capsule would
  // rest that deep in the ground and stop that deep in walls.
  state->world.getDispatchInfo().m_allowedCcdPenetration = 0.0f;
  state->mesh.build(level);
  state->mesh_object = std::make_unique<btCollisionObject>();
  state->mesh_object->setCollisionShape(state->mesh.shape.get());
  state->mesh_object->setCollisionFlags(btCollisionObject::CF_STATIC_OBJECT);
  state->world.addCollisionObject(state->mesh_object.get(), btBroadphaseProxy::StaticFilter,
                                  btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
  return BulletCharacters(std::move(state));
}

Result<size_t> BulletCharacters::add(const glm::dvec3& feet, const CapsuleSettings& settings) {
  const float values[] = {settings.radius, settings.height, settings.step_height,
                          settings.max_slope, settings.gravity};
  for (float v : values) {
    if (!std::isfinite(v) || v <= 0.0f) {
      return Error{
          "capsule: radius, height, step height, max slope and gravity must be finite "
          "and positive"};
    }
  }
  if (settings.height < 2.0f * settings.radius) {
    return Error{"capsule: the height must be at least twice the radius"};
  }
  if (!finite(feet) || !within(feet, kMaxLevelCoordinate)) {
    return Error{"capsule: the feet must be finite and within ±100000 m of the world origin"};
  }
  State& s = *state_;
  Capsule capsule;
  capsule.settings = settings;
  // Bullet's capsule height is its cylinder part's.
  capsule.shape =
      std::make_unique<btCapsuleShape>(settings.radius, settings.height - 2.0f * settings.radius);
  capsule.ghost = std::make_unique<btPairCachingGhostObject>();
  capsule.ghost->setCollisionShape(capsule.shape.get());
  capsule.ghost->setCollisionFlags(btCollisionObject::CF_CHARACTER_OBJECT);
  capsule.controller = std::make_unique<btKinematicCharacterController>(
      capsule.ghost.get(), capsule.shape.get(), settings.step_height, btVector3(0, 1, 0));
  capsule.controller->setMaxSlope(settings.max_slope);
  capsule.controller->setGravity(btVector3(0, -settings.gravity, 0));
  // Placed upright after the controller is made: its constructor turns the ghost object from
  // its default up axis (Z) to the one given, which would lay a Y capsule on its side.
  btTransform start;
  start.setIdentity();
  start.setOrigin(to_bullet(feet - s.origin + glm::dvec3(0.0, 0.5 * settings.height, 0.0)));
  capsule.ghost->setWorldTransform(start);
  // The capsules collide with the level, not with each other (a crowd's separation is the
  // game's own business).
  s.world.addCollisionObject(capsule.ghost.get(), btBroadphaseProxy::CharacterFilter,
                             btBroadphaseProxy::StaticFilter);
  s.capsules.push_back(std::move(capsule));
  return s.capsules.size() - 1;
}

glm::dvec3 BulletCharacters::move(size_t index, const glm::dvec3& goal, float dt) {
  State& s = *state_;
  MM_ASSERT(index < s.capsules.size());
  Capsule& capsule = s.capsules[index];
  const glm::dvec3 from = s.feet(capsule);
  glm::dvec3 step(goal.x - from.x, 0.0, goal.z - from.z);
  if (!finite(step) || !within(goal, kMaxLevelCoordinate)) step = glm::dvec3(0.0);
  // The walk direction is the displacement of this one step (not a velocity).
  capsule.controller->setWalkDirection(to_bullet(step));
  capsule.controller->updateAction(&s.world, dt);
  return s.feet(capsule);
}

glm::dvec3 BulletCharacters::feet(size_t index) const {
  MM_ASSERT(index < state_->capsules.size());
  return state_->feet(state_->capsules[index]);
}

bool BulletCharacters::on_ground(size_t index) const {
  MM_ASSERT(index < state_->capsules.size());
  return state_->capsules[index].controller->onGround();
}

size_t BulletCharacters::size() const {
  return state_->capsules.size();
}

}  // namespace mm
