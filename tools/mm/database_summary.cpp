#include "database_summary.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mm/database/files.hpp"
#include "mm/offline/idle.hpp"

namespace mm::cli {

namespace {

const char* kind_name(FeatureKind kind) {
  switch (kind) {
    case FeatureKind::BonePosition:
      return "bone-position";
    case FeatureKind::BoneVelocity:
      return "bone-velocity";
    case FeatureKind::TrajectoryPosition:
      return "trajectory-position";
    case FeatureKind::TrajectoryDirection:
      return "trajectory-direction";
    case FeatureKind::BoneDirection:
      return "bone-direction";
  }
  return "unknown";
}

}  // namespace

void print_joint_map(FILE* out, const Skeleton& skeleton, const JointRoleIndices& roles) {
  std::fprintf(out, "joint map:\n");
  for (const JointRoleInfo& role : kJointRoles) {
    const int joint = roles.*role.index;
    const bool known = joint >= 0 && joint < skeleton.joint_count();
    std::fprintf(out, "  %-16.*s %s%s\n", static_cast<int>(role.name.size()), role.name.data(),
                 known ? skeleton.name(joint).c_str() : "-",
                 known ? "" : (role.required ? "  (required, missing)" : "  (absent)"));
  }
}

// One line per style: clips, duration, and which kinds of motion it has, from the clips' motion
// tags (a Bandai name's content word).
void print_styles(FILE* out, const Database& db) {
  if (db.style_names().empty()) return;
  const std::pair<const char*, const char*> kinds[] = {
      {"walk", "walk"},         {"run", "run"},           {"dash", "run"},
      {"walk-turn", "turns"},   {"walk-left", "strafes"}, {"walk-right", "strafes"},
      {"walk-back", "backward"}};
  std::fprintf(out, "styles:      %zu (clips without one, such as idle, serve every style)\n",
               db.style_names().size());
  for (size_t s = 0; s < db.style_names().size(); ++s) {
    int clips = 0;
    long long frames = 0;
    std::vector<std::string> covers;
    for (const ClipRange& c : db.clips()) {
      if (c.style != static_cast<int>(s)) continue;
      ++clips;
      frames += c.frame_count();
      for (size_t t = 0; t < db.tag_names().size() && t < 64; ++t) {
        if (!(c.tags & (uint64_t{1} << t))) continue;
        for (const auto& [prefix, kind] : kinds) {
          if (db.tag_names()[t].starts_with(prefix) &&
              std::find(covers.begin(), covers.end(), kind) == covers.end())
            covers.emplace_back(kind);
        }
      }
    }
    std::string list;
    for (const std::string& k : covers) list += (list.empty() ? "" : ", ") + k;
    std::fprintf(out, "  %-24s %5d clips %8.1f s  %s\n", db.style_names()[s].c_str(), clips,
                 static_cast<double>(frames) * db.frame_time(), list.c_str());
  }
  int styleless = 0;
  for (const ClipRange& c : db.clips()) styleless += c.style < 0 ? 1 : 0;
  std::fprintf(out, "  %-24s %5d clips (idle: %s)\n", "(none)", styleless,
               db.tag_mask(std::vector<std::string>{kIdleTag}) != 0 ? "yes" : "no");
}

void print_database_summary(FILE* out, const Database& db, uint64_t file_bytes,
                            const std::string& idle_source) {
  int mirrored = 0;
  for (const ClipRange& c : db.clips()) mirrored += c.mirrored ? 1 : 0;
  const long long searchable =
      std::count(db.searchable().begin(), db.searchable().end(), uint8_t{1});
  const double rate = db.frame_time() > 0.0f ? 1.0 / db.frame_time() : 0.0;
  std::fprintf(out, "clips:       %zu", db.clips().size());
  if (mirrored) std::fprintf(out, " (%d of them mirrored)", mirrored);
  std::fprintf(out, "\nframes:      %d at %.4g Hz (%.1f s, %.1f min)\n", db.frame_count(), rate,
               db.frame_count() * static_cast<double>(db.frame_time()),
               db.frame_count() * static_cast<double>(db.frame_time()) / 60.0);
  std::fprintf(out, "searchable:  %lld frames (%.1f %%)\n", searchable,
               db.frame_count() ? 100.0 * searchable / db.frame_count() : 0.0);
  if (const int idle = find_idle_clip(db); idle >= 0) {
    const ClipRange& clip = db.clips()[static_cast<size_t>(idle)];
    std::fprintf(out, "idle:        %d frames (%.1f s), clip %d", clip.frame_count(),
                 clip.frame_count() * static_cast<double>(db.frame_time()), idle);
    if (!idle_source.empty()) std::fprintf(out, ", holding %s", idle_source.c_str());
    std::fprintf(out, "\n");
  } else {
    // Idle clips of the data (e.g. ReActIdle's), when the builder synthesized none.
    const uint64_t idle_tag = db.tag_mask(std::vector<std::string>{kIdleTag});
    int clips = 0;
    long long frames = 0;
    for (const ClipRange& c : db.clips()) {
      if (!(c.tags & idle_tag)) continue;
      ++clips;
      frames += c.frame_count();
    }
    if (clips == 0) {
      std::fprintf(out, "idle:        none\n");
    } else {
      std::fprintf(out, "idle:        %d clips of the data tagged idle, %lld frames (%.1f s)\n",
                   clips, frames, frames * static_cast<double>(db.frame_time()));
    }
  }
  std::fprintf(out, "joints:      %d (joint 0 '%s')\n", db.joint_count(),
               db.joint_count() ? db.skeleton().name(0).c_str() : "-");
  print_joint_map(out, db.skeleton(), db.roles());
  std::fprintf(out, "features:    %d dimensions in %zu channels:", db.feature_dims(),
               db.schema().channels.size());
  for (const FeatureChannel& c : db.schema().channels) std::fprintf(out, " %s", c.name.c_str());
  const auto is_style = [&](const std::string& tag) {
    return std::find(db.style_names().begin(), db.style_names().end(), tag) !=
           db.style_names().end();
  };
  std::fprintf(out, "\ntags:        %zu (motion and action tags; the styles' own tags below)\n",
               db.tag_names().size());
  for (size_t t = 0; t < db.tag_names().size() && t < 64; ++t) {
    if (is_style(db.tag_names()[t])) continue;
    int clips = 0;
    long long frames = 0;
    for (const ClipRange& c : db.clips()) {
      if (c.tags & (uint64_t{1} << t)) {
        ++clips;
        frames += c.frame_count();
      }
    }
    std::fprintf(out, "  %-24s %5d clips %8lld frames\n", db.tag_names()[t].c_str(), clips, frames);
  }
  print_styles(out, db);
  if (file_bytes > 0) std::fprintf(out, "file size:   %s\n", format_bytes(file_bytes).c_str());
}

void print_feature_statistics(FILE* out, const Database& db) {
  // Per-column deviations from the stored (normalized) matrix over the searchable frames,
  // scaled back to feature units.
  const int dims = db.feature_dims();
  std::vector<double> sum(dims, 0.0), sum_squares(dims, 0.0);
  long long rows = 0;
  for (int f = 0; f < db.frame_count(); ++f) {
    if (!db.searchable()[f]) continue;
    ++rows;
    const float* row = db.features().data() + static_cast<size_t>(f) * dims;
    for (int c = 0; c < dims; ++c) {
      sum[c] += row[c];
      sum_squares[c] += static_cast<double>(row[c]) * row[c];
    }
  }
  std::fprintf(out,
               "feature statistics over the %lld searchable frames (group std = the channel's "
               "normalization deviation = scale * weight):\n",
               rows);
  for (size_t i = 0; i < db.schema().channels.size(); ++i) {
    const FeatureChannel& c = db.schema().channels[i];
    const int first = db.schema().offset(static_cast<int>(i));
    std::string source;
    if (c.kind == FeatureKind::TrajectoryPosition || c.kind == FeatureKind::TrajectoryDirection) {
      source = "times";
      for (float t : c.times) {
        char buffer[32];
        std::snprintf(buffer, sizeof buffer, " %g", t);
        source += buffer;
      }
      source += " s";
    } else {
      source = "bone " + c.bone;
    }
    const double group_std = static_cast<double>(db.feature_scale()[first]) * c.weight;
    std::fprintf(out, "  %-22s %-20s %-24s columns %2d-%2d  weight %-5g group std %.4f\n",
                 c.name.c_str(), kind_name(c.kind), source.c_str(), first, first + c.dims() - 1,
                 c.weight, group_std);
    std::fprintf(out, "      mean:");
    for (int k = first; k < first + c.dims(); ++k)
      std::fprintf(out, " %8.4f", db.feature_offset()[k]);
    std::fprintf(out, "\n      std: ");
    for (int k = first; k < first + c.dims(); ++k) {
      double column_std = 0.0;
      if (rows > 0) {
        const double mean = sum[k] / rows;
        column_std =
            std::sqrt(std::max(0.0, sum_squares[k] / rows - mean * mean)) * db.feature_scale()[k];
      }
      std::fprintf(out, " %8.4f", column_std);
    }
    std::fprintf(out, "\n");
  }
}

}  // namespace mm::cli
