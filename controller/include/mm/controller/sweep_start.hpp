#pragma once
// A sweep started behind where it goes from (issue 29): a small sphere swept along a toe's way
// in the air starts a radius behind the toe (a sphere starting in contact finds nothing). A toe
// kept a radius off a face and moving away from it then starts inside that face, and the physics
// engine's contact there, at the sweep's start, faces back along the way: the reverse of the
// face's normal. Pushed out along it, the toe went into the face it was leaving (the side of the
// second course's stairs_20_25, 3.5 cm; docs/world.md, session 31). A contact at the start that
// lies across the way (a toe sliding along the riser it is kept off) is the face's own.
//
// Units: metres. Robustness: a sweep of no horizontal length never counts as backed into a face.
// Called per update: no allocation.

#include "mm/controller/world.hpp"

namespace mm {

// A face met at a sweep's start whose normal's share against the way is more than this (cosine)
// faces back along it.
inline constexpr float kAcrossTheWay = 0.5f;

// Whether `hit`, the answer to `sweep` (started `radius` behind where its toe was), met a face
// within half a radius of its start facing back along its way: the start was inside the face.
bool backed_into_face(const ShapeSweep& sweep, const SweepHit& hit, float radius);

}  // namespace mm
