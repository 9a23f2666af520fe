// Settings by name, for command lines (mm eval --set) and live tuning panels, and their
// validation: both read one table of the fields.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "mm/controller/controller.hpp"

namespace mm {

namespace {

// Every float setting once: its name, where it lives and the range validate() accepts.
struct FloatField {
  const char* name;
  float ControllerSettings::*member;
  float min;
  float max;
};

constexpr FloatField kFloatFields[] = {
    {"walk_speed_forward", &ControllerSettings::walk_speed_forward, 0.0f, 20.0f},
    {"walk_speed_sideways", &ControllerSettings::walk_speed_sideways, 0.0f, 20.0f},
    {"walk_speed_backward", &ControllerSettings::walk_speed_backward, 0.0f, 20.0f},
    {"run_speed_forward", &ControllerSettings::run_speed_forward, 0.0f, 20.0f},
    {"run_speed_sideways", &ControllerSettings::run_speed_sideways, 0.0f, 20.0f},
    {"run_speed_backward", &ControllerSettings::run_speed_backward, 0.0f, 20.0f},
    {"stick_deadzone", &ControllerSettings::stick_deadzone, 0.0f, 0.9f},
    {"stop_speed", &ControllerSettings::stop_speed, 0.0f, 20.0f},
    {"simulation_velocity_halflife", &ControllerSettings::simulation_velocity_halflife, 0.0f,
     10.0f},
    {"simulation_rotation_halflife", &ControllerSettings::simulation_rotation_halflife, 0.0f,
     10.0f},
    {"simulation_max_turn_rate", &ControllerSettings::simulation_max_turn_rate, 0.1f, 100.0f},
    {"body_max_turn_rate", &ControllerSettings::body_max_turn_rate, 0.0f, 100.0f},
    {"search_interval", &ControllerSettings::search_interval, 0.0f, 10.0f},
    {"transition_cost", &ControllerSettings::transition_cost, 0.0f, 1e6f},
    {"style_cost", &ControllerSettings::style_cost, 0.0f, 1e6f},
    {"style_fallback_step", &ControllerSettings::style_fallback_step, 0.0f, 1e6f},
    {"ignore_window", &ControllerSettings::ignore_window, 0.0f, 10.0f},
    {"idle_ignore_window", &ControllerSettings::idle_ignore_window, 0.0f, 60.0f},
    {"replan_velocity_change", &ControllerSettings::replan_velocity_change, 0.0f, 100.0f},
    {"replan_facing_change", &ControllerSettings::replan_facing_change, 0.0f, 10.0f},
    {"clip_end_lookahead", &ControllerSettings::clip_end_lookahead, 0.0f, 10.0f},
    {"transition_cooldown", &ControllerSettings::transition_cooldown, 0.0f, 10.0f},
    {"inertialization_halflife", &ControllerSettings::inertialization_halflife, 0.0f, 10.0f},
    {"dead_blend_time", &ControllerSettings::dead_blend_time, 0.0f, 10.0f},
    {"dead_blend_decay_halflife", &ControllerSettings::dead_blend_decay_halflife, 0.0f, 10.0f},
    {"adjustment_halflife", &ControllerSettings::adjustment_halflife, 0.0f, 10.0f},
    {"simulation_yield_halflife", &ControllerSettings::simulation_yield_halflife, 0.0f, 100.0f},
    {"simulation_yield_max_velocity_ratio",
     &ControllerSettings::simulation_yield_max_velocity_ratio, 0.0f, 1000.0f},
    {"simulation_yield_standing_speed", &ControllerSettings::simulation_yield_standing_speed, 0.0f,
     100.0f},
    {"adjustment_max_velocity_ratio", &ControllerSettings::adjustment_max_velocity_ratio, 0.0f,
     100.0f},
    {"adjustment_max_angular_velocity_ratio",
     &ControllerSettings::adjustment_max_angular_velocity_ratio, 0.0f, 100.0f},
    {"clamp_max_distance", &ControllerSettings::clamp_max_distance, 0.0f, 1e3f},
    {"clamp_max_angle", &ControllerSettings::clamp_max_angle, 0.0f, 4.0f},
    {"strafe_warp_max", &ControllerSettings::strafe_warp_max, 0.0f, 3.2f},
    {"stand_turn_max_rate", &ControllerSettings::stand_turn_max_rate, 0.1f, 100.0f},
    {"stand_turn_acceleration", &ControllerSettings::stand_turn_acceleration, 0.1f, 1000.0f},
    {"foot_unlock_radius", &ControllerSettings::foot_unlock_radius, 0.0f, 10.0f},
    {"foot_lock_release_halflife", &ControllerSettings::foot_lock_release_halflife, 0.0f, 10.0f},
    {"character_radius", &ControllerSettings::character_radius, 0.01f, 10.0f},
    {"character_height", &ControllerSettings::character_height, 0.02f, 20.0f},
    {"step_height", &ControllerSettings::step_height, 0.0f, 10.0f},
    {"max_step_down", &ControllerSettings::max_step_down, 0.0f, 100.0f},
    {"max_slope", &ControllerSettings::max_slope, 0.0f, 1.5f},
    {"ground_height_halflife", &ControllerSettings::ground_height_halflife, 0.0f, 10.0f},
    {"max_pelvis_drop", &ControllerSettings::max_pelvis_drop, 0.0f, 2.0f},
    {"max_climb_speed", &ControllerSettings::max_climb_speed, 0.0f, 100.0f},
    {"min_playback_rate", &ControllerSettings::min_playback_rate, 0.1f, 1.0f},
    {"obstacle_deceleration", &ControllerSettings::obstacle_deceleration, 0.0f, 100.0f},
    {"pelvis_drop_halflife", &ControllerSettings::pelvis_drop_halflife, 0.0f, 10.0f},
    {"max_foot_tilt", &ControllerSettings::max_foot_tilt, 0.0f, 1.5f},
    {"max_dt", &ControllerSettings::max_dt, 1e-4f, 10.0f},
};

struct FlagField {
  const char* name;
  bool ControllerSettings::*member;
};

constexpr FlagField kFlagFields[] = {
    {"ik_enabled", &ControllerSettings::ik_enabled},
    {"foot_lock_enabled", &ControllerSettings::foot_lock_enabled},
    {"compute_skinning", &ControllerSettings::compute_skinning},
    {"cubic_playback", &ControllerSettings::cubic_playback},
};

// Every enum setting once: its name, its value as an integer (any integer of the underlying type
// can be stored, from a cast or a struct filled by other code) and the names of its valid values,
// by value from 0.
// The names of InterpolationMethod's values, by value.
constexpr std::string_view kInterpolationNames[] = {"nlerp", "slerp", "sclerp"};
// By TransitionMode's values.
constexpr std::string_view kTransitionModeNames[] = {"dead-blending", "inertialization"};

// "a, b, c".
std::string joined(std::span<const std::string_view> names) {
  std::string list;
  for (std::string_view n : names) list.append(list.empty() ? "" : ", ").append(n);
  return list;
}

struct EnumField {
  const char* name;
  int value;
  std::vector<std::string_view> names;
};

std::vector<EnumField> enum_fields(const ControllerSettings& s) {
  return {
      {"interpolation",
       static_cast<int>(s.interpolation),
       {std::begin(kInterpolationNames), std::end(kInterpolationNames)}},
      {"transition_mode",
       static_cast<int>(s.transition_mode),
       {std::begin(kTransitionModeNames), std::end(kTransitionModeNames)}},
      {"sync_mode",
       static_cast<int>(s.sync_mode),
       {sync_mode_name(SyncMode::CharacterFollowsSimulation),
        sync_mode_name(SyncMode::SimulationFollowsCharacter), sync_mode_name(SyncMode::None)}},
  };
}

Error bad_value(std::string_view name, std::string_view value, const char* expected) {
  return Error{"setting '" + std::string(name) + "': expected " + expected + ", found '" +
               std::string(value) + "'"};
}

// An enum field from its name, the names listed in the enum's order.
template <typename Enum, size_t N>
Status parse_named(std::string_view name, std::string_view value,
                   const std::string_view (&names)[N], const char* expected, Enum& out) {
  const auto* found = std::find(std::begin(names), std::end(names), value);
  if (found == std::end(names)) return bad_value(name, value, expected);
  out = static_cast<Enum>(found - std::begin(names));
  return Status::success();
}

}  // namespace

Status ControllerSettings::validate() const {
  for (const FloatField& f : kFloatFields) {
    const float value = this->*f.member;
    if (!std::isfinite(value) || value < f.min || value > f.max) {
      return Error{std::string("controller settings: ") + f.name + " must be a number in [" +
                   std::to_string(f.min) + ", " + std::to_string(f.max) + "], found " +
                   std::to_string(value)};
    }
  }
  for (const EnumField& f : enum_fields(*this)) {
    if (f.value < 0 || static_cast<size_t>(f.value) >= f.names.size()) {
      return Error{std::string("controller settings: ") + f.name + " must be one of " +
                   joined(f.names) + " (0 to " + std::to_string(f.names.size() - 1) + "), found " +
                   std::to_string(f.value)};
    }
  }
  if (character_height < 2.0f * character_radius) {
    return Error{
        "controller settings: character_height must be at least twice character_radius "
        "(a capsule), found " +
        std::to_string(character_height) + " and " + std::to_string(character_radius)};
  }
  if (bone_length_iterations < 0 || bone_length_iterations > 100) {
    return Error{"controller settings: bone_length_iterations must be in [0, 100], found " +
                 std::to_string(bone_length_iterations)};
  }
  const auto names = search_method_names();
  if (std::find(names.begin(), names.end(), search_method) == names.end()) {
    return Error{"controller settings: unknown search method '" + search_method + "' (one of " +
                 joined(names) + ")"};
  }
  return Status::success();
}

Status set_controller_setting(ControllerSettings& settings, std::string_view name,
                              std::string_view value) {
  for (const FloatField& f : kFloatFields) {
    if (name != f.name) continue;
    float x = 0.0f;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), x);
    if (ec != std::errc() || end != value.data() + value.size()) {
      return bad_value(name, value, "a number");
    }
    settings.*f.member = x;
    return Status::success();
  }
  for (const FlagField& f : kFlagFields) {
    if (name != f.name) continue;
    if (value == "on" || value == "true" || value == "1") {
      settings.*f.member = true;
    } else if (value == "off" || value == "false" || value == "0") {
      settings.*f.member = false;
    } else {
      return bad_value(name, value, "on or off");
    }
    return Status::success();
  }
  if (name == "bone_length_iterations") {
    int n = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
    if (ec != std::errc() || end != value.data() + value.size()) {
      return bad_value(name, value, "a whole number");
    }
    settings.bone_length_iterations = n;
    return Status::success();
  }
  if (name == "search_method") {
    settings.search_method = std::string(value);
    return Status::success();
  }
  if (name == "sync_mode") {
    if (!parse_sync_mode(value, settings.sync_mode)) {
      return bad_value(name, value, "character, simulation or none");
    }
    return Status::success();
  }
  if (name == "transition_mode") {
    return parse_named(name, value, kTransitionModeNames, "dead-blending or inertialization",
                       settings.transition_mode);
  }
  if (name == "interpolation") {
    return parse_named(name, value, kInterpolationNames, "nlerp, slerp or sclerp",
                       settings.interpolation);
  }
  return Error{"unknown setting '" + std::string(name) + "'"};
}

}  // namespace mm
