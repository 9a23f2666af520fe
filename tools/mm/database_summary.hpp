#pragma once
// What `mm build` and `mm info` print about a database.

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "mm/database/database.hpp"

namespace mm::cli {

// Prints clips (and mirrored copies), frames, duration, rate, searchable frames, the idle clip,
// joints and roles, feature dimensions and channels, and tags with their clip and frame counts.
// `file_bytes` (when > 0) is printed as the file size. `idle_source` (e.g. "frame 37 of
// <clip>") says which frame the idle clip holds; the file does not record it, so only the
// builder can say.
void print_database_summary(FILE* out, const Database& db, uint64_t file_bytes,
                            const std::string& idle_source = {});

// Prints one line per joint role: its name and the joint that plays it ("-" when absent).
void print_joint_map(FILE* out, const Skeleton& skeleton, const JointRoleIndices& roles);

// Prints one line per feature channel: name, kind, bone or times, columns, weight, and the
// per-column mean and standard deviation (the normalization's offset and scale * weight).
void print_feature_statistics(FILE* out, const Database& db);

}  // namespace mm::cli
