#pragma once
// A Clip is what an importer produces: a skeleton and one pose (local transforms, metres) per
// frame at a fixed frame time. It is editable "raw" data; the builder turns clips into a
// Database.

#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

struct Clip {
  std::string name;                 // the source file's stem, e.g. "dataset-2_walk_normal_001"
  std::string source_path;          // where it was read from (empty for generated clips)
  Skeleton skeleton;                // depth-first joint order, rest transforms in metres
  float frame_time = 1.0f / 30.0f;  // seconds between frames, > 0
  int frame_count = 0;
  // frame_count * joint_count local transforms, frame-major: local[f * joint_count + j].
  std::vector<Transform> local;
  // Per joint: the offset of its End Site (a BVH leaf's tip, metres, in the joint's frame), zero
  // where it has none. Empty when the importer knows of none (glTF).
  std::vector<glm::vec3> end_sites;
  // What the importer accepted but ignored, one message per kind of problem per file, each
  // naming the file and line ("<file>:<line>: ..."), e.g. BVH frame lines beyond "Frames:";
  // empty for a clean file. Only importers fill it: clips made from this one (resample_clip,
  // retarget_clip, mirror_clip) start without. The builder passes the warnings of every clip it
  // imports or is given on to BuildReport::warnings, and the `mm` commands print them.
  std::vector<std::string> warnings;

  int joint_count() const { return skeleton.joint_count(); }
  float duration() const { return frame_count > 1 ? (frame_count - 1) * frame_time : 0.0f; }
  std::span<const Transform> pose(int frame) const {
    return {local.data() + static_cast<size_t>(frame) * joint_count(),
            static_cast<size_t>(joint_count())};
  }
  std::span<Transform> pose(int frame) {
    return {local.data() + static_cast<size_t>(frame) * joint_count(),
            static_cast<size_t>(joint_count())};
  }

  // Checks sizes, a positive finite frame time, unit finite rotations and finite translations.
  Status validate() const;
};

}  // namespace mm
