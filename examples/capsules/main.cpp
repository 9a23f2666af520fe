// mm-capsules-example: characters whose capsules the game's own physics moves (Bullet's
// kinematic character controller), the animation kept in sync by mm. The "game-owned capsule"
// integration of docs/world.md; examples/crowd is the plain one on a flat plane.
//
// Every frame, for every character:
//   1. controller.update(dt, input): mm moves its simulation object (where the character wants
//      to be) and picks and blends the animation toward it;
//   2. the game asks its physics to walk the capsule there: Bullet slides it along walls,
//      climbs steps, keeps it on the ground;
//   3. controller.set_simulation_position_world(capsule's feet): mm takes the resolved position
//      back (what the physics refused is taken out of its velocity), keeps the animated root
//      within its clamping distance of it, and puts the body at the capsule's height.
// mm knows nothing of Bullet: the game could use PhysX, Jolt or its own code the same way.
//
// The level, built here from Bullet boxes: a ground, a staircase of six 15 cm risers from
// z = 3 to a 0.9 m high landing, and a wall across the landing at z = 8. The characters stand
// in a row along x at z = 0 and walk (every other one runs) toward +Z: up the stairs, then
// into the wall, where they stop.
//
// Usage: mm-capsules-example DATABASE.mmdb [characters=8] [seconds=8]
// Prints, per character, where its capsule ended, the height of the ground under it (a ray
// down) and the highest it got.

#include <btBulletDynamicsCommon.h>

#include <BulletCollision/CollisionDispatch/btGhostObject.h>
#include <BulletDynamics/Character/btKinematicCharacterController.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <memory>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/controller.hpp"
#include "mm/database/database_file.hpp"

namespace {

// Reads a whole command-line argument as a number; false on anything else ("12abc", "").
template <class T>
bool parse_number(std::string_view text, T& value) {
  const char* end = text.data() + text.size();
  const auto [last, error] = std::from_chars(text.data(), end, value);
  return error == std::errc() && last == end;
}

constexpr float kRadius = 0.3f;  // the capsule: mm's ControllerSettings defaults
constexpr float kHeight = 1.7f;
constexpr float kStepHeight = 0.35f;
constexpr float kDt = 1.0f / 60.0f;

// ---- The level: static boxes in one Bullet collision world.
struct Level {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btGhostPairCallback ghost_pairs;  // keeps each capsule's list of what it overlaps
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
  std::vector<std::unique_ptr<btBoxShape>> shapes;
  std::vector<std::unique_ptr<btCollisionObject>> boxes;

  Level() {
    broadphase.getOverlappingPairCache()->setInternalGhostPairCallback(&ghost_pairs);
    // Bullet's sweeps allow 4 cm of penetration by default: the capsule would rest that deep in
    // the ground. None here.
    world.getDispatchInfo().m_allowedCcdPenetration = 0.0f;
    add_box({-20, -1, -20}, {20, 0, 20});   // the ground, top at y = 0
    for (int step = 0; step < 6; ++step) {  // each riser 0.15 m, each tread 0.35 m
      const float z = 3.0f + 0.35f * static_cast<float>(step);
      add_box({-20, 0, z}, {20, 0.15f * static_cast<float>(step + 1), 20});
    }
    add_box({-20, 0.9f, 8.0f}, {20, 3.0f, 8.5f});  // the wall on the landing
  }
  ~Level() {
    for (auto& box : boxes) world.removeCollisionObject(box.get());
  }

  void add_box(const btVector3& low, const btVector3& high) {
    shapes.push_back(std::make_unique<btBoxShape>((high - low) * 0.5f));
    auto box = std::make_unique<btCollisionObject>();
    box->setCollisionShape(shapes.back().get());
    box->getWorldTransform().setOrigin((low + high) * 0.5f);
    world.addCollisionObject(box.get(), btBroadphaseProxy::StaticFilter,
                             btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
    boxes.push_back(std::move(box));
  }

  // The height of the highest surface under (x, z), by a ray straight down.
  float ground_under(float x, float z) {
    const btVector3 from(x, 10.0f, z);
    const btVector3 to(x, -10.0f, z);
    btCollisionWorld::ClosestRayResultCallback hit(from, to);
    world.rayTest(from, to, hit);
    return hit.hasHit() ? hit.m_hitPointWorld.y() : -10.0f;
  }
};

// ---- A character: mm's controller and the capsule the game's physics moves.
struct Character {
  explicit Character(mm::Controller made) : controller(std::move(made)) {}
  ~Character() {
    if (world != nullptr) world->removeCollisionObject(ghost.get());
  }
  Character(const Character&) = delete;
  Character& operator=(const Character&) = delete;

  mm::Controller controller;
  std::unique_ptr<btCapsuleShape> shape;
  std::unique_ptr<btPairCachingGhostObject> ghost;
  std::unique_ptr<btKinematicCharacterController> physics;
  btCollisionWorld* world = nullptr;  // the capsule's, which must outlive it
  bool run = false;
  float highest = 0.0f;

  // Where the capsule's feet are: its centre is half its height above them.
  glm::dvec3 feet() const {
    const btVector3& centre = ghost->getWorldTransform().getOrigin();
    return {centre.x(), centre.y() - 0.5f * kHeight, centre.z()};
  }
};

std::unique_ptr<Character> spawn(Level& level, mm::Controller controller, float x, bool run) {
  auto c = std::make_unique<Character>(std::move(controller));
  c->run = run;
  c->controller.teleport(glm::vec3(x, 0.0f, 0.0f), 0.0f);  // facing +Z
  c->shape = std::make_unique<btCapsuleShape>(kRadius, kHeight - 2.0f * kRadius);
  c->ghost = std::make_unique<btPairCachingGhostObject>();
  c->ghost->setCollisionShape(c->shape.get());
  c->ghost->setCollisionFlags(btCollisionObject::CF_CHARACTER_OBJECT);
  c->physics = std::make_unique<btKinematicCharacterController>(c->ghost.get(), c->shape.get(),
                                                                kStepHeight, btVector3(0, 1, 0));
  c->physics->setGravity(btVector3(0, -9.81f, 0));
  // After the controller is made: its constructor turns the ghost from Bullet's default up axis
  // (Z) to Y, which would lay the capsule on its side.
  btTransform start;
  start.setIdentity();
  start.setOrigin(btVector3(x, 0.5f * kHeight, 0.0f));
  c->ghost->setWorldTransform(start);
  // Capsules collide with the level only; keeping a crowd apart is another topic.
  level.world.addCollisionObject(c->ghost.get(), btBroadphaseProxy::CharacterFilter,
                                 btBroadphaseProxy::StaticFilter);
  c->world = &level.world;
  return c;
}

// ---- One frame of one character: the three steps of the comment at the top.
void frame(Level& level, Character& c) {
  mm::ControllerInput input;
  input.left_stick = {0.0f, 1.0f};  // straight ahead: +Z, with the camera at yaw 0
  input.run = c.run;
  c.controller.update(kDt, input);

  const glm::dvec3 wanted = c.controller.simulation_position_world();
  const glm::dvec3 feet = c.feet();
  // The walk direction is this frame's displacement; the physics owns the height.
  c.physics->setWalkDirection(btVector3(static_cast<float>(wanted.x - feet.x), 0.0f,
                                        static_cast<float>(wanted.z - feet.z)));
  c.physics->updateAction(&level.world, kDt);

  c.controller.set_simulation_position_world(c.feet());
  c.highest = std::max(c.highest, static_cast<float>(c.feet().y));
  // Render the pose here: c.controller.global_transforms().
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    std::fputs("usage: mm-capsules-example DATABASE.mmdb [characters=8] [seconds=8]\n", stderr);
    return 2;
  }
  int characters = 8;
  float seconds = 8.0f;
  if ((argc > 2 && !parse_number(argv[2], characters)) ||
      (argc > 3 && !parse_number(argv[3], seconds)) || characters < 1 || characters > 1000 ||
      !(seconds > 0.0f && seconds <= 600.0f)) {
    std::fputs(
        "mm-capsules-example: characters is a whole number in [1, 1000], seconds a number "
        "in (0, 600]\n",
        stderr);
    return 2;
  }
  mm::Result<mm::Database> database = mm::load_database(argv[1]);
  if (!database) {
    std::fprintf(stderr, "mm-capsules-example: %s\n", database.message().c_str());
    return 1;
  }
  auto shared = mm::ControllerDatabase::create(
      std::make_shared<const mm::Database>(std::move(database).value()));
  if (!shared) {
    std::fprintf(stderr, "mm-capsules-example: %s\n", shared.message().c_str());
    return 1;
  }

  Level level;
  std::vector<std::unique_ptr<Character>> crowd;
  for (int i = 0; i < characters; ++i) {
    mm::Result<mm::Controller> controller = mm::Controller::create(*shared);
    if (!controller) {
      std::fprintf(stderr, "mm-capsules-example: %s\n", controller.message().c_str());
      return 1;
    }
    // In a row 1 m apart along x, every other one running.
    const float x = static_cast<float>(i) - 0.5f * static_cast<float>(characters - 1);
    crowd.push_back(spawn(level, std::move(controller).value(), x, i % 2 == 1));
  }

  const int frames = static_cast<int>(seconds / kDt);
  for (int f = 0; f < frames; ++f) {
    for (auto& c : crowd) frame(level, *c);
  }

  for (size_t i = 0; i < crowd.size(); ++i) {
    const glm::dvec3 feet = crowd[i]->feet();
    const float ground = level.ground_under(static_cast<float>(feet.x), static_cast<float>(feet.z));
    std::printf("character %zu: x=%.3f y=%.3f z=%.3f ground=%.3f highest=%.3f\n", i, feet.x, feet.y,
                feet.z, static_cast<double>(ground), static_cast<double>(crowd[i]->highest));
  }
  std::printf("summary: %d characters, %d frames at 60 Hz\n", characters, frames);
  return 0;
}
