#pragma once
// The crowd of `mm-viewer --crowd N` without any OpenGL: N controllers over one shared database,
// each on its own reproducible input (varied_input_script), standing on a sunflower spiral around
// the origin, all stepped through a CrowdScheduler whose significance is minus each character's
// horizontal distance to the camera; and the packing of every character's bones into one
// instance buffer (one instance per bone, so the renderer draws all bones of all characters in
// one call). Testable without a window (tests/viewer/crowd_view_test.cpp).

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/controller.hpp"
#include "mm/controller/crowd_scheduler.hpp"
#include "mm/controller/script.hpp"
#include "mm/runtime/result.hpp"

namespace mm::viewer {

// Where character i of the crowd starts (y = 0) and the way it faces (yaw, radians): on a
// sunflower spiral about the origin with about `spacing` metres between neighbours, so the crowd
// is a disc of radius about spacing * sqrt(n / pi) whatever n is, and character 0 is nearest the
// middle. The same i always gives the same place.
glm::vec3 crowd_start_position(size_t i, float spacing);
float crowd_start_yaw(size_t i);

// The colour a tier is drawn in when the tiers are shown (the panel's legend uses the same).
glm::vec3 crowd_tier_colour(CrowdTier tier);

// One drawn bone: a unit box (x, z in [-0.5, 0.5], y in [0, 1]) placed by `model` (columns),
// and its colour. The layout is the renderer's per-instance vertex attributes.
struct BoneInstance {
  glm::vec4 model[4];
  glm::vec4 colour;
};

// The bones drawn per character: one per joint with a parent (from the parent to the joint)
// and one more for the head, above the head joint.
size_t crowd_bones_per_character(std::span<const int> parents);

// Writes character's bones into `out` (crowd_bones_per_character(parents) of them): `pose` is
// the scheduler's pose (global transforms), `carry` the rigid motion the scheduler says to apply
// to it (CrowdScheduler::carry; identity for most tiers), `head` the head joint (-1: none).
// A bone's box runs from its parent joint to its joint, as wide as a fraction of its length
// (within limits), turned with the parent joint about its length.
void pack_bone_instances(std::span<const Transform> pose, const Transform& carry,
                         std::span<const int> parents, int head, const glm::vec4& colour,
                         std::span<BoneInstance> out);

struct CrowdViewSettings {
  int characters = 100;
  float spacing = 2.0f;        // metres between neighbours at the start
  float budget_ms = 4.0f;      // the scheduler's frame budget (0: every character at full rate)
  float script_seconds = 600;  // each character's input repeats after this long
};

class CrowdView {
 public:
  static Result<std::unique_ptr<CrowdView>> create(std::shared_ptr<const ControllerDatabase> shared,
                                                   const ControllerSettings& settings,
                                                   const CrowdViewSettings& crowd);

  // One frame: plans the tiers from the camera's position, steps every character (timed: the
  // smoothed update_ms()).
  void step(float dt, const glm::vec3& camera);
  // Every character's bones into `out` (resized), coloured by tier or all alike.
  void pack(bool tier_colours, std::vector<BoneInstance>& out) const;

  // The budget the next plan uses (ms; 0: none); fails, changing nothing, on a bad budget.
  Status set_budget_ms(float ms);
  float budget_ms() const { return scheduler_->settings().budget_ms; }
  const CrowdScheduler& scheduler() const { return *scheduler_; }
  size_t characters() const { return controllers_.size(); }
  float time() const { return time_; }
  // Running mean of plan + steps (ms per frame), smoothed over about a second.
  float update_ms() const { return update_ms_; }
  // The crowd's radius at the start (m; it stands about the origin), for placing the camera.
  float radius() const { return radius_; }

 private:
  CrowdView() = default;

  std::shared_ptr<const ControllerDatabase> shared_;
  std::vector<Controller> controllers_;
  std::vector<InputScript> scripts_;
  std::optional<CrowdScheduler> scheduler_;  // made in create()
  std::vector<float> significance_;
  std::vector<int> parents_;
  int head_ = -1;
  float script_seconds_ = 600.0f;
  float time_ = 0.0f;
  float update_ms_ = 0.0f;
  float radius_ = 0.0f;
};

}  // namespace mm::viewer
