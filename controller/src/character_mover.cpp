// A character's capsule through the game's world: sweep, slide, ground (character_mover.hpp).

#include "mm/controller/character_mover.hpp"

#include <algorithm>
#include <cmath>

#include "mm/runtime/assert.hpp"
#include "mm/runtime/finite.hpp"

namespace mm {

namespace {

// A contact normal's horizontal part, unit length; when the contact is (nearly) level, a floor
// or ceiling met at the capsule's edge, it stops the move head-on instead.
glm::vec3 horizontal_normal(const glm::vec3& normal, const glm::vec3& move) {
  glm::vec3 n(normal.x, 0.0f, normal.z);
  const float length = glm::length(n);
  if (length > 0.1f) return n / length;
  const float move_length = glm::length(move);
  return move_length > 0.0f ? -move / move_length : glm::vec3(0.0f);
}

// The part of a sweep from -> to that may be travelled, `skin` short of a hit at `fraction`.
float safe_fraction(float fraction, float distance, float skin) {
  return distance > 0.0f ? std::max(0.0f, fraction - skin / distance) : 0.0f;
}

// The ring's directions (CharacterMover::kEdgeProbes of them, evenly around).
constexpr float kDiagonal = 0.70710678f;
constexpr float kRing[CharacterMover::kEdgeProbes][2] = {
    {1.0f, 0.0f},  {kDiagonal, kDiagonal},   {0.0f, 1.0f},  {-kDiagonal, kDiagonal},
    {-1.0f, 0.0f}, {-kDiagonal, -kDiagonal}, {0.0f, -1.0f}, {kDiagonal, -kDiagonal}};

glm::vec3 lift(const CharacterShape& shape) {
  return glm::vec3(0.0f, shape.step_height, 0.0f);
}

// A contact this close to straight up is the lifted capsule's bottom resting on a step's top: the
// step is as high as the lift, within a few millimetres (a contact a centimetre up its hemisphere
// already leans 15 degrees).
bool on_step_top(const glm::vec3& normal) {
  return normal.y >= CharacterMover::kStepTopNormalY;
}

}  // namespace

bool CharacterMover::accept(const ShapeSweep& query, SweepHit& hit) {
  (void)query;
  if (!hit.hit) return true;
  const float length = glm::length(hit.normal);
  if (!std::isfinite(hit.fraction) || hit.fraction < -1e-3f || hit.fraction > 1.0f + 1e-3f ||
      !finite(hit.normal) || !(length > 0.5f && length < 2.0f)) {
    ++rejected_;
    hit = SweepHit{};
    return false;
  }
  hit.fraction = std::clamp(hit.fraction, 0.0f, 1.0f);
  hit.normal /= length;
  return true;
}

bool CharacterMover::accept(const GroundProbe& query, GroundHit& hit) {
  if (!hit.hit) return true;
  constexpr float kTolerance = 0.01f;  // m: how far off the probe's segment a point may be
  const float length = glm::length(hit.normal);
  const bool on_segment = finite(hit.point) && std::abs(hit.point.x - query.from.x) <= kTolerance &&
                          std::abs(hit.point.z - query.from.z) <= kTolerance &&
                          hit.point.y <= query.from.y + kTolerance &&
                          hit.point.y >= query.from.y - query.max_distance - kTolerance;
  if (!on_segment || !finite(hit.normal) || !(length > 0.5f && length < 2.0f)) {
    ++rejected_;
    hit = GroundHit{};
    return false;
  }
  hit.normal /= length;
  if (hit.normal.y < 0.0f) hit.normal = -hit.normal;
  return true;
}

void CharacterMover::collide(const WorldQueries& world, const glm::dvec3& origin,
                             const CharacterShape& shape, std::span<const glm::vec3> starts,
                             std::span<const glm::vec3> goals, std::span<MoveResult> out) {
  const size_t n = starts.size();
  MM_ASSERT(n <= static_cast<size_t>(kMaxMoves) && goals.size() == n && out.size() == n);
  const glm::vec3 up = lift(shape);
  // 1. Sweep every move that goes anywhere.
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 d = goals[i] - starts[i];
    d.y = 0.0f;
    out[i] = MoveResult{};
    // Unobstructed, the goal itself (start + (goal - start) is not always the goal in float).
    out[i].position = glm::vec3(goals[i].x, starts[i].y, goals[i].z);
    if (glm::length(d) < 1e-6f) continue;
    sweeps_[count] = ShapeSweep{starts[i] + up, starts[i] + up + d, shape.radius, shape.height};
    slid_[count++] = static_cast<int>(i);
  }
  if (count > 0)
    world.sweep(origin, std::span(sweeps_).first(count), std::span(sweep_hits_).first(count));
  // 2. Slide what a hit cut off along the obstacle; climb a step the capsule's bottom rests on.
  size_t slides = 0;
  for (size_t k = 0; k < count; ++k) {
    if (!accept(sweeps_[k], sweep_hits_[k]) || !sweep_hits_[k].hit) continue;
    const size_t i = static_cast<size_t>(slid_[k]);
    const glm::vec3 d = sweeps_[k].to - sweeps_[k].from;
    const float distance = glm::length(d);
    const float travelled = safe_fraction(sweep_hits_[k].fraction, distance, kSkin);
    const glm::vec3 stop = starts[i] + d * travelled;
    const glm::vec3 rest = d * (1.0f - travelled);
    out[i].position = stop;
    climbed_[k] = on_step_top(sweep_hits_[k].normal);
    glm::vec3 from = stop + up, slide = rest;
    if (climbed_[k]) {
      // A step exactly as high as the lift: its top touches the capsule's bottom, and read as a
      // wall head-on it stalled the character at its edge. The rest is swept again from a little
      // higher; the ground probe (3.) finds the step's top and climbs it.
      from.y += kStepClearance;
    } else {
      const glm::vec3 normal = horizontal_normal(sweep_hits_[k].normal, d);
      out[i].blocked = true;
      out[i].normal = normal;
      slide = rest - normal * glm::dot(rest, normal);
      // Stopped kSkin short along a move that met the face at a glancing angle, the capsule is
      // nearly touching it, and a slide along it swept from there met the same face where it
      // started: stuck against a wall it was pushed along (off the lanes, up to 0.85 s at the 60°
      // wall). The slide is swept kSkin off the face's plane, and made where the capsule is:
      // parallel to the face, it comes no nearer to it.
      const float gap = (sweep_hits_[k].fraction - travelled) * distance *
                        std::max(0.0f, -glm::dot(d / distance, normal));
      from += normal * std::max(0.0f, kSkin - gap);
    }
    if (glm::length(slide) < 1e-6f) continue;
    // Written over the sweeps already read: slot `slides` <= k.
    sweeps_[slides] = ShapeSweep{from, from + slide, shape.radius, shape.height};
    climbed_[slides] = climbed_[k];
    slid_[slides++] = static_cast<int>(i);
  }
  if (slides > 0) {
    world.sweep(origin, std::span(sweeps_).first(slides), std::span(sweep_hits_).first(slides));
    for (size_t k = 0; k < slides; ++k) {
      accept(sweeps_[k], sweep_hits_[k]);
      const SweepHit& hit = sweep_hits_[k];
      const glm::vec3 slide = sweeps_[k].to - sweeps_[k].from;
      MoveResult& result = out[static_cast<size_t>(slid_[k])];
      const float travelled =
          hit.hit ? safe_fraction(hit.fraction, glm::length(slide), kSkin) : 1.0f;
      result.position += slide * travelled;
      // After a climb, what stops the rest is the obstacle met (a slide keeps its first one's).
      if (climbed_[k] && hit.hit) {
        result.blocked = true;
        result.normal = horizontal_normal(hit.normal, slide);
      } else if (hit.hit) {
        result.slide_normal = horizontal_normal(hit.normal, slide);
      }
    }
  }
  // 3. The ground where each move ended, reached from the start's height, and ahead of it. The
  // probe starts kStepClearance above the lift: a ray starting exactly on a step's top (a step as
  // high as step_height) passes through it and finds the ground under the step.
  size_t probes = 0;
  for (size_t i = 0; i < n; ++i) {
    const glm::vec3 top(out[i].position.x, starts[i].y + shape.step_height + kStepClearance,
                        out[i].position.z);
    const float reach = shape.step_height + kStepClearance + shape.max_step_down;
    probes_[probes++] = GroundProbe{top, reach, shape.min_walkable_normal_y};
    glm::vec3 d = goals[i] - starts[i];
    d.y = 0.0f;
    const float length = glm::length(d);
    // Only a step within the capsule's own size (the simulation's and the root's per update):
    // the ground ahead of a trajectory sample a metre away, up or down stairs, says nothing.
    const bool short_move = length >= 1e-6f && length <= shape.radius;
    lead_[i] = short_move ? static_cast<int>(probes) : -1;
    if (lead_[i] >= 0) {
      probes_[probes++] = GroundProbe{top + d * (kLedgeLead * shape.radius / length), reach, 0.0f};
    }
    ring_[i] = lead_[i] >= 0 ? static_cast<int>(probes) : -1;
    if (ring_[i] >= 0) {
      // Inner probes first (halfway out), then the outer ones, in the same directions. Each
      // starts as much higher as it is out (a 45 degree rise): ground up a flight of stairs,
      // above the lift, would be no ground to a probe starting inside it, and read as a drop.
      for (const float out_to : {0.5f * kEdgeRing * shape.radius, kEdgeRing * shape.radius}) {
        for (const auto& direction : kRing) {
          const glm::vec3 at = top + glm::vec3(direction[0], 1.0f, direction[1]) * out_to;
          probes_[probes++] = GroundProbe{at, reach + out_to, 0.0f};
        }
      }
    }
  }
  std::fill_n(ground_hits_.begin(), probes, GroundHit{});
  if (probes > 0) {
    world.probe_ground(origin, std::span(probes_).first(probes),
                       std::span(ground_hits_).first(probes));
  }
  for (size_t i = 0, k = 0; i < n; ++i) {
    GroundHit& hit = ground_hits_[k];
    const bool ground = accept(probes_[k], hit) && hit.hit && hit.walkable;
    k += 1 + (lead_[i] >= 0 ? 1 : 0) + (ring_[i] >= 0 ? 2 * kEdgeProbes : 0);
    // A drop up to kStepClearance deeper than a step is a step: walking back, the probe (which
    // starts that much above the lift) finds the top the sweep, starting against its edge, does
    // not; off a box exactly step_height high the floor reads a hair deeper than a step.
    const float step_down = shape.step_height + kStepClearance;
    bool ledge = !ground;
    if (ground && lead_[i] >= 0) {
      const size_t lead = static_cast<size_t>(lead_[i]);
      // A probe that fails the checks is no ground here: the move stops rather than step off.
      if (!accept(probes_[lead], ground_hits_[lead]) || drops(hit, ground_hits_[lead], step_down)) {
        ledge = true;
        glm::vec3 d = goals[i] - starts[i];
        d.y = 0.0f;
        out[i].edge_normal = -glm::normalize(d);
      }
    }
    if (ledge) {
      out[i].position = starts[i];
      out[i].no_ground = true;
      continue;
    }
    out[i].position.y = hit.point.y;
    out[i].ground_normal = hit.normal;
    if (ring_[i] >= 0) {
      keep_off_edges(starts[i], hit, step_down, static_cast<size_t>(ring_[i]), out[i]);
    }
  }
}

// Whether `lead`, probed beyond `from`, found a drop deeper than a step below it, or no ground.
// Measured from the end's own ground, not the start's: a trajectory sample a metre down a stair
// is far below the start and on no ledge.
bool CharacterMover::drops(const GroundHit& from, const GroundHit& lead, float step_down) {
  return !lead.hit || lead.point.y < from.point.y - step_down;
}

// A ledge's edge beside the move's end (a drop deeper than a step under a probe of the ring) is
// met like a wall: the part of the step toward it is taken away, the rest goes on, and a step
// that had such a part is blocked with the edge's normal (the simulation loses its velocity
// into it). With the probe ahead only, a character circling on a platform kept its centre a
// few centimetres from the side edge, one foot planted on air. An answer that fails the checks
// says nothing here: a false edge would bend the path. Drops on opposite sides (a beam narrower
// than the ring) give no direction: the probe ahead still stops the move at either side.
void CharacterMover::keep_off_edges(const glm::vec3& start, const GroundHit& ground,
                                    float step_down, size_t first, MoveResult& out) {
  // Each outward direction in two hops, the centre to the inner probe and that to the outer one,
  // each no longer than a steep stair's tread: down 20 cm risers on 25 cm treads the ground a
  // ring's radius out is two risers lower, a stair and not a ledge.
  glm::vec3 toward(0.0f);
  for (int j = 0; j < kEdgeProbes; ++j) {
    GroundHit& inner = ground_hits_[first + static_cast<size_t>(j)];
    GroundHit& outer = ground_hits_[first + static_cast<size_t>(kEdgeProbes + j)];
    const bool inner_ok = accept(probes_[first + static_cast<size_t>(j)], inner);
    const bool outer_ok = accept(probes_[first + static_cast<size_t>(kEdgeProbes + j)], outer);
    const bool drop = (inner_ok && drops(ground, inner, step_down)) ||
                      (inner_ok && inner.hit && outer_ok && drops(inner, outer, step_down));
    if (drop) toward += glm::vec3(kRing[j][0], 0.0f, kRing[j][1]);
  }
  if (glm::length(toward) < 0.5f) return;
  const glm::vec3 normal = -glm::normalize(toward);
  out.edge_normal = normal;
  glm::vec3 step(out.position.x - start.x, 0.0f, out.position.z - start.z);
  const float into = -glm::dot(step, normal);
  if (into <= 0.0f) return;  // along it or away from it: nothing held back
  step += normal * into;
  const glm::vec3 end(start.x + step.x, 0.0f, start.z + step.z);
  // On the plane of the ground found at the unbent end: exact on a flat top or an even slope.
  const glm::vec3& n = ground.normal;
  out.position = glm::vec3(
      end.x,
      ground.point.y - (n.x * (end.x - ground.point.x) + n.z * (end.z - ground.point.z)) / n.y,
      end.z);
  if (!out.blocked) {
    out.blocked = true;
    out.edge = true;
    out.normal = normal;
  }
}

MoveResult CharacterMover::move(const WorldQueries& world, const glm::dvec3& origin,
                                const CharacterShape& shape, const glm::vec3& start,
                                const glm::vec3& goal) {
  MoveResult result;
  collide(world, origin, shape, std::span(&start, 1), std::span(&goal, 1), std::span(&result, 1));
  return result;
}

glm::vec3 CharacterMover::free_step(const WorldQueries& world, const glm::dvec3& origin,
                                    const CharacterShape& shape, const glm::vec3& position,
                                    const glm::vec3& step) {
  const glm::vec3 d(step.x, 0.0f, step.z);
  if (!(glm::length(d) > 1e-6f)) return d;
  const glm::vec3 from = position + lift(shape);
  const ShapeSweep query{from, from + d, shape.radius, shape.height};
  SweepHit hit;
  world.sweep(origin, std::span(&query, 1), std::span(&hit, 1));
  if (!accept(query, hit) || !hit.hit || on_step_top(hit.normal)) return d;
  const glm::vec3 n = horizontal_normal(hit.normal, d);
  return d - n * std::min(0.0f, glm::dot(d, n));
}

bool CharacterMover::ground(const WorldQueries& world, const glm::dvec3& origin,
                            const CharacterShape& shape, const glm::vec3& position, float above,
                            GroundHit& hit) {
  const GroundProbe probe{position + glm::vec3(0.0f, above, 0.0f), above + shape.max_step_down,
                          shape.min_walkable_normal_y};
  hit = GroundHit{};
  world.probe_ground(origin, std::span(&probe, 1), std::span(&hit, 1));
  return accept(probe, hit) && hit.hit && hit.walkable;
}

void CharacterMover::probe(const WorldQueries& world, const glm::dvec3& origin,
                           std::span<const GroundProbe> probes, std::span<GroundHit> hits) {
  std::fill(hits.begin(), hits.end(), GroundHit{});
  if (probes.empty()) return;
  world.probe_ground(origin, probes, hits);
  for (size_t i = 0; i < probes.size(); ++i) accept(probes[i], hits[i]);
}

void CharacterMover::sweep(const WorldQueries& world, const glm::dvec3& origin,
                           std::span<const ShapeSweep> sweeps, std::span<SweepHit> hits) {
  std::fill(hits.begin(), hits.end(), SweepHit{});
  if (sweeps.empty()) return;
  world.sweep(origin, sweeps, hits);
  for (size_t i = 0; i < sweeps.size(); ++i) accept(sweeps[i], hits[i]);
}

void HeldContacts::hold(glm::vec3& end, const MoveResult& move, float dt) {
  for (int i = 0; i < count_; ++i) planes_[static_cast<size_t>(i)].age += dt;
  keep_if([](const HalfPlane& h) { return h.age <= kMemory; });
  if (finite(move.position)) {
    remember(move.position, move.normal);
    remember(move.position, move.slide_normal);
    remember(move.position, move.edge_normal);
  }
  for (int pass = 0; pass < 2; ++pass) {
    for (int i = 0; i < count_; ++i) {
      const HalfPlane& h = planes_[static_cast<size_t>(i)];
      const float past = glm::dot(h.point - end, h.normal);
      if (past > 0.0f) end += h.normal * past;
    }
  }
  keep_if([&](const HalfPlane& h) { return glm::dot(end - h.point, h.normal) <= kRelease; });
}

// The same obstacle met again moves its line to where the end is now; a new one takes a free
// slot, or the oldest's.
void HeldContacts::remember(const glm::vec3& point, const glm::vec3& normal) {
  const glm::vec3 n(normal.x, 0.0f, normal.z);
  if (glm::length(n) < 0.5f) return;
  const glm::vec3 unit = glm::normalize(n);
  int slot = -1;
  for (int i = 0; i < count_ && slot < 0; ++i) {
    if (glm::dot(planes_[static_cast<size_t>(i)].normal, unit) >= kSameNormal) slot = i;
  }
  if (slot < 0 && count_ < kMax) slot = count_++;
  if (slot < 0) {
    slot = 0;
    for (int i = 1; i < count_; ++i) {
      if (planes_[static_cast<size_t>(i)].age > planes_[static_cast<size_t>(slot)].age) slot = i;
    }
  }
  planes_[static_cast<size_t>(slot)] = HalfPlane{point, unit, 0.0f};
}

glm::vec3 HeldContacts::reach(const glm::vec3& goal) const {
  glm::vec3 deeper = goal;
  for (int i = 0; i < count_; ++i) {
    const HalfPlane& h = planes_[static_cast<size_t>(i)];
    if (glm::dot(h.point - goal, h.normal) >= 0.0f) deeper -= h.normal * kReach;
  }
  return deeper;
}

void HeldContacts::shift(const glm::vec3& by) {
  for (int i = 0; i < count_; ++i) planes_[static_cast<size_t>(i)].point += by;
}

}  // namespace mm
