#pragma once
// The local origin of a controller in a big world.
//
// A float holds about seven significant digits: a position kilometres from the world origin
// keeps only millimetres, and foot locking needs far finer steps than that (a locked toe that
// moves by one float step every frame already shows as skating). So a controller keeps every
// position of its state (simulation object, trajectory, root, transition source, joints, foot
// locks) relative to a local origin near the character, in float, and the origin itself in
// double. When the simulation object strays farther than kRebaseDistance from the origin, the
// origin jumps to the whole metre nearest it (a rebase): every stored position is shifted by
// the same whole-metre amount, which changes nothing in the motion. The state never holds a
// coordinate much larger than kRebaseDistance, wherever the character is.
//
// Near the world origin (within kRebaseDistance of it) a teleport leaves the origin at zero,
// so a character that stays there has local = world, exactly as before big worlds existed.
//
// Units: metres. The origin is always on the ground (y = 0) at whole metres in x and z.

#include <cmath>

#include <glm/glm.hpp>

namespace mm {

// The simulation object farther than this (m, horizontally) from the local origin rebases it.
// Small, so local coordinates stay where a float is finest; rebasing costs a few hundred
// additions, so doing it every few seconds of walking is free.
inline constexpr float kRebaseDistance = 8.0f;

// The horizontal whole-metre shift that moves the origin onto `local` (a position relative to
// the current origin) once it is farther than kRebaseDistance from it; zero otherwise. Whole
// metres keep the double origin exact; the float positions near the character, shifted by a
// number that close to them, round by at most the float step there (sub-micrometre), once.
inline glm::vec3 rebase_shift(const glm::vec3& local) {
  if (std::hypot(local.x, local.z) <= kRebaseDistance) return glm::vec3(0.0f);
  return glm::vec3(std::round(local.x), 0.0f, std::round(local.z));
}

// The local origin for a character placed at `world`: zero within kRebaseDistance of the
// world origin, else the whole metre nearest it on the ground. Non-finite input gives zero.
inline glm::dvec3 origin_for(const glm::dvec3& world) {
  if (!std::isfinite(world.x) || !std::isfinite(world.z)) return glm::dvec3(0.0);
  if (std::hypot(world.x, world.z) <= static_cast<double>(kRebaseDistance)) return glm::dvec3(0.0);
  return glm::dvec3(std::round(world.x), 0.0, std::round(world.z));
}

// A world position from one relative to `origin`, and back (the difference taken in double,
// then rounded once to float).
inline glm::dvec3 to_world(const glm::dvec3& origin, const glm::vec3& local) {
  return origin + glm::dvec3(local);
}
inline glm::vec3 to_local(const glm::dvec3& origin, const glm::dvec3& world) {
  return glm::vec3(world - origin);
}

}  // namespace mm
