#pragma once
// A world for tests, answered exactly from its definition rather than by a physics engine: a
// ground given as a height function, and boxes standing on it (footprints rotated about Y, from
// far below up to `top`). Sweeps test the capsule's footprint circle against each box's
// footprint grown by the radius (square corners: close enough for walls and steps), for boxes
// whose top is above the capsule's bottom; the terrain itself never blocks a sweep (its
// steepness is the ground probe's to judge). It counts its calls, and can be told to answer
// garbage.

#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/local_origin.hpp"
#include "mm/controller/world.hpp"

namespace mm::test {

struct AnalyticBox {
  glm::vec2 center{0.0f};  // world x, z
  glm::vec2 half{0.5f};    // half extents along the box's own x and z
  float yaw = 0.0f;        // rotation about +Y (radians)
  float top = 1.0f;        // world y of the top face
};

class AnalyticWorld : public WorldQueries {
 public:
  // World y of the ground at world (x, z); flat y = 0 by default.
  std::function<double(double x, double z)> height = [](double, double) { return 0.0; };
  std::vector<AnalyticBox> boxes;
  // Where the world's coordinates start: geometry is defined relative to it (to test far away).
  glm::dvec3 offset{0.0};
  // Answers garbage: NaN fractions and points, zero normals, points off the probe.
  bool garbage = false;
  // Counted atomically: several controllers may query one world from several threads.
  mutable std::atomic<int> probe_calls{0};
  mutable std::atomic<int> sweep_calls{0};
  mutable std::atomic<int> probes{0};
  mutable std::atomic<int> sweeps{0};

  void probe_ground(const glm::dvec3& origin, std::span<const GroundProbe> queries,
                    std::span<GroundHit> hits) const override {
    ++probe_calls;
    probes += static_cast<int>(queries.size());
    for (size_t i = 0; i < queries.size(); ++i) hits[i] = probe(origin, queries[i]);
  }

  void sweep(const glm::dvec3& origin, std::span<const ShapeSweep> queries,
             std::span<SweepHit> hits) const override {
    ++sweep_calls;
    sweeps += static_cast<int>(queries.size());
    for (size_t i = 0; i < queries.size(); ++i) hits[i] = sweep_one(origin, queries[i]);
  }

  // The ground's (or a box top's) height under world-relative (x, z), as probe_ground sees it
  // from high above.
  double surface(double x, double z) const {
    double y = height(x, z);
    for (const AnalyticBox& b : boxes) {
      if (inside(b, x, z, 0.0)) y = std::max(y, static_cast<double>(b.top));
    }
    return y;
  }

 private:
  static glm::dvec2 to_box(const AnalyticBox& b, double x, double z) {
    const double dx = x - b.center.x, dz = z - b.center.y;
    const double c = std::cos(b.yaw), s = std::sin(b.yaw);
    // The inverse of the box's rotation about +Y (x' = c x - s z for a yaw of -angle).
    return {c * dx - s * dz, s * dx + c * dz};
  }
  static glm::dvec2 from_box(const AnalyticBox& b, const glm::dvec2& v) {
    const double c = std::cos(b.yaw), s = std::sin(b.yaw);
    return {c * v.x + s * v.y, -s * v.x + c * v.y};
  }
  static bool inside(const AnalyticBox& b, double x, double z, double grow) {
    const glm::dvec2 p = to_box(b, x, z);
    return std::abs(p.x) <= b.half.x + grow && std::abs(p.y) <= b.half.y + grow;
  }

  GroundHit probe(const glm::dvec3& origin, const GroundProbe& q) const {
    GroundHit hit;
    if (garbage) {
      hit.hit = true;
      hit.point = glm::vec3(std::numeric_limits<float>::quiet_NaN(), 0.0f, 5.0f);
      hit.normal = glm::vec3(0.0f);
      hit.walkable = true;
      return hit;
    }
    const glm::dvec3 from = origin + glm::dvec3(q.from) - offset;
    double best = -std::numeric_limits<double>::infinity();
    glm::dvec3 normal(0.0, 1.0, 0.0);
    const double ground = height(from.x, from.z);
    if (ground <= from.y + 1e-9) {
      best = ground;
      constexpr double h = 1e-3;
      const double dx = (height(from.x + h, from.z) - height(from.x - h, from.z)) / (2 * h);
      const double dz = (height(from.x, from.z + h) - height(from.x, from.z - h)) / (2 * h);
      normal = glm::normalize(glm::dvec3(-dx, 1.0, -dz));
    }
    for (const AnalyticBox& b : boxes) {
      if (b.top <= from.y + 1e-9 && b.top > best && inside(b, from.x, from.z, 0.0)) {
        best = b.top;
        normal = glm::dvec3(0.0, 1.0, 0.0);
      }
    }
    if (!(best >= from.y - q.max_distance)) return hit;
    hit.hit = true;
    hit.point = glm::vec3(glm::dvec3(from.x, best, from.z) + offset - origin);
    hit.normal = glm::vec3(normal);
    hit.walkable = normal.y >= q.min_walkable_normal_y;
    return hit;
  }

  SweepHit sweep_one(const glm::dvec3& origin, const ShapeSweep& q) const {
    SweepHit result;
    if (garbage) {
      result.hit = true;
      result.fraction = std::numeric_limits<float>::quiet_NaN();
      return result;
    }
    const glm::dvec3 from = origin + glm::dvec3(q.from) - offset;
    const glm::dvec3 to = origin + glm::dvec3(q.to) - offset;
    double best = 2.0;
    glm::dvec2 best_normal(0.0);
    for (const AnalyticBox& b : boxes) {
      if (b.top <= from.y + 1e-6) continue;  // the capsule passes over it
      const glm::dvec2 a = to_box(b, from.x, from.z);
      const glm::dvec2 e = to_box(b, to.x, to.z);
      const glm::dvec2 d = e - a;
      const glm::dvec2 half = glm::dvec2(b.half) + glm::dvec2(q.radius);
      // Slab test of the segment against the grown footprint.
      double enter = 0.0, leave = 1.0;
      glm::dvec2 normal(0.0);
      bool missed = false;
      for (int k = 0; k < 2 && !missed; ++k) {
        if (std::abs(d[k]) < 1e-12) {
          missed = std::abs(a[k]) > half[k];
          continue;
        }
        double t0 = (-half[k] - a[k]) / d[k], t1 = (half[k] - a[k]) / d[k];
        const double sign = d[k] > 0 ? -1.0 : 1.0;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > enter) {
          enter = t0;
          normal = glm::dvec2(0.0);
          normal[k] = sign;
        }
        leave = std::min(leave, t1);
        missed = enter > leave;
      }
      if (missed || enter >= best) continue;
      if (normal == glm::dvec2(0.0)) {
        // Starting inside: pushed out along the nearest face.
        const double gx = half.x - std::abs(a.x), gz = half.y - std::abs(a.y);
        normal =
            gx < gz ? glm::dvec2(a.x < 0 ? -1.0 : 1.0, 0.0) : glm::dvec2(0.0, a.y < 0 ? -1.0 : 1.0);
      }
      best = enter;
      best_normal = from_box(b, normal);
    }
    if (best > 1.0) return result;
    result.hit = true;
    result.fraction = static_cast<float>(best);
    result.normal =
        glm::vec3(static_cast<float>(best_normal.x), 0.0f, static_cast<float>(best_normal.y));
    return result;
  }
};

}  // namespace mm::test
