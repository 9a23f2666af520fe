#include "mm/offline/idle.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <vector>
#include "mm/runtime/assert.hpp"

#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {

namespace {

// Global transforms of one frame's pose (its simulation root where it stands).
void frame_globals(const DatabaseView& db, int frame, std::vector<Transform>& local,
                   std::vector<Transform>& global) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  local.resize(joints);
  global.resize(joints);
  const size_t base = static_cast<size_t>(frame) * joints;
  for (size_t j = 0; j < joints; ++j) {
    local[j].translation = db.local_positions[base + j];
    local[j].rotation = db.local_rotations[base + j];
  }
  forward_kinematics(db.skeleton.parents(), local, global);
}

float feet_distance(const DatabaseView& db, const std::vector<Transform>& global) {
  const int joints = db.joint_count();
  const int left = db.roles.left_foot;
  const int right = db.roles.right_foot;
  if (left < 0 || right < 0 || left >= joints || right >= joints) {
    return std::numeric_limits<float>::infinity();
  }
  const glm::vec3 a = global[static_cast<size_t>(left)].translation;
  const glm::vec3 b = global[static_cast<size_t>(right)].translation;
  return std::hypot(a.x - b.x, a.z - b.z);
}

// Joint 0 turns about +Y only, so world heights are heights over the simulation root. A lower
// arm is an arm end only where the skeleton has no hands; its joint is the elbow, which hangs at
// the waist, a little below halfway from the hips to the shoulder: it is measured from two thirds
// of the way from the hips to its upper arm.
float arm_end_height(const DatabaseView& db, const std::vector<int>& arm_ends,
                     const std::vector<Transform>& global) {
  float highest = -std::numeric_limits<float>::infinity();
  if (db.roles.hips < 0) return highest;
  const float hips = global[static_cast<size_t>(db.roles.hips)].translation.y;
  const int elbows[2][2] = {{db.roles.left_lower_arm, db.roles.left_upper_arm},
                            {db.roles.right_lower_arm, db.roles.right_upper_arm}};
  for (const int j : arm_ends) {
    float base = hips;
    for (const auto& [elbow, upper_arm] : elbows) {
      if (j == elbow && upper_arm >= 0) {
        base = hips + (2.0f / 3.0f) * (global[static_cast<size_t>(upper_arm)].translation.y - hips);
      }
    }
    highest = std::max(highest, global[static_cast<size_t>(j)].translation.y - base);
  }
  return highest;
}

std::string metres(float value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", static_cast<double>(value));
  return buffer;
}

}  // namespace

double idle_motion_energy(const DatabaseView& db, int frame) {
  const int joints = db.joint_count();
  const size_t base = static_cast<size_t>(frame) * static_cast<size_t>(joints);
  double energy = 0.0;
  for (int j = 1; j < joints; ++j) {
    const glm::vec3 w = db.local_angular_velocities[base + j];
    energy += static_cast<double>(glm::dot(w, w));
    if (db.skeleton.parent(j) == 0) {
      const glm::vec3 v = db.local_velocities[base + j];
      energy += static_cast<double>(glm::dot(v, v));
    }
  }
  return energy;
}

float horizontal_feet_distance(const DatabaseView& db, int frame) {
  std::vector<Transform> local, global;
  frame_globals(db, frame, local, global);
  return feet_distance(db, global);
}

std::vector<int> arm_end_joints(const Skeleton& skeleton, const JointRoleIndices& roles) {
  const int joints = skeleton.joint_count();
  std::vector<int> ends;
  // The map knows the arms: the hands, or the wrist ends of the lower arms (a skeleton without
  // hands). Leaves elsewhere (ReActIdle's pelvis stubs) are not arms.
  const int left = roles.left_hand >= 0 ? roles.left_hand : roles.left_lower_arm;
  const int right = roles.right_hand >= 0 ? roles.right_hand : roles.right_lower_arm;
  if (left >= 0 && right >= 0 && left < joints && right < joints) return {left, right};
  if (roles.head < 0 || roles.hips < 0 || roles.head >= joints || roles.hips >= joints) {
    return ends;
  }
  std::vector<uint8_t> has_child(static_cast<size_t>(joints), 0);
  for (int j = 0; j < joints; ++j) {
    if (skeleton.parent(j) >= 0) has_child[static_cast<size_t>(skeleton.parent(j))] = 1;
  }
  const int excluded[] = {roles.head, roles.left_foot, roles.right_foot};
  for (int j = 0; j < joints; ++j) {
    if (has_child[static_cast<size_t>(j)]) continue;
    bool inside = false;
    for (int a = j; a >= 0 && !inside; a = skeleton.parent(a)) {
      inside = std::find(std::begin(excluded), std::end(excluded), a) != std::end(excluded);
    }
    if (!inside) ends.push_back(j);
  }
  return ends;
}

float highest_arm_end_over_hips(const DatabaseView& db, int frame) {
  std::vector<Transform> local, global;
  frame_globals(db, frame, local, global);
  return arm_end_height(db, arm_end_joints(db.skeleton, db.roles), global);
}

IdleSourceSearch search_idle_source(const DatabaseView& db, const IdleCriteria& criteria) {
  IdleSourceSearch out;
  const size_t joints = static_cast<size_t>(db.joint_count());
  const std::vector<int> arm_ends = arm_end_joints(db.skeleton, db.roles);
  std::vector<Transform> local, global;
  for (const ClipRange& clip : db.clips) {
    if (clip.mirrored || is_idle_clip(db, clip)) continue;
    for (int f = clip.start; f < clip.end; ++f) {
      const size_t k = static_cast<size_t>(f);
      if (!db.contacts[2 * k] || !db.contacts[2 * k + 1]) continue;
      ++out.on_both_feet;
      const glm::vec3 v = db.local_velocities[k * joints];
      if (!(std::hypot(v.x, v.z) < criteria.max_root_speed)) continue;
      ++out.slow;
      frame_globals(db, f, local, global);
      if (!(feet_distance(db, global) < criteria.max_feet_distance)) continue;
      ++out.feet_together;
      if (!(arm_end_height(db, arm_ends, global) < criteria.max_arm_end_over_hips)) continue;
      ++out.arms_down;
      const double energy = idle_motion_energy(db, f);
      if (out.frame < 0 || energy < out.energy || (energy == out.energy && f < out.frame)) {
        out.frame = f;
        out.energy = energy;
      }
    }
  }
  return out;
}

int find_calmest_standing_frame(const DatabaseView& db, const IdleCriteria& criteria) {
  return search_idle_source(db, criteria).frame;
}

std::string idle_search_failure(const IdleSourceSearch& search, const IdleCriteria& criteria) {
  if (search.frame >= 0) return {};
  if (search.on_both_feet == 0) return "no frame stands with both feet in contact";
  const std::string both = std::to_string(search.on_both_feet) + " frames stand on both feet";
  if (search.slow == 0) {
    return both + " but in all of them the simulation root moves at " +
           metres(criteria.max_root_speed) + " m/s or faster";
  }
  const std::string slow = both + ", " + std::to_string(search.slow) +
                           " of them with the simulation root slower than " +
                           metres(criteria.max_root_speed) + " m/s";
  if (search.feet_together == 0) {
    return slow + ", but none with the feet closer than " + metres(criteria.max_feet_distance) +
           " m apart";
  }
  return slow + ", " + std::to_string(search.feet_together) +
         " of these with the feet closer than " + metres(criteria.max_feet_distance) +
         " m apart, but none with the hands (arm ends) lower than " +
         metres(criteria.max_arm_end_over_hips) + " m above the hips";
}

void fill_idle_clip(const DatabaseFill& db, const ClipRange& range, int source_frame) {
  MM_ASSERT(source_frame >= 0 && source_frame < db.frame_count);
  MM_ASSERT(source_frame < range.start || source_frame >= range.end);
  MM_ASSERT(range.start >= 0 && range.end <= db.frame_count);
  const size_t joints = static_cast<size_t>(db.joint_count());
  const size_t source = static_cast<size_t>(source_frame) * joints;
  for (int f = range.start; f < range.end; ++f) {
    const size_t base = static_cast<size_t>(f) * joints;
    db.local_positions[base] = glm::vec3(0.0f);
    db.local_rotations[base] = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    std::copy_n(db.local_positions.begin() + static_cast<std::ptrdiff_t>(source + 1), joints - 1,
                db.local_positions.begin() + static_cast<std::ptrdiff_t>(base + 1));
    std::copy_n(db.local_rotations.begin() + static_cast<std::ptrdiff_t>(source + 1), joints - 1,
                db.local_rotations.begin() + static_cast<std::ptrdiff_t>(base + 1));
    std::fill_n(db.local_velocities.begin() + static_cast<std::ptrdiff_t>(base), joints,
                glm::vec3(0.0f));
    std::fill_n(db.local_angular_velocities.begin() + static_cast<std::ptrdiff_t>(base), joints,
                glm::vec3(0.0f));
    db.contacts[2 * static_cast<size_t>(f)] = 1;
    db.contacts[2 * static_cast<size_t>(f) + 1] = 1;
  }
}

namespace {

// Per frame: whether both feet are planted, and the body's yaw across the upper legs.
struct FrameCalm {
  bool planted = false;
  float yaw = 0.0f;
};

std::vector<FrameCalm> frame_calm(const Clip& clip, const JointRoleIndices& roles,
                                  const CalmIdleCriteria& criteria) {
  const size_t frames = static_cast<size_t>(clip.frame_count);
  std::vector<glm::vec3> feet(2 * frames);
  std::vector<FrameCalm> out(frames);
  std::vector<Transform> global(static_cast<size_t>(clip.joint_count()));
  for (size_t f = 0; f < frames; ++f) {
    forward_kinematics(clip.skeleton.parents(), clip.pose(static_cast<int>(f)), global);
    feet[2 * f] = global[static_cast<size_t>(roles.left_foot)].translation;
    feet[2 * f + 1] = global[static_cast<size_t>(roles.right_foot)].translation;
    out[f].yaw = pair_yaw(global[static_cast<size_t>(roles.left_upper_leg)].translation,
                          global[static_cast<size_t>(roles.right_upper_leg)].translation);
  }
  const float limit = criteria.max_foot_speed * clip.frame_time;
  for (size_t f = 0; f < frames; ++f) {
    const size_t a = f > 0 ? f - 1 : f, b = f + 1 < frames ? f + 1 : f;
    bool planted = true;
    for (size_t side = 0; side < 2; ++side) {
      glm::vec3 d = feet[2 * b + side] - feet[2 * a + side];
      d.y = 0.0f;
      planted = planted && glm::length(d) <= limit * static_cast<float>(b - a);
    }
    out[f].planted = planted;
  }
  return out;
}

float angle_between(float a, float b) {
  return std::abs(std::remainder(a - b, 2.0f * glm::pi<float>()));
}

Clip segment_of(const Clip& clip, int first, int end) {
  Clip out;
  out.name =
      clip.name + "_at" + std::to_string(clamped_integer<int>(first * clip.frame_time)) + "s";
  out.source_path = clip.source_path;
  out.skeleton = clip.skeleton;
  out.end_sites = clip.end_sites;
  out.frame_time = clip.frame_time;
  out.frame_count = end - first;
  const size_t joints = static_cast<size_t>(clip.joint_count());
  out.local.assign(clip.local.begin() + static_cast<std::ptrdiff_t>(first * joints),
                   clip.local.begin() + static_cast<std::ptrdiff_t>(end * joints));
  return out;
}

}  // namespace

std::vector<Clip> calm_idle_segments(const Clip& clip, const JointRoleIndices& roles,
                                     const CalmIdleCriteria& criteria) {
  const std::vector<FrameCalm> calm = frame_calm(clip, roles, criteria);
  const int min_frames = clamped_integer<int>(std::ceil(criteria.min_seconds / clip.frame_time));
  std::vector<Clip> out;
  int f = 0;
  while (f < clip.frame_count) {
    if (!calm[static_cast<size_t>(f)].planted) {
      ++f;
      continue;
    }
    const int first = f;
    while (f < clip.frame_count && calm[static_cast<size_t>(f)].planted &&
           angle_between(calm[static_cast<size_t>(f)].yaw, calm[static_cast<size_t>(first)].yaw) <=
               criteria.max_turn) {
      ++f;
    }
    if (f - first >= min_frames) out.push_back(segment_of(clip, first, f));
  }
  return out;
}

}  // namespace mm
