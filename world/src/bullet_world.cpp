// BulletWorld (mm/world/bullet_world.hpp): the controller's world queries answered by Bullet.

#include "mm/world/bullet_world.hpp"

#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "level_mesh.hpp"
#include "mm/runtime/assert.hpp"

namespace mm {
namespace {

// Object bounds are grown by this (m) before a query's bounds are tested against them: the
// bounds are floats, and a query that only touches an object must not be culled.
constexpr float kCullingSlack = 0.01f;

// A number as a person would write it ("0.05", "100000"), not std::to_string's "0.050000".
std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

bool finite(double v) {
  return std::isfinite(v);
}

glm::dvec3 from_bullet(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}

// A collision object and its bounds in the world's float frame, for culling.
struct Culled {
  btCollisionObject* object = nullptr;
  btVector3 low;
  btVector3 high;
};

bool overlaps(const Culled& culled, const btVector3& low, const btVector3& high) {
  return culled.low.x() <= high.x() && low.x() <= culled.high.x() && culled.low.y() <= high.y() &&
         low.y() <= culled.high.y() && culled.low.z() <= high.z() && low.z() <= culled.high.z();
}

// The closest hit of a convex sweep, leaving out contacts the shape moves away from (Bullet's
// normal points from the obstacle toward the shape; along the motion, the shape leaves the
// surface it touches). A capsule touching a wall and moving along it (parallel to within 1e-5)
// got a hit at fraction 0 whose normal pointed a hair along the motion; turned against the
// motion, into the wall, it was taken for a wall behind the character (the second course's
// wall_60: the body then pushed 6 cm into the real one).
struct ApproachingConvexResult : btCollisionWorld::ClosestConvexResultCallback {
  using ClosestConvexResultCallback::ClosestConvexResultCallback;
  btScalar addSingleResult(btCollisionWorld::LocalConvexResult& result,
                           bool normal_in_world_space) override {
    const btVector3 normal =
        normal_in_world_space
            ? result.m_hitNormalLocal
            : result.m_hitCollisionObject->getWorldTransform().getBasis() * result.m_hitNormalLocal;
    if (normal.dot(m_convexToWorld - m_convexFromWorld) > 0) return m_closestHitFraction;
    return ClosestConvexResultCallback::addSingleResult(result, normal_in_world_space);
  }
};

}  // namespace

// Declared so that the collision world is destroyed first (it removes every object's proxy from
// the broadphase), then the broadphase, and the objects, shapes and arrays it pointed into last.
struct BulletWorld::State {
  glm::dvec3 origin{0.0};
  // The level's triangles and Bullet's mesh over them (State lives on the heap and never moves).
  LevelMesh mesh;
  std::unique_ptr<btCollisionObject> mesh_object;
  std::vector<std::unique_ptr<btBoxShape>> box_shapes;
  std::vector<std::unique_ptr<btCollisionObject>> box_objects;
  // Every object with its bounds: what each query walks.
  std::vector<Culled> culled;

  // The collision world that holds the objects. The queries do not go through it (see
  // bullet_world.hpp, "Threads"), but a game's own Bullet code (a kinematic character
  // controller, its physics) works on one.
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};

  void add(btCollisionObject* object) {
    object->setCollisionFlags(object->getCollisionFlags() | btCollisionObject::CF_STATIC_OBJECT);
    world.addCollisionObject(object);
    Culled entry;
    entry.object = object;
    object->getCollisionShape()->getAabb(object->getWorldTransform(), entry.low, entry.high);
    entry.low -= btVector3(kCullingSlack, kCullingSlack, kCullingSlack);
    entry.high += btVector3(kCullingSlack, kCullingSlack, kCullingSlack);
    culled.push_back(entry);
  }

  // `position` relative to the query's `origin`, in the world's float frame; false when it is
  // not finite or out of reach (Bullet is then not asked).
  bool to_local(const glm::dvec3& query_origin, const glm::dvec3& position,
                glm::dvec3& local) const {
    // The two origins first: both may be large, their difference is small and exact.
    local = (query_origin - origin) + position;
    return finite(local) && within(local, kMaxQueryReach);
  }
};

BulletWorld::BulletWorld(std::unique_ptr<State> state) : state_(std::move(state)) {}
BulletWorld::BulletWorld(BulletWorld&&) noexcept = default;
BulletWorld& BulletWorld::operator=(BulletWorld&&) noexcept = default;
BulletWorld::~BulletWorld() = default;

Result<BulletWorld> BulletWorld::create(const Level& level) {
  if (Status valid = level.validate(); !valid) {
    return Error{"the level is not valid: " + valid.message()};
  }
  auto state = std::make_unique<State>();
  state->origin = level.origin;
  state->mesh.build(level);
  if (state->mesh.shape) {
    state->mesh_object = std::make_unique<btCollisionObject>();
    state->mesh_object->setCollisionShape(state->mesh.shape.get());
    state->add(state->mesh_object.get());
  }
  return BulletWorld(std::move(state));
}

Status BulletWorld::add_box(const WorldBox& box) {
  const glm::dvec3 half(box.half_extents);
  if (!finite(box.center) || !finite(half) || !finite(static_cast<double>(box.yaw))) {
    return Error{"box: the centre, half extents and yaw must be finite"};
  }
  if (std::min({half.x, half.y, half.z}) < static_cast<double>(kMinBoxHalfExtent)) {
    return Error{"box: every half extent must be at least " + number(kMinBoxHalfExtent) +
                 " m (Bullet rounds a box's edges by 4 cm inside it)"};
  }
  // The farthest corner from the centre along each world axis, turned about Y.
  const double c = std::abs(std::cos(static_cast<double>(box.yaw)));
  const double s = std::abs(std::sin(static_cast<double>(box.yaw)));
  const glm::dvec3 reach(c * half.x + s * half.z, half.y, s * half.x + c * half.z);
  if (!within(box.center + reach, kMaxLevelCoordinate) ||
      !within(box.center - reach, kMaxLevelCoordinate)) {
    return Error{"box: a corner lies beyond ±" + number(kMaxLevelCoordinate) +
                 " m of the world origin"};
  }
  auto shape = std::make_unique<btBoxShape>(to_bullet(half));
  auto object = std::make_unique<btCollisionObject>();
  btTransform transform;
  transform.setIdentity();
  transform.setOrigin(to_bullet(box.center - state_->origin));
  transform.setRotation(btQuaternion(btVector3(0, 1, 0), box.yaw));
  object->setWorldTransform(transform);
  object->setCollisionShape(shape.get());
  state_->add(object.get());
  state_->box_shapes.push_back(std::move(shape));
  state_->box_objects.push_back(std::move(object));
  return Status::success();
}

void BulletWorld::probe_ground(const glm::dvec3& origin, std::span<const GroundProbe> probes,
                               std::span<GroundHit> hits) const {
  MM_ASSERT(probes.size() == hits.size());
  const State& state = *state_;
  for (size_t i = 0; i < probes.size(); ++i) {
    const GroundProbe& probe = probes[i];
    GroundHit& hit = hits[i];
    hit = GroundHit{};
    if (!(probe.max_distance >= 0.0f) || !std::isfinite(probe.max_distance) ||
        !std::isfinite(probe.min_walkable_normal_y)) {
      continue;
    }
    glm::dvec3 from;
    glm::dvec3 to;
    const glm::dvec3 start(probe.from);
    if (!state.to_local(origin, start, from) ||
        !state.to_local(origin, start - glm::dvec3(0.0, probe.max_distance, 0.0), to)) {
      continue;
    }
    const btVector3 ray_from = to_bullet(from);
    const btVector3 ray_to = to_bullet(to);
    btTransform from_transform;
    from_transform.setIdentity();
    from_transform.setOrigin(ray_from);
    btTransform to_transform;
    to_transform.setIdentity();
    to_transform.setOrigin(ray_to);
    btCollisionWorld::ClosestRayResultCallback result(ray_from, ray_to);
    // GJK rather than the sub-simplex cast for rays against boxes: exact on their faces.
    result.m_flags |= btTriangleRaycastCallback::kF_UseGjkConvexCastRaytest;
    btVector3 low = ray_from;
    btVector3 high = ray_from;
    low.setMin(ray_to);
    high.setMax(ray_to);
    for (const Culled& culled : state.culled) {
      if (!overlaps(culled, low, high)) continue;
      btCollisionWorld::rayTestSingle(from_transform, to_transform, culled.object,
                                      culled.object->getCollisionShape(),
                                      culled.object->getWorldTransform(), result);
    }
    if (!result.hasHit()) continue;
    glm::dvec3 normal = from_bullet(result.m_hitNormalWorld);
    const double length = glm::length(normal);
    const double fraction = std::clamp(static_cast<double>(result.m_closestHitFraction), 0.0, 1.0);
    if (!(length > 1e-6) || !std::isfinite(length) || !std::isfinite(fraction)) continue;
    normal /= length;
    if (normal.y < 0.0) normal = -normal;  // a surface hit from below still faces up
    hit.hit = true;
    hit.point = glm::vec3(probe.from.x, static_cast<float>(start.y - fraction * probe.max_distance),
                          probe.from.z);
    hit.normal = glm::vec3(normal);
    hit.walkable = hit.normal.y >= probe.min_walkable_normal_y;
  }
}

void BulletWorld::sweep(const glm::dvec3& origin, std::span<const ShapeSweep> sweeps,
                        std::span<SweepHit> hits) const {
  MM_ASSERT(sweeps.size() == hits.size());
  const State& state = *state_;
  for (size_t i = 0; i < sweeps.size(); ++i) {
    const ShapeSweep& sweep = sweeps[i];
    SweepHit& hit = hits[i];
    hit = SweepHit{};
    if (!(sweep.radius > 0.0f) || !std::isfinite(sweep.radius) || !std::isfinite(sweep.height)) {
      continue;
    }
    // A height below two radii is a sphere, standing on `from` all the same.
    const double height = std::max(static_cast<double>(sweep.height), 2.0 * sweep.radius);
    const glm::dvec3 lift(0.0, 0.5 * height, 0.0);
    glm::dvec3 from;
    glm::dvec3 to;
    if (!state.to_local(origin, glm::dvec3(sweep.from) + lift, from) ||
        !state.to_local(origin, glm::dvec3(sweep.to) + lift, to)) {
      continue;
    }
    const btVector3 centre_from = to_bullet(from);
    const btVector3 centre_to = to_bullet(to);
    btCapsuleShape capsule(sweep.radius, static_cast<btScalar>(height - 2.0 * sweep.radius));
    btTransform from_transform;
    from_transform.setIdentity();
    from_transform.setOrigin(centre_from);
    btTransform to_transform;
    to_transform.setIdentity();
    to_transform.setOrigin(centre_to);
    ApproachingConvexResult result(centre_from, centre_to);
    const btVector3 extent(sweep.radius, static_cast<btScalar>(0.5 * height), sweep.radius);
    btVector3 low = centre_from;
    btVector3 high = centre_from;
    low.setMin(centre_to);
    high.setMax(centre_to);
    low -= extent;
    high += extent;
    for (const Culled& culled : state.culled) {
      if (!overlaps(culled, low, high)) continue;
      btCollisionWorld::objectQuerySingle(&capsule, from_transform, to_transform, culled.object,
                                          culled.object->getCollisionShape(),
                                          culled.object->getWorldTransform(), result,
                                          /*allowedPenetration=*/0.0f);
    }
    if (!result.hasHit()) continue;
    glm::dvec3 normal = from_bullet(result.m_hitNormalWorld);
    const double length = glm::length(normal);
    const double fraction = static_cast<double>(result.m_closestHitFraction);
    if (!(length > 1e-6) || !std::isfinite(length) || !std::isfinite(fraction)) continue;
    normal /= length;  // out of the obstacle, against the motion (ApproachingConvexResult)
    hit.hit = true;
    hit.fraction = static_cast<float>(std::clamp(fraction, 0.0, 1.0));
    hit.normal = glm::vec3(normal);
  }
}

glm::dvec3 BulletWorld::origin() const {
  return state_->origin;
}

size_t BulletWorld::triangle_count() const {
  return state_->mesh.indices.size() / 3;
}

size_t BulletWorld::box_count() const {
  return state_->box_objects.size();
}

}  // namespace mm
