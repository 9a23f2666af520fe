// Settings by name, for command lines (mm eval --set) and live tuning panels.

#include <charconv>
#include <string>

#include "mm/controller/controller.hpp"

namespace mm {

namespace {

struct FloatField {
  const char* name;
  float ControllerSettings::*member;
};

constexpr FloatField kFloatFields[] = {
    {"walk_speed_forward", &ControllerSettings::walk_speed_forward},
    {"walk_speed_sideways", &ControllerSettings::walk_speed_sideways},
    {"walk_speed_backward", &ControllerSettings::walk_speed_backward},
    {"run_speed_forward", &ControllerSettings::run_speed_forward},
    {"run_speed_sideways", &ControllerSettings::run_speed_sideways},
    {"run_speed_backward", &ControllerSettings::run_speed_backward},
    {"stick_deadzone", &ControllerSettings::stick_deadzone},
    {"stop_speed", &ControllerSettings::stop_speed},
    {"simulation_velocity_halflife", &ControllerSettings::simulation_velocity_halflife},
    {"simulation_rotation_halflife", &ControllerSettings::simulation_rotation_halflife},
    {"search_interval", &ControllerSettings::search_interval},
    {"transition_cost", &ControllerSettings::transition_cost},
    {"ignore_window", &ControllerSettings::ignore_window},
    {"replan_velocity_change", &ControllerSettings::replan_velocity_change},
    {"replan_facing_change", &ControllerSettings::replan_facing_change},
    {"clip_end_lookahead", &ControllerSettings::clip_end_lookahead},
    {"transition_cooldown", &ControllerSettings::transition_cooldown},
    {"inertialization_halflife", &ControllerSettings::inertialization_halflife},
    {"adjustment_halflife", &ControllerSettings::adjustment_halflife},
    {"simulation_yield_halflife", &ControllerSettings::simulation_yield_halflife},
    {"adjustment_max_velocity_ratio", &ControllerSettings::adjustment_max_velocity_ratio},
    {"adjustment_max_angular_velocity_ratio",
     &ControllerSettings::adjustment_max_angular_velocity_ratio},
    {"clamp_max_distance", &ControllerSettings::clamp_max_distance},
    {"clamp_max_angle", &ControllerSettings::clamp_max_angle},
    {"foot_unlock_radius", &ControllerSettings::foot_unlock_radius},
    {"foot_lock_release_halflife", &ControllerSettings::foot_lock_release_halflife},
    {"max_dt", &ControllerSettings::max_dt},
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

Error bad_value(std::string_view name, std::string_view value, const char* expected) {
  return Error{"setting '" + std::string(name) + "': expected " + expected + ", found '" +
               std::string(value) + "'"};
}

}  // namespace

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
  if (name == "interpolation") {
    if (value == "nlerp") {
      settings.interpolation = InterpolationMethod::Nlerp;
    } else if (value == "slerp") {
      settings.interpolation = InterpolationMethod::Slerp;
    } else if (value == "sclerp") {
      settings.interpolation = InterpolationMethod::Sclerp;
    } else {
      return bad_value(name, value, "nlerp, slerp or sclerp");
    }
    return Status::success();
  }
  return Error{"unknown setting '" + std::string(name) + "'"};
}

}  // namespace mm
