// The JSON of one `mm eval` run (evaluation_json.hpp).

#include "mm/programs/evaluation_json.hpp"

namespace mm {

nlohmann::json evaluation_metrics_json(const EvaluationMetrics& m) {
  return {{"foot_skate_cm_s_mean", m.foot_skate_cm_s_mean},
          {"foot_skate_cm_s_p95", m.foot_skate_cm_s_p95},
          {"root_sim_distance_cm_mean", m.root_sim_distance_cm_mean},
          {"root_sim_distance_cm_max", m.root_sim_distance_cm_max},
          {"facing_error_deg_mean", m.facing_error_deg_mean},
          {"speed_response_s", m.speed_response_s},
          {"speed_events", m.speed_events},
          {"speed_events_reached", m.speed_events_reached},
          {"heading_response_s", m.heading_response_s},
          {"heading_events", m.heading_events},
          {"heading_events_reached", m.heading_events_reached},
          {"stand_root_speed_cm_s_mean", m.stand_root_speed_cm_s_mean},
          {"stand_foot_speed_cm_s_mean", m.stand_foot_speed_cm_s_mean},
          {"stand_frames", m.stand_frames},
          {"transitions_per_s", m.transitions_per_s},
          {"style_match", m.style_match},
          {"style_frames", m.style_frames},
          {"style_response_s", m.style_response_s},
          {"style_response_s_max", m.style_response_s_max},
          {"style_requests", m.style_requests},
          {"style_requests_reached", m.style_requests_reached},
          {"transition_accel_ratio", m.transition_accel_ratio},
          {"transition_accel_p99_m_s2", m.transition_accel_p99},
          {"database_accel_p99_m_s2", m.database_accel_p99},
          {"transition_accel_ratio_same_sampling", m.transition_accel_ratio_same_sampling},
          {"database_accel_p99_same_sampling_m_s2", m.database_accel_p99_same_sampling},
          {"transition_accel_ratio_played", m.transition_accel_ratio_played},
          {"played_accel_p99_m_s2", m.played_accel_p99},
          {"leg_accel_ratio", m.leg_accel_ratio},
          {"leg_accel_max_m_s2", m.leg_accel_max},
          {"leg_accel_max_t", m.leg_accel_max_t},
          {"leg_accel_played_max_m_s2", m.leg_accel_played_max},
          {"search_us_mean", m.search_us_mean},
          {"update_us_mean", m.update_us_mean},
          {"body_turn_rate_deg_s_p99", m.body_turn_rate_deg_s_p99},
          {"body_turn_rate_deg_s_max", m.body_turn_rate_deg_s_max},
          {"foot_pivot_deg_s_mean", m.foot_pivot_deg_s_mean},
          {"foot_pivot_frames", m.foot_pivot_frames},
          {"stand_turns", m.stand_turns},
          {"stand_turn_unsettled", m.stand_turn_unsettled},
          {"stand_turn_interrupted", m.stand_turn_interrupted},
          {"stand_turn_final_error_deg_max", m.stand_turn_final_error_deg_max},
          {"stand_turn_response_s", m.stand_turn_response_s},
          {"stand_turn_final_error_deg_mean", m.stand_turn_final_error_deg_mean},
          {"stand_turn_peak_rate_deg_s_max", m.stand_turn_peak_rate_deg_s_max},
          {"strafe_chest_error_deg_mean", m.strafe_chest_error_deg_mean},
          {"strafe_chest_frames", m.strafe_chest_frames},
          {"idle_head_speed_cm_s_mean", m.idle_head_speed_cm_s_mean},
          {"idle_head_frames", m.idle_head_frames},
          {"toe_height_min_cm", m.toe_height_min_cm},
          {"foot_skate_geom_cm_s_mean", m.ground.foot_skate_geom_cm_s_mean},
          {"foot_skate_geom_frames", m.ground.foot_skate_geom_frames},
          {"foot_skate_geom_data_cm_s_mean", m.foot_skate_geom_data_cm_s_mean},
          {"toe_clearance_cm_min", m.ground.toe_clearance_cm_min},
          {"toe_clearance_cm_p1", m.ground.toe_clearance_cm_p1},
          {"foot_penetration_cm_mean", m.ground.foot_penetration_cm_mean},
          {"foot_penetration_cm_max", m.ground.foot_penetration_cm_max},
          {"foot_float_cm_mean", m.ground.foot_float_cm_mean},
          {"foot_float_data_cm_mean", m.ground.foot_float_data_cm_mean},
          {"hips_height_cm_mean", m.ground.hips_height_cm_mean},
          {"hips_height_cm_std", m.ground.hips_height_cm_std},
          {"hips_vertical_accel_p99_m_s2", m.ground.hips_vertical_accel_p99_m_s2},
          {"knee_overextension_frames", m.ground.knee_overextension_frames},
          {"wall_depth_cm_max", m.ground.wall_depth_cm_max},
          {"stuck_s", m.ground.stuck_s},
          {"frames", m.frames},
          {"seconds", m.seconds}};
}

nlohmann::json evaluation_run_json(const EvaluationMetrics& metrics, const std::string& script,
                                   const EvaluationOptions& options) {
  nlohmann::json json = evaluation_metrics_json(metrics);
  json["script"] = script;
  json["dt"] = options.dt;
  json["ik"] = options.settings.ik_enabled;
  json["start"] = {options.start.x, options.start.y};
  return json;
}

}  // namespace mm
