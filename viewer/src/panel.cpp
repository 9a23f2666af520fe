#include "panel.hpp"

#include <imgui.h>

#include <string>

namespace mm::viewer {
namespace {

void show_status(const Status& status, const char* success, PanelState& state) {
  state.message = status ? success : status.message();
}

void timings(const Scene& scene, const PanelState& state) {
  const FrameTimes& t = scene.times();
  if (t.frame > 0.0f) {
    ImGui::Text("%.0f fps   update %.1f us   search %.1f us", 1.0f / t.frame, t.update * 1e6f,
                t.search * 1e6f);
  } else {
    ImGui::Text("update %.1f us   search %.1f us", t.update * 1e6f, t.search * 1e6f);
  }
  ImGui::Text("input: %s", state.input_source.c_str());
  ImGui::Text("time %.2f s", scene.time());
}

void playback(const Scene& scene) {
  const ControllerDebug& d = scene.controller().debug();
  const Database& db = scene.database();
  if (d.clip < 0 || d.clip >= static_cast<int>(db.clips().size())) return;
  const ClipRange& clip = db.clips()[d.clip];
  ImGui::Text("clip %s", clip.name.c_str());
  ImGui::Text("frame %d (%.2f s into the clip, rate %.2f)", d.frame, d.clip_time, d.playback_rate);
  std::string tags;
  for (size_t t = 0; t < db.tag_names().size(); ++t) {
    if (clip.tags & (uint64_t{1} << t)) tags += (tags.empty() ? "" : ", ") + db.tag_names()[t];
  }
  ImGui::Text("tags: %s", tags.empty() ? "-" : tags.c_str());
  ImGui::Text("transitions %d   searches %d   %s", d.transitions, d.searches,
              d.standing ? "standing" : "moving");
}

void last_search(const Scene& scene) {
  const ControllerDebug& d = scene.controller().debug();
  const FeatureSchema& schema = scene.database().schema();
  ImGui::Text("cost %.3f (best frame %d)", d.last_cost, d.last_best_frame);
  float largest = 1e-6f;
  for (int c = 0; c < d.channel_count; ++c) largest = std::max(largest, d.last_channel_costs[c]);
  for (int c = 0; c < d.channel_count && c < static_cast<int>(schema.channels.size()); ++c) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3f", d.last_channel_costs[c]);
    ImGui::ProgressBar(d.last_channel_costs[c] / largest, ImVec2(120, 0), text);
    ImGui::SameLine();
    ImGui::TextUnformatted(schema.channels[c].name.c_str());
  }
}

void settings(Scene& scene, PanelState& state) {
  ControllerSettings s = scene.controller().settings();
  bool changed = false;
  changed |= ImGui::SliderFloat("velocity halflife", &s.simulation_velocity_halflife, 0.05f, 1.0f,
                                "%.2f s");
  changed |= ImGui::SliderFloat("rotation halflife", &s.simulation_rotation_halflife, 0.05f, 1.0f,
                                "%.2f s");
  changed |=
      ImGui::SliderFloat("inertialization", &s.inertialization_halflife, 0.02f, 0.5f, "%.2f s");
  changed |= ImGui::SliderFloat("adjustment", &s.adjustment_halflife, 0.02f, 0.5f, "%.2f s");
  changed |= ImGui::SliderFloat("search interval", &s.search_interval, 0.02f, 0.5f, "%.2f s");
  changed |= ImGui::SliderFloat("transition cost", &s.transition_cost, 0.0f, 5.0f, "%.2f");
  const auto methods = search_method_names();
  if (ImGui::BeginCombo("search method", s.search_method.c_str())) {
    for (std::string_view m : methods) {
      if (ImGui::Selectable(std::string(m).c_str(), m == s.search_method)) {
        s.search_method = std::string(m);
        changed = true;
      }
    }
    ImGui::EndCombo();
  }
  int sync = static_cast<int>(s.sync_mode);
  if (ImGui::Combo("sync", &sync, "character follows\0simulation follows\0none\0")) {
    s.sync_mode = static_cast<SyncMode>(sync);
    changed = true;
  }
  changed |= ImGui::Checkbox("IK and foot locking", &s.ik_enabled);
  if (changed) show_status(scene.apply_settings(s), "settings applied", state);
}

void feature_weights(Scene& scene, PanelState& state) {
  const FeatureSchema& schema = scene.database().schema();
  ImGui::TextWrapped(
      "A new weight rebuilds the normalized features and the search, and starts "
      "the character again where it stands.");
  for (int c = 0; c < static_cast<int>(schema.channels.size()); ++c) {
    float weight = schema.channels[c].weight;
    ImGui::SliderFloat(schema.channels[c].name.c_str(), &weight, 0.05f, 5.0f, "%.2f",
                       ImGuiSliderFlags_Logarithmic);
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      show_status(scene.set_channel_weight(c, weight), "features rebuilt", state);
      return;  // the schema was replaced
    }
  }
}

void body(Scene& scene, PanelState& state) {
  int skinning = state.skinning == SkinningMethod::LinearBlend ? 0 : 1;
  if (ImGui::RadioButton("linear blend", &skinning, 0))
    state.skinning = SkinningMethod::LinearBlend;
  ImGui::SameLine();
  if (ImGui::RadioButton("dual quaternion", &skinning, 1)) {
    state.skinning = SkinningMethod::DualQuaternion;
  }
  ImGui::Checkbox("body", &state.show_body);
  if (!scene.can_reweigh()) return;
  const WeightMethod methods[] = {WeightMethod::Distance, WeightMethod::Envelope,
                                  WeightMethod::HeatDiffusion, WeightMethod::Geodesic};
  const std::string current(weight_method_name(scene.weight_method()));
  if (ImGui::BeginCombo("weights", current.c_str())) {
    for (WeightMethod m : methods) {
      const std::string name(weight_method_name(m));
      if (ImGui::Selectable(name.c_str(), m == scene.weight_method())) {
        show_status(scene.set_weight_method(m), "weights recomputed", state);
      }
    }
    ImGui::EndCombo();
  }
}

void debug_toggles(Scene& scene) {
  DebugToggles& t = scene.toggles;
  ImGui::Checkbox("trajectories", &t.trajectory);
  ImGui::SameLine();
  ImGui::Checkbox("roots", &t.roots);
  ImGui::SameLine();
  ImGui::Checkbox("features", &t.features);
  ImGui::Checkbox("contacts and locks", &t.contacts);
  ImGui::SameLine();
  ImGui::Checkbox("skeleton", &t.skeleton);
}

void recording(Scene& scene, PanelState& state) {
  ImGui::Checkbox("pause", &state.paused);
  ImGui::SameLine();
  ImGui::SliderFloat("speed", &state.time_scale, 0.1f, 2.0f, "%.1fx");
  if (!state.recorder) return;
  InputRecorder& r = *state.recorder;
  if (!r.active()) {
    if (ImGui::Button("record input")) r.start(scene.time());
    return;
  }
  if (ImGui::Button("stop and save")) {
    r.stop();
    show_status(r.save(state.record_path), ("saved " + state.record_path).c_str(), state);
  }
  ImGui::SameLine();
  ImGui::Text("%d lines", r.line_count());
}

}  // namespace

void draw_panel(Scene& scene, PanelState& state) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(380, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("motion matching");
  timings(scene, state);
  // The style playing now as requested (a script's or the selector's), then the selector.
  const ControllerDatabase& db = scene.controller().controller_database();
  ImGui::Text(
      "style: %s",
      std::string(StyleSelector::name(db, scene.controller().debug().requested_style)).c_str());
  if (state.styles) state.styles->draw(db);
  playback(scene);
  if (ImGui::CollapsingHeader("last search", ImGuiTreeNodeFlags_DefaultOpen)) last_search(scene);
  if (ImGui::CollapsingHeader("settings")) settings(scene, state);
  if (ImGui::CollapsingHeader("feature weights")) feature_weights(scene, state);
  if (ImGui::CollapsingHeader("body", ImGuiTreeNodeFlags_DefaultOpen)) body(scene, state);
  if (ImGui::CollapsingHeader("debug drawing", ImGuiTreeNodeFlags_DefaultOpen))
    debug_toggles(scene);
  if (ImGui::CollapsingHeader("run", ImGuiTreeNodeFlags_DefaultOpen)) recording(scene, state);
  if (!state.message.empty()) ImGui::TextWrapped("%s", state.message.c_str());
  ImGui::End();
}

}  // namespace mm::viewer
