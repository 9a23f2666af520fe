#include "mm/runtime/ik.hpp"

#include <algorithm>
#include <cmath>
#include "mm/runtime/assert.hpp"

#include "mm/runtime/finite.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/transform_sse.hpp"

namespace mm {

namespace {

// Bones shorter than this (metres) cannot be bent meaningfully.
constexpr float kMinBoneLength = 1e-6f;

// An angle as its cosine and sine: every angle of the solve is only ever turned
// into a rotation, and a rotation's quaternion needs the half angle's cosine and sine, which
// follow from these by algebra (rotation_about), so no angle is ever computed.
struct Angle {
  float cos = 1.0f;
  float sin = 0.0f;
};

// The angle whose cosine and sine are proportional to d and c.
Angle angle_from(float d, float c) {
  const float r = std::sqrt(d * d + c * c);
  return r > 0.0f ? Angle{d / r, c / r} : Angle{};
}

// The unsigned angle between two vectors (both non-zero), from their dot and cross products:
// accurate near 0 and pi, where an arccosine of the dot product alone is not.
Angle angle_between(const glm::vec3& u, const glm::vec3& v) {
  return angle_from(glm::dot(u, v), glm::length(glm::cross(u, v)));
}

// The interior angle opposite side c of a triangle with sides a, b, c (law of cosines).
Angle triangle_angle(float a, float b, float opposite) {
  const float cosine =
      std::clamp((a * a + b * b - opposite * opposite) / (2.0f * a * b), -1.0f, 1.0f);
  return {cosine, std::sqrt(std::max(0.0f, 1.0f - cosine * cosine))};
}

// The rotation by `to` minus `from` about the unit `axis`, t's cosine and sine by the
// difference formulas. The half-angle identities make (1 + cos t, sin t axis) and
// (sin t, (1 - cos t) axis) both proportional to the quaternion of angle t; the first loses
// precision near a half turn and the second near none, so each is taken where the other is
// worse (w >= 0: t lies in (-pi, pi]).
glm::quat rotation_about(const Angle& to, const Angle& from, const glm::vec3& axis) {
  const float c = to.cos * from.cos + to.sin * from.sin;
  const float s = to.sin * from.cos - to.cos * from.sin;
  glm::quat q;
  if (c >= 0.0f) {
    q = glm::quat(1.0f + c, s * axis);
  } else {
    q = glm::quat(std::abs(s), (s < 0.0f ? c - 1.0f : 1.0f - c) * axis);
  }
  return glm::normalize(q);
}

// A unit vector perpendicular to u (|u| > 0), preferring the direction of `hint`'s part
// perpendicular to u when it has one.
glm::vec3 perpendicular(const glm::vec3& u, const glm::vec3& hint) {
  const glm::vec3 un = glm::normalize(u);
  glm::vec3 p = hint - glm::dot(hint, un) * un;
  if (glm::length(p) > 1e-6f * (glm::length(hint) + 1e-30f) && glm::length(p) > 1e-20f) {
    return glm::normalize(p);
  }
  const glm::vec3 other = std::abs(un.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(un, other));
}

// A quaternion product and a rotated vector in GLM's formulas, always inlined: the solve's few
// products and rotations were calls to GLM's out-of-line copies. With SSE2 in registers
// (transform_sse.hpp: the same bits).
#if defined(__SSE2__)
[[gnu::always_inline]] inline glm::quat mul(const glm::quat& p, const glm::quat& q) {
  return sse::to_quat(sse::product(sse::load(p), sse::load(q)));
}

[[gnu::always_inline]] inline glm::vec3 rotate(const glm::quat& q, const glm::vec3& v) {
  return sse::to_vec3(sse::rotate(sse::load(q), sse::load(v)));
}
#else
[[gnu::always_inline]] inline glm::quat mul(const glm::quat& p, const glm::quat& q) {
  return glm::quat(
      p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z, p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
      p.w * q.y + p.y * q.w + p.z * q.x - p.x * q.z, p.w * q.z + p.z * q.w + p.x * q.y - p.y * q.x);
}

[[gnu::always_inline]] inline glm::vec3 rotate(const glm::quat& q, const glm::vec3& v) {
  const glm::vec3 u(q.x, q.y, q.z);
  const glm::vec3 uv = glm::cross(u, v);
  const glm::vec3 uuv = glm::cross(u, uv);
  return v + ((uv * q.w) + uuv) * 2.0f;
}
#endif

// The rotation that takes the orthonormal pair (u, n) to the orthonormal pair (u2, n2) (and so
// u x n to u2 x n2): the product of the two frames' matrices, one transposed, as a quaternion.
glm::quat turn_between_frames(const glm::vec3& u, const glm::vec3& n, const glm::vec3& u2,
                              const glm::vec3& n2) {
  const glm::mat3 from(u, n, glm::cross(u, n));
  const glm::mat3 to(u2, n2, glm::cross(u2, n2));
  return glm::quat_cast(to * glm::transpose(from));
}

// The solve as two turns: the hip's (bend, swing, twist: every joint of the chain turns by it)
// and the knee's bend (about the same axis as the hip's bend, so the two commute and the knee's
// new local rotation is its bend seen from the hip, whatever the swing and the twist).
struct ChainTurns {
  glm::quat hip_turn{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat knee_bend{1.0f, 0.0f, 0.0f, 0.0f};
  bool reached = false;
};

// Whether every value the solve reads is finite (the end's rotation it does not read). With
// SSE2 one check of a register instead of a compare and a branch per component: a finite value
// times zero is a zero, an infinity or a NaN times zero is a NaN, and a sum with a NaN is NaN.
bool input_finite(const TwoBoneIkInput& in) {
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps();
  __m128 sum = _mm_mul_ps(sse::load(in.root.rotation), zero);
  for (const __m128 value :
       {sse::load(in.mid.rotation), sse::load(in.root_parent_rotation),
        sse::load(in.root.translation), sse::load(in.mid.translation),
        sse::load(in.end.translation), sse::load(in.target), sse::load(in.pole),
        sse::load(in.hinge), _mm_set_ss(in.extension_epsilon)}) {
    sum = _mm_add_ps(sum, _mm_mul_ps(value, zero));
  }
  return _mm_movemask_ps(_mm_cmpunord_ps(sum, sum)) == 0;
#else
  return finite(in.root.translation) && finite(in.mid.translation) && finite(in.end.translation) &&
         finite(in.target) && finite(in.pole) && finite(in.hinge) && finite(in.root.rotation) &&
         finite(in.mid.rotation) && finite(in.root_parent_rotation) &&
         std::isfinite(in.extension_epsilon);
#endif
}

// The solve about a hinge (TwoBoneIkInput::hinge): the knee turns about it to the interior angle
// that makes the hip-ankle distance `reach`, then the chain swings the least way onto the line
// to the target. The axis is taken square to the thigh, about which the knee turns; a shin not
// square to it turns on a cone, whose part across the axis is the triangle's side. False where
// there is no hinge, or it lies along the thigh: the pole's solve then.
bool hinge_turns(const TwoBoneIkInput& in, const glm::vec3& ab, const glm::vec3& bc, float reach,
                 const glm::vec3& direction, ChainTurns& out) {
  const float upper = glm::length(ab);
  // Bending closes the knee: its interior angle opens about the hinge's opposite.
  glm::vec3 axis = -(in.hinge - glm::dot(in.hinge, ab) / (upper * upper) * ab);
  const float axis_length = glm::length(axis);
  if (!(axis_length > 1e-3f * glm::length(in.hinge))) return false;
  axis /= axis_length;
  const glm::vec3 shin_across = bc - glm::dot(bc, axis) * axis;
  const float across = glm::length(shin_across);
  if (!(across > 1e-6f * upper)) return false;
  // The interior angle now, signed: past 180 degrees (its sine negative) for a knee
  // overstretched backward, which so unbends through straight instead of bending further back.
  const Angle now = angle_from(glm::dot(-ab, shin_across), glm::dot(axis, glm::cross(-ab, bc)));
  const float along = glm::dot(bc, axis);
  const float cosine = std::clamp(
      (upper * upper + across * across + along * along - reach * reach) / (2.0f * upper * across),
      -1.0f, 1.0f);
  const Angle wanted{cosine, std::sqrt(std::max(0.0f, 1.0f - cosine * cosine))};
  out.knee_bend = rotation_about(wanted, now, axis);
  out.hip_turn = quat_between(ab + rotate(out.knee_bend, bc), direction);
  return true;
}

// False for zero-length bones or non-finite input (the chain is then left as it is).
bool solve_turns(const TwoBoneIkInput& in, ChainTurns& out) {
  const glm::vec3 a = in.root.translation;
  const glm::vec3 b = in.mid.translation;
  const glm::vec3 c = in.end.translation;
  // Each length computed once: with errno kept by the library's sqrt, the compiler does not
  // merge two square roots of the same sum.
  const glm::vec3 ab = b - a;
  const glm::vec3 ac = c - a;
  const float upper = glm::length(ab);  // glm::distance(a, b) is this length
  const float lower = glm::distance(b, c);
  if (!input_finite(in) || upper < kMinBoneLength || lower < kMinBoneLength) {
    return false;
  }

  // Clamp the wanted hip-to-ankle distance to what the two bones can make.
  const float total = upper + lower;
  const float epsilon = std::clamp(in.extension_epsilon, 0.0f, 0.5f);
  const float max_reach = total * (1.0f - epsilon);
  const float min_reach = std::min(std::abs(upper - lower) + epsilon * total, max_reach);
  const float target_distance = glm::distance(a, in.target);
  const float reach = std::clamp(target_distance, min_reach, max_reach);

  // The direction to reach along: toward the target, or (target at the hip) the current one.
  glm::vec3 direction = in.target - a;
  float direction_length = target_distance;  // glm::distance(a, target) is this length
  const float ac_length = glm::length(ac);
  if (!(target_distance > 1e-6f * total)) {
    direction = ac;
    direction_length = ac_length;
  }
  if (!(direction_length > 1e-6f * total)) direction = ab;
  direction = glm::normalize(direction);

  out.reached = target_distance >= min_reach && target_distance <= max_reach;
  if (hinge_turns(in, ab, c - b, reach, direction, out)) return true;

  // 1. Bend about the current bend axis: the knee's interior angle goes to the one that makes
  // the hip-ankle distance `reach`, and the hip turns so the ankle stays on its old line.
  glm::vec3 bend_axis = glm::cross(ac, ab);
  const float bend_axis_length = glm::length(bend_axis);
  Angle hip_angle_now;
  const bool has_plane = bend_axis_length > 1e-6f * upper * ac_length && ac_length > 1e-6f * total;
  if (has_plane) {
    bend_axis /= bend_axis_length;
    // angle_between(ac, ab), its cross product's length already known.
    hip_angle_now = angle_from(glm::dot(ac, ab), bend_axis_length);
  } else {
    // Straight or folded limb: no plane yet. Bend toward the pole; step 3 settles the twist.
    bend_axis = glm::normalize(glm::cross(ab, perpendicular(ab, in.pole)));
  }
  Angle knee_angle_now = angle_between(a - b, c - b);
  const glm::vec3 pole_across = in.pole - glm::dot(in.pole, direction) * direction;
  const float pole_across_length = glm::length(pole_across);
  // A limb bent away from the pole (a knee overstretched backward, as standing actors' knees
  // are) unbends through straight toward it, as a hinge does: its angles are taken about the
  // other way round axis, the knee's past 180 degrees. Twisted round the hip-target line
  // instead, the thigh and shin would turn half a turn about themselves, the knee's front to
  // the back.
  if (has_plane && glm::dot(bend_axis, glm::cross(direction, pole_across)) < 0.0f) {
    bend_axis = -bend_axis;
    hip_angle_now.sin = -hip_angle_now.sin;
    knee_angle_now.sin = -knee_angle_now.sin;
  }
  const Angle hip_angle = triangle_angle(upper, reach, lower);
  const glm::quat knee_bend =
      rotation_about(triangle_angle(upper, lower, reach), knee_angle_now, bend_axis);
  out.knee_bend = knee_bend;

  // Where the three steps below end, written down at once: the knee bent, the hip-to-ankle line
  // lies along the direction and the bend axis (ac x ab, turned round above if need be, whose
  // sign the bends keep: both are about it and end with the triangle's angles inside (0, pi)) is
  // direction x the pole's side of it, so the knee is on that side. The hip's turn takes the
  // bent chain's hip-to-ankle line and the bend axis to those, so the ankle lands on the line to
  // the target whatever the rounding of the bend (as the swing of step 2 makes it). Taken where the
  // limb has a plane, the knee leaves the line and the pole leaves the direction; the steps
  // themselves handle the degenerate cases.
  if (has_plane && hip_angle.sin > 1e-6f && pole_across_length > 1e-6f) {
    const glm::vec3 side = pole_across / pole_across_length;
    const glm::vec3 bent_ankle = ab + rotate(knee_bend, c - b);
    out.hip_turn = turn_between_frames(glm::normalize(bent_ankle), bend_axis, direction,
                                       glm::cross(direction, side));
    return true;
  }

  const glm::quat hip_bend = rotation_about(hip_angle, hip_angle_now, bend_axis);

  const glm::vec3 knee = rotate(hip_bend, ab);  // from the hip
  const glm::vec3 ankle = knee + rotate(knee_bend, rotate(hip_bend, c - b));

  // 2. Swing the whole chain about the hip so the ankle lies on the line toward the target.
  const glm::quat swing = quat_between(ankle, direction);

  // 3. Twist about that line so the knee is in the half-plane of the pole.
  const glm::vec3 knee_offset = rotate(swing, knee);
  glm::quat turn = swing;
  const glm::vec3 knee_across = knee_offset - glm::dot(knee_offset, direction) * direction;
  if (glm::length(knee_across) > 1e-6f * upper && pole_across_length > 1e-6f) {
    // The signed angle from the knee's side to the pole's about the direction, its sine the
    // cross product's part along the direction.
    const float cosine = glm::dot(knee_across, pole_across);
    const float sine = glm::dot(direction, glm::cross(knee_across, pole_across));
    const float r = std::sqrt(cosine * cosine + sine * sine);
    if (r > 0.0f)
      turn = mul(rotation_about(Angle{cosine / r, sine / r}, Angle{}, direction), swing);
  }
  out.hip_turn = mul(turn, hip_bend);
  return true;
}

}  // namespace

TwoBoneIkResult solve_two_bone_ik(const TwoBoneIkInput& in) {
  TwoBoneIkResult r;
  ChainTurns t;
  if (!solve_turns(in, t)) {
    r.root_global = in.root.rotation;
    r.mid_global = in.mid.rotation;
    r.root_local = glm::conjugate(in.root_parent_rotation) * in.root.rotation;
    r.mid_local = glm::conjugate(in.root.rotation) * in.mid.rotation;
    r.mid_position = in.mid.translation;
    r.end_position = in.end.translation;
    return r;
  }
  const glm::quat bent_mid = mul(t.knee_bend, in.mid.rotation);
  r.root_global = glm::normalize(mul(t.hip_turn, in.root.rotation));
  r.mid_global = glm::normalize(mul(t.hip_turn, bent_mid));
  r.root_local = glm::normalize(mul(glm::conjugate(in.root_parent_rotation), r.root_global));
  r.mid_local = glm::normalize(mul(glm::conjugate(in.root.rotation), bent_mid));
  const glm::vec3 a = in.root.translation;
  r.mid_position = a + rotate(t.hip_turn, in.mid.translation - a);
  r.end_position = r.mid_position +
                   rotate(t.hip_turn, rotate(t.knee_bend, in.end.translation - in.mid.translation));
  r.reached = t.reached;
  return r;
}

namespace {

// The solve of a pose's chain, its local rotations written and the root's global refreshed (its
// rotation only: the root's translation and scale do not move). A chain the solve cannot bend
// keeps its locals. The result's global rotations and positions are not filled in: the pose's
// callers read the globals they refresh.
TwoBoneIkResult solve_in_place(std::span<const int> parents, std::span<Transform> local,
                               std::span<Transform> global, int root, int mid, int end,
                               const glm::vec3& target, const glm::vec3& pole,
                               const glm::vec3& hinge, float extension_epsilon) {
  MM_ASSERT(parents.size() == local.size() && parents.size() == global.size());
  MM_ASSERT(root >= 0 && mid >= 0 && end >= 0 && static_cast<size_t>(end) < parents.size());
  MM_ASSERT(parents[mid] == root && parents[end] == mid);
  const size_t r = static_cast<size_t>(root), m = static_cast<size_t>(mid);
  TwoBoneIkInput in;
  in.root = global[r];
  in.mid = global[m];
  in.end = global[static_cast<size_t>(end)];
  const int root_parent = parents[r];
  in.root_parent_rotation = root_parent >= 0 ? global[static_cast<size_t>(root_parent)].rotation
                                             : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  in.target = target;
  in.pole = pole;
  in.hinge = hinge;
  in.extension_epsilon = extension_epsilon;
  TwoBoneIkResult result;
  ChainTurns t;
  if (!solve_turns(in, t)) {
    result.root_local = local[r].rotation;
    result.mid_local = local[m].rotation;
    return result;
  }
#if defined(__SSE2__)
  // The same products and normalizations in SSE registers (transform_sse.hpp: the same bits).
  const __m128 parent_rotation = sse::load(in.root_parent_rotation);
  const __m128 root_rotation = sse::load(in.root.rotation);
  const __m128 root_local = sse::normalize(sse::product(
      sse::conjugate(parent_rotation), sse::product(sse::load(t.hip_turn), root_rotation)));
  sse::store(root_local, local[r].rotation);
  sse::store(sse::normalize(
                 sse::product(sse::conjugate(root_rotation),
                              sse::product(sse::load(t.knee_bend), sse::load(in.mid.rotation)))),
             local[m].rotation);
  sse::store(root_parent >= 0 ? sse::product(parent_rotation, root_local) : root_local,
             global[r].rotation);
#else
  local[r].rotation = glm::normalize(
      mul(glm::conjugate(in.root_parent_rotation), mul(t.hip_turn, in.root.rotation)));
  local[m].rotation =
      glm::normalize(mul(glm::conjugate(in.root.rotation), mul(t.knee_bend, in.mid.rotation)));
  global[r].rotation =
      root_parent >= 0 ? mul(in.root_parent_rotation, local[r].rotation) : local[r].rotation;
#endif
  result.root_local = local[r].rotation;
  result.mid_local = local[m].rotation;
  result.reached = t.reached;
  return result;
}

}  // namespace

TwoBoneIkResult apply_two_bone_ik(std::span<const int> parents, std::span<Transform> local,
                                  std::span<Transform> global, int root, int mid, int end,
                                  const glm::vec3& target, const glm::vec3& pole,
                                  const glm::vec3& hinge, float extension_epsilon) {
  const TwoBoneIkResult r = solve_in_place(parents, local, global, root, mid, end, target, pole,
                                           hinge, extension_epsilon);
  // Parents come first, so one pass from the root on refreshes every descendant. Only the root's
  // descendants move: every other joint's global already is the FK of its unchanged local.
  for (size_t i = static_cast<size_t>(root) + 1; i < parents.size(); ++i) {
    int ancestor = parents[i];
    while (ancestor > root) ancestor = parents[ancestor];
    if (ancestor == root) global[i] = compose(global[parents[i]], local[i]);
  }
  return r;
}

TwoBoneIkResult apply_two_bone_ik_above_end(std::span<const int> parents,
                                            std::span<const int> subtree_sizes,
                                            std::span<Transform> local, std::span<Transform> global,
                                            int root, int mid, int end, const glm::vec3& target,
                                            const glm::vec3& pole, const glm::vec3& hinge,
                                            float extension_epsilon) {
  MM_ASSERT(subtree_sizes.size() == parents.size());
  const TwoBoneIkResult r = solve_in_place(parents, local, global, root, mid, end, target, pole,
                                           hinge, extension_epsilon);
  // The root's descendants are the joints right after it; the end's subtree is left to the
  // caller, which changes the end's local and refreshes it then (refreshed here too, it would
  // be computed twice and the first thrown away).
  const int end_last = end + subtree_sizes[static_cast<size_t>(end)];
  const int root_last = root + subtree_sizes[static_cast<size_t>(root)];
  for (int i = root + 1; i < root_last; ++i) {
    if (i == end) {
      i = end_last - 1;
      continue;
    }
    const size_t j = static_cast<size_t>(i);
    sse::compose_into(global[static_cast<size_t>(parents[j])], local[j], global[j]);
  }
  return r;
}

}  // namespace mm
