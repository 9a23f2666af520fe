#pragma once
// A distance-constraint relaxation solver (position-based, Gauss-Seidel): each constraint
// keeps two points at a rest length. Relaxing a constraint moves both ends along their
// difference so their distance becomes the rest length, and shares that correction in
// proportion to the two ends' relaxation weights: end a moves by w_a / (w_a + w_b) of it and
// end b by w_b / (w_a + w_b). A zero weight pins that end; equal weights move both ends
// equally. A constraint is skipped when its total weight is zero (both ends pinned), when its
// ends coincide (no direction to move along), or when any of its numbers is not finite.
// Negative weights count as zero. Used for foot locking and for restoring bone lengths after
// points were moved. Nothing here allocates.

#include <span>

#include <glm/glm.hpp>

namespace mm {

// One distance constraint between two points of a point array (e.g. joint positions).
struct DistanceConstraint {
  int a = 0;                 // index of the first end
  int b = 0;                 // index of the second end
  float rest_length = 0.0f;  // the distance to keep between them (metres, >= 0)
  float weight_a = 1.0f;     // relaxation weight of end a: its share of the correction (0 pins)
  float weight_b = 1.0f;     // relaxation weight of end b: its share of the correction (0 pins)
};

// Relaxes one constraint between the points a and b once, exactly to the rest length. Returns
// false, leaving both points unchanged, when the constraint is skipped (see above).
bool relax_distance_constraint(glm::vec3& a, glm::vec3& b, float rest_length, float weight_a,
                               float weight_b);

// Runs `iterations` passes over all constraints in order, relaxing each against the points as
// they are at that moment (Gauss-Seidel). Every index must be in [0, points.size()).
void relax_distance_constraints(std::span<glm::vec3> points,
                                std::span<const DistanceConstraint> constraints, int iterations);

// The largest |distance - rest_length| over the constraints: how far from solved they are.
float max_distance_constraint_error(std::span<const glm::vec3> points,
                                    std::span<const DistanceConstraint> constraints);

}  // namespace mm
