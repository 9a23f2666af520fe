#pragma once
// The controller tests' shared database: the whole Bandai normal folder built with the default
// options (the database the controller's targets are measured on), once per test program
// (normal_database.hpp: loaded from the file ctest's setup test writes).

#include <gtest/gtest.h>

#include <memory>
#include <span>

#include "mm/controller/controller.hpp"
#include "mm/runtime/pose.hpp"
#include "normal_database.hpp"

namespace mm::test {

inline std::shared_ptr<const ControllerDatabase> normal_controller_database() {
  static const std::shared_ptr<const ControllerDatabase> shared = [] {
    Result<Database> db = normal_database();
    EXPECT_TRUE(db.ok()) << (db.ok() ? "" : db.message());
    Result<std::shared_ptr<const ControllerDatabase>> made =
        ControllerDatabase::create(std::make_shared<const Database>(std::move(db).value()));
    EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.message());
    return made.ok() ? *made : nullptr;
  }();
  return shared;
}

// A controller on normal_controller_database() (the test fails if it cannot be made).
inline Controller make_controller(const ControllerSettings& settings = {}) {
  Result<Controller> c = Controller::create(normal_controller_database(), settings);
  EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.message());
  return std::move(c).value();
}

// A stick pushed fully toward world yaw `degrees` with the camera at 0 (yaw 0 is +Z, 90 is +X).
inline ControllerInput push_toward(float degrees, bool run = false) {
  ControllerInput input;
  const float yaw = glm::radians(degrees);
  // The camera at yaw 0 looks along +Z and its right is -X: stick +x is world -X.
  input.left_stick = glm::vec2(-std::sin(yaw), std::cos(yaw));
  input.run = run;
  return input;
}

// The hips' facing as `mm eval` reads it: pair_yaw across the upper legs' world positions.
inline float hips_yaw(const Controller& c) {
  const Database& db = c.controller_database().database();
  const std::span<const Transform> g = c.global_transforms();
  return pair_yaw(g[static_cast<size_t>(db.roles().left_upper_leg)].translation,
                  g[static_cast<size_t>(db.roles().right_upper_leg)].translation);
}

// The chest's facing as `mm eval` reads it: across the upper arms.
inline float chest_yaw(const Controller& c) {
  const Database& db = c.controller_database().database();
  const std::span<const Transform> g = c.global_transforms();
  return pair_yaw(g[static_cast<size_t>(db.roles().left_upper_arm)].translation,
                  g[static_cast<size_t>(db.roles().right_upper_arm)].translation);
}

inline float horizontal_speed(const glm::vec3& a, const glm::vec3& b, float dt) {
  return std::hypot(a.x - b.x, a.z - b.z) / dt;
}

}  // namespace mm::test
