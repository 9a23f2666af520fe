// ControllerDatabase: what every controller of one database shares (candidates, searchers,
// measured speeds, tag bits), made once, read-only afterwards.

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mm/controller/controller.hpp"
#include "mm/database/database.hpp"
#include "mm/database/search_input.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

namespace {

// Bit mask of one tag name, 0 when the database does not have it.
uint64_t tag_bit(const Database& db, std::string_view name) {
  for (size_t i = 0; i < db.tag_names().size(); ++i) {
    if (db.tag_names()[i] == name) return uint64_t{1} << i;
  }
  return 0;
}

float median(std::vector<float>& values) {
  if (values.empty()) return 0.0f;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Root speeds of the locomotion frames, split by gait and by direction of travel relative to
// the facing. A direction with too few frames (the Bandai data has no side steps and almost
// no backward walking) takes a fraction of the forward speed.
ControllerDatabase::Speeds measure_speeds(const Database& db, uint64_t excluded_tags) {
  const uint64_t run_tags = tag_bit(db, "run") | tag_bit(db, "dash");
  const int joints = db.joint_count();
  // Samples: [gait][direction], gait 0 walk, 1 run; direction 0 forward, 1 sideways, 2 backward.
  std::vector<float> samples[2][3];
  for (const ClipRange& clip : db.clips()) {
    if (clip.tags & excluded_tags) continue;
    const bool tagged_run = (clip.tags & run_tags) != 0;
    for (int f = clip.start; f < clip.end; ++f) {
      const size_t k = static_cast<size_t>(f) * static_cast<size_t>(joints);
      const glm::vec3 v = db.local_velocities()[k];
      const float speed = std::sqrt(v.x * v.x + v.z * v.z);
      if (speed < 0.3f) continue;
      const glm::vec3 local = glm::conjugate(db.local_rotations()[k]) * v;
      const float angle = std::abs(std::atan2(local.x, local.z));
      const int gait = run_tags ? (tagged_run ? 1 : 0) : (speed > 2.5f ? 1 : 0);
      int direction = -1;
      if (angle < glm::radians(30.0f)) {
        direction = 0;
      } else if (angle > glm::radians(60.0f) && angle < glm::radians(120.0f)) {
        direction = 1;
      } else if (angle > glm::radians(150.0f)) {
        direction = 2;
      }
      if (direction >= 0) samples[gait][direction].push_back(speed);
    }
  }
  // Fewer samples than this (one second of data at 30 Hz) do not make a speed.
  const size_t kMinSamples = 30;
  auto speed_or = [&](int gait, int direction, float fallback) {
    std::vector<float>& s = samples[gait][direction];
    return s.size() >= kMinSamples ? median(s) : fallback;
  };
  ControllerDatabase::Speeds speeds;
  speeds.walk_forward = speed_or(0, 0, speeds.walk_forward);
  speeds.run_forward = speed_or(1, 0, std::max(speeds.run_forward, 2.0f * speeds.walk_forward));
  speeds.walk_sideways = speed_or(0, 1, 0.75f * speeds.walk_forward);
  speeds.walk_backward = speed_or(0, 2, 0.65f * speeds.walk_forward);
  // Runs sideways and backward, where the data has none, are warped forward runs and backward
  // walks (see strafe_warp_max), which carry the character at about half the forward run.
  speeds.run_sideways = speed_or(1, 1, 0.5f * speeds.run_forward);
  speeds.run_backward = speed_or(1, 2, 0.5f * speeds.run_forward);
  return speeds;
}

// `joint` and its ancestors, root first.
std::vector<int> chain_to(const Database& db, int joint) {
  std::vector<int> chain;
  for (int j = joint; j >= 0; j = db.skeleton().parent(j)) chain.push_back(j);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

// The global transform of the chain's last joint at frame f, joint 0 being relative to the
// ground (its clip's origin).
Transform chain_global(const Database& db, std::span<const int> chain, int frame) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  Transform global;
  for (const int j : chain) {
    const size_t k = static_cast<size_t>(frame) * joints + static_cast<size_t>(j);
    global = compose(global, Transform{db.local_rotations()[k], db.local_positions()[k]});
  }
  return global;
}

// The lowest height above the ground of `joint` in any frame (m).
float lowest_height(const Database& db, int joint) {
  const std::vector<int> chain = chain_to(db, joint);
  float lowest = std::numeric_limits<float>::infinity();
  for (int f = 0; f < db.frame_count(); ++f) {
    lowest = std::min(lowest, chain_global(db, chain, f).translation.y);
  }
  return std::isfinite(lowest) ? lowest : 0.0f;
}

// ControllerDatabase::next_landing of one side for every frame: each clip walked backward,
// remembering its latest frame whose label is on (the frame itself where it is).
void find_landings(const Database& db, int side, int end_joint,
                   std::span<ControllerDatabase::FootLanding> landings) {
  const std::vector<int> chain = chain_to(db, end_joint);
  const int horizon =
      clamped_integer<int>(std::floor(ControllerDatabase::kLandingHorizon / db.frame_time()));
  for (const ClipRange& clip : db.clips()) {
    int next = -1;  // the clip's next frame with the label on, and its toe
    glm::vec3 next_toe(0.0f);
    for (int f = clip.end - 1; f >= clip.start; --f) {
      ControllerDatabase::FootLanding& out =
          landings[2 * static_cast<size_t>(f) + static_cast<size_t>(side)];
      if (db.contacts()[2 * static_cast<size_t>(f) + static_cast<size_t>(side)] != 0) {
        next = f;
        next_toe = chain_global(db, chain, f).translation;
      }
      if (next < 0 || next - f > horizon) continue;
      const Transform root = chain_global(db, std::span(chain).first(1), f);
      out.toe = transform_point(inverse(root), next_toe);
      out.found = true;
    }
  }
}

// A knee's bend axis in its own frame (ControllerDatabase::knee_hinge): the mean of its local
// rotations' axes (turned to w >= 0) over the frames it is bent more than kHingeBend, kept when
// they agree (their mean at least kHingeAgreement long, a spread of about 25 degrees at most).
// The bend limits it from an overstretched knee's turn the other way, which the mean would mix in.
constexpr float kHingeBend = 0.3f;  // radians
constexpr float kHingeAgreement = 0.9f;
constexpr int kHingeMinFrames = 10;

glm::vec3 measure_knee_hinge(const Database& db, int knee) {
  glm::vec3 sum(0.0f);
  int count = 0;
  const float min_sine = std::sin(0.5f * kHingeBend);
  for (int f = 0; f < db.frame_count(); ++f) {
    glm::quat q = db.local_rotation(f, knee);
    if (q.w < 0.0f) q = -q;
    const glm::vec3 axis(q.x, q.y, q.z);
    const float sine = glm::length(axis);  // of half the angle
    if (!(sine > min_sine)) continue;
    sum += axis / sine;
    ++count;
  }
  if (count < kHingeMinFrames) return glm::vec3(0.0f);
  const glm::vec3 mean = sum / static_cast<float>(count);
  return glm::length(mean) >= kHingeAgreement ? glm::normalize(mean) : glm::vec3(0.0f);
}

}  // namespace

Result<std::shared_ptr<const ControllerDatabase>> ControllerDatabase::create(
    std::shared_ptr<const Database> database, const ControllerDatabaseOptions& options) {
  if (!database) return Error{"controller database: no database given"};
  const Database& db = *database;
  if (Status s = db.validate(); !s) return Error{"controller database: " + s.message()};
  if (db.roles().hips < 0 || db.roles().left_foot < 0 || db.roles().right_foot < 0) {
    return Error{"controller database: the database has no hips or feet joint roles"};
  }
  bool has_trajectory = false;
  for (const FeatureChannel& c : db.schema().channels) {
    has_trajectory |=
        c.kind == FeatureKind::TrajectoryPosition || c.kind == FeatureKind::TrajectoryDirection;
  }
  if (!has_trajectory) {
    return Error{
        "controller database: the feature schema has no trajectory channel, so the stick "
        "could not steer the search"};
  }
  if (!std::isfinite(options.clip_end_exclusion) || options.clip_end_exclusion < 0.0f) {
    return Error{"controller database: clip_end_exclusion must be >= 0 seconds"};
  }
  if (!std::isfinite(options.idle_clip_end_exclusion) || options.idle_clip_end_exclusion < 0.0f) {
    return Error{"controller database: idle_clip_end_exclusion must be >= 0 seconds"};
  }

  std::shared_ptr<ControllerDatabase> out(new ControllerDatabase());
  out->database_ = std::move(database);
  out->options_ = options;
  out->action_tags_ = tag_bit(db, "action");
  out->idle_tags_ = tag_bit(db, kIdleTag);
  out->resolve_style_tags();

  const int excluded =
      clamped_integer<int>(std::round(options.clip_end_exclusion / db.frame_time()));
  const int idle_excluded =
      clamped_integer<int>(std::round(options.idle_clip_end_exclusion / db.frame_time()));
  out->candidates_.assign(db.searchable().begin(), db.searchable().end());
  for (const ClipRange& clip : db.clips()) {
    // The synthesized idle clip is one held pose: its end is as good as its start. Idle clips
    // of the data end like any take: jumping to their last frames would hold the last pose.
    if (is_idle_clip(db, clip)) continue;
    int end_frames = excluded;
    if ((clip.tags & out->idle_tags_) != 0) {
      end_frames = std::max(excluded, std::min(idle_excluded, (clip.end - clip.start) / 2));
    }
    for (int f = std::max(clip.start, clip.end - end_frames); f < clip.end; ++f) {
      out->candidates_[static_cast<size_t>(f)] = 0;
    }
  }
  if (std::find(out->candidates_.begin(), out->candidates_.end(), uint8_t{1}) ==
      out->candidates_.end()) {
    return Error{
        "controller database: no frame can be matched (every clip is shorter than the feature "
        "times and the clip-end exclusion need)"};
  }
  out->speeds_ = measure_speeds(db, out->action_tags_ | out->idle_tags_);
  // The same end joint per leg as the controller's foot IK (Controller::resolve_joints).
  const int feet[2] = {db.roles().left_foot, db.roles().right_foot};
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  out->landings_.resize(2 * static_cast<size_t>(db.frame_count()));
  for (int side = 0; side < 2; ++side) {
    const bool toe = toes[side] >= 0 && db.skeleton().parent(toes[side]) == feet[side];
    const int end = toe ? toes[side] : feet[side];
    out->lowest_foot_end_[side] = lowest_height(db, end);
    find_landings(db, side, end, out->landings_);
    const int knee = db.skeleton().parent(feet[side]);
    if (knee > 0) out->knee_hinge_[side] = measure_knee_hinge(db, knee);
  }
  return std::shared_ptr<const ControllerDatabase>(std::move(out));
}

uint64_t ControllerDatabase::tag_bits(std::string_view tag) const {
  if (tag.empty()) return 0;
  uint64_t bits = 0;
  const std::span<const std::string> names = database_->tag_names();
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& name = names[i];
    const bool word = name.size() > tag.size() && name.compare(0, tag.size(), tag) == 0 &&
                      name[tag.size()] == '-';
    if (name == tag || word) bits |= uint64_t{1} << i;
  }
  return bits;
}

Result<const Searcher*> ControllerDatabase::searcher(std::string_view method) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const SearcherEntry& e : searchers_) {
    if (e.method == method) return static_cast<const Searcher*>(e.searcher.get());
  }
  DatabaseSearchInput views(*database_);
  views.input.searchable = candidates_;
  Result<std::unique_ptr<Searcher>> made = make_searcher(method, views.input, options_.search);
  if (!made) return Error{made.message()};
  searchers_.push_back({std::string(method), std::move(made).value()});
  return static_cast<const Searcher*>(searchers_.back().searcher.get());
}

}  // namespace mm
