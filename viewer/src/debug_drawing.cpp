#include "debug_drawing.hpp"

#include <algorithm>

namespace mm::viewer {
namespace {

const glm::vec3 kDesired{0.10f, 0.65f, 0.15f};
const glm::vec3 kPredicted{0.15f, 0.35f, 0.90f};
const glm::vec3 kSimulation{0.95f, 0.55f, 0.05f};
const glm::vec3 kRoot{1.0f, 1.0f, 1.0f};
const glm::vec3 kQuery{0.95f, 0.85f, 0.05f};
const glm::vec3 kMatch{0.85f, 0.15f, 0.85f};
const glm::vec3 kContact{0.1f, 0.8f, 0.2f};
const glm::vec3 kAir{0.45f, 0.45f, 0.45f};
const glm::vec3 kLock{0.9f, 0.1f, 0.1f};
const glm::vec3 kProbe{0.2f, 0.8f, 0.9f};
const glm::vec3 kPelvis{0.95f, 0.3f, 0.6f};
constexpr float kLift = 0.01f;  // lines on the ground are lifted so the grid does not hide them

glm::vec3 ground(glm::vec3 p) {
  return {p.x, kLift, p.z};
}

glm::vec3 facing(const glm::quat& q, float length) {
  return q * glm::vec3(0.0f, 0.0f, length);
}

void draw_trajectory(const ControllerDebug& d, DebugLines& lines) {
  glm::vec3 previous_desired = ground(d.world(d.simulation_position));
  glm::vec3 previous_predicted = previous_desired;
  for (int i = 0; i < d.trajectory_count; ++i) {
    const glm::vec3 desired = ground(d.world(d.desired_positions[i]));
    const glm::vec3 predicted = ground(d.world(d.predicted_positions[i]));
    lines.line(previous_desired, desired, kDesired);
    lines.line(previous_predicted, predicted, kPredicted);
    lines.cross(desired, 0.04f, kDesired);
    lines.arrow(predicted, facing(d.predicted_rotations[i], 0.25f), kPredicted);
    previous_desired = desired;
    previous_predicted = predicted;
  }
}

void draw_roots(const Controller& controller, DebugLines& lines) {
  const ControllerDebug& d = controller.debug();
  lines.circle(ground(d.world(d.simulation_position)), 0.25f, kSimulation);
  lines.arrow(ground(d.world(d.simulation_position)), facing(d.simulation_rotation, 0.45f),
              kSimulation);
  const Transform& root = controller.root_transform();
  lines.circle(ground(root.translation), 0.18f, kRoot);
  lines.arrow(ground(root.translation), facing(root.rotation, 0.35f), kRoot);
}

// One feature row (normalized, as the search sees it) turned back into metres and placed in
// the character's root frame.
void draw_feature_row(const Database& db, const Transform& root, const float* row, int dims,
                      const glm::vec3& colour, DebugLines& lines) {
  const FeatureSchema& schema = db.schema();
  auto raw = [&](int column) {
    return row[column] * db.feature_scale()[column] + db.feature_offset()[column];
  };
  for (int c = 0; c < static_cast<int>(schema.channels.size()); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    const int first = schema.offset(c);
    if (first + channel.dims() > dims) break;
    switch (channel.kind) {
      case FeatureKind::BonePosition:
        lines.cross(transform_point(root, {raw(first), raw(first + 1), raw(first + 2)}), 0.05f,
                    colour);
        break;
      case FeatureKind::BoneVelocity: {
        // Drawn from the hips' height for the hips, from the ground for the feet.
        const glm::vec3 v{raw(first), raw(first + 1), raw(first + 2)};
        const glm::vec3 from =
            transform_point(root, {0.0f, channel.bone == "hips" ? 1.0f : kLift, 0.0f});
        lines.line(from, from + transform_vector(root, v * 0.1f), colour);
        break;
      }
      case FeatureKind::TrajectoryPosition:
        for (size_t t = 0; t < channel.times.size(); ++t) {
          const int k = first + 2 * static_cast<int>(t);
          lines.cross(ground(transform_point(root, {raw(k), 0.0f, raw(k + 1)})), 0.06f, colour);
        }
        break;
      case FeatureKind::TrajectoryDirection:
      case FeatureKind::BoneDirection:
        break;  // drawn with the positions they belong to below
    }
  }
  // Trajectory directions at the trajectory positions of the same times.
  for (int c = 0; c < static_cast<int>(schema.channels.size()); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    if (channel.kind != FeatureKind::TrajectoryDirection) continue;
    for (int p = 0; p < static_cast<int>(schema.channels.size()); ++p) {
      const FeatureChannel& positions = schema.channels[p];
      if (positions.kind != FeatureKind::TrajectoryPosition || positions.times != channel.times)
        continue;
      for (size_t t = 0; t < channel.times.size(); ++t) {
        const int k = schema.offset(c) + 2 * static_cast<int>(t);
        const int q = schema.offset(p) + 2 * static_cast<int>(t);
        if (std::max(k, q) + 1 >= dims) continue;
        const glm::vec3 at = ground(transform_point(root, {raw(q), 0.0f, raw(q + 1)}));
        lines.arrow(at, transform_vector(root, glm::vec3(raw(k), 0.0f, raw(k + 1)) * 0.3f), colour);
      }
    }
  }
}

void draw_features(const Controller& controller, DebugLines& lines) {
  const ControllerDebug& d = controller.debug();
  const Database& db = controller.controller_database().database();
  const Transform& root = controller.root_transform();
  if (d.query_dims > 0) draw_feature_row(db, root, d.last_query, d.query_dims, kQuery, lines);
  if (d.last_best_frame >= 0 && d.last_best_frame < db.frame_count()) {
    const std::span<const float> row = db.feature_row(d.last_best_frame);
    draw_feature_row(db, root, row.data(), static_cast<int>(row.size()), kMatch, lines);
  }
}

void draw_contacts(const Controller& controller, DebugLines& lines) {
  const ControllerDebug& d = controller.debug();
  const Database& db = controller.controller_database().database();
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  const auto globals = controller.global_transforms();
  for (int side = 0; side < 2; ++side) {
    if (toes[side] < 0) continue;
    const glm::vec3 toe = globals[toes[side]].translation;
    // In a world, the circle lies on the ground the foot stands on (foot_placement.hpp).
    glm::vec3 on_ground = ground(toe);
    if (controller.world()) {
      on_ground.y = static_cast<float>(d.origin.y + d.foot_ground[side].toe) + kLift;
    }
    lines.circle(on_ground, 0.07f, d.contact[side] ? kContact : kAir, 16);
    if (d.locked[side]) lines.cross(d.world(d.lock_position[side]), 0.06f, kLock);
    lines.cross(d.world(d.ik_target[side]), 0.03f, kAir);
  }
}

// Feet on a level's ground: each probe from the foot down to the ground it found (a cross
// there), where each foot in the air lands by the playing clip (a circle on its ground), and the
// pelvis drop as a bar from where the hips would be down to where they are.
void draw_foot_placement(const Controller& controller, DebugLines& lines) {
  if (!controller.world()) return;
  const ControllerDebug& d = controller.debug();
  for (int i = 0; i < FootPlacement::kProbes; ++i) {
    const glm::vec3 found = d.world(d.foot_probe_grounds[i]);
    lines.line(d.world(d.foot_probes[i]), found, kProbe);
    lines.cross(found, 0.02f, kProbe);
  }
  for (int side = 0; side < 2; ++side) {
    if (!d.foot_lands[side]) continue;
    glm::vec3 landing = d.world(d.foot_landing[side]);
    landing.y = static_cast<float>(d.origin.y + d.foot_ground[side].toe) + kLift;
    lines.circle(landing, 0.04f, kProbe, 12);
  }
  const int hips = controller.controller_database().database().roles().hips;
  if (hips < 0 || d.pelvis_drop <= 0.0f) return;
  const glm::vec3 at = controller.global_transforms()[static_cast<size_t>(hips)].translation;
  lines.line(at + glm::vec3(0.0f, d.pelvis_drop, 0.0f), at, kPelvis);
  lines.cross(at, 0.05f, kPelvis);
}

}  // namespace

void draw_controller_debug(const Controller& controller, const DebugToggles& toggles,
                           DebugLines& lines) {
  if (toggles.trajectory) draw_trajectory(controller.debug(), lines);
  if (toggles.roots) draw_roots(controller, lines);
  if (toggles.features) draw_features(controller, lines);
  if (toggles.contacts) {
    draw_contacts(controller, lines);
    draw_foot_placement(controller, lines);
  }
}

void draw_skeleton(const Controller& controller, DebugLines& lines) {
  const Skeleton& skeleton = controller.controller_database().database().skeleton();
  const auto globals = controller.global_transforms();
  // Joint 0 is the simulation root on the ground, and a source root the controller plays at
  // joint 0 (Bandai's joint_Root) sits there too: their links to the hips are not bones.
  const glm::vec3 ground_root = globals[0].translation;
  for (int j = 1; j < skeleton.joint_count(); ++j) {
    const int parent = skeleton.parent(j);
    if (parent <= 0 || glm::distance(globals[parent].translation, ground_root) < 0.01f) continue;
    lines.line(globals[parent].translation, globals[j].translation, {0.1f, 0.1f, 0.1f});
  }
  for (int j = 1; j < skeleton.joint_count(); ++j)
    lines.cross(globals[j].translation, 0.015f, {0.9f, 0.9f, 0.2f});
}

}  // namespace mm::viewer
