#include "mm/programs/shared_options.hpp"

#include <vector>

#include "mm/controller/script.hpp"
#include "mm/database/database_file.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/programs/number_parsing.hpp"

namespace mm::cli {

void add_set_option(CLI::App& app, ControllerSettings& settings) {
  app.add_option_function<std::vector<std::string>>(
         "--set",
         [&settings](const std::vector<std::string>& assignments) {
           for (const std::string& text : assignments) {
             const auto [name, value] = *split_assignment(text);
             const Status s = set_controller_setting(settings, name, value);
             if (!s) throw CLI::ValidationError("--set", s.message());
           }
         },
         "any controller setting by its name (e.g. inertialization_halflife=0.1, "
         "sync_mode=none, search_method=kdtree); repeatable")
      ->check(assignment("NAME=VALUE"))
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false);
}

void add_ik_option(CLI::App& app, ControllerSettings& settings) {
  app.add_option_function<std::string>(
         "--ik", [&settings](const std::string& value) { settings.ik_enabled = value == "on"; },
         "foot locking with IK (default on)")
      ->check(CLI::IsMember({"on", "off"}))
      ->type_name("");
}

void add_dt_option(CLI::App& app, float& dt, const std::string& default_text) {
  // The bounds of every scripted run (script.hpp), so that a run is refused before it starts.
  app.add_option("--dt", dt, "seconds per update (" + default_text + ")")
      ->check(number_in(kMinRunDt, kMaxRunDt))
      ->type_name("SECONDS");
}

void add_weights_option(CLI::App& app, WeightMethod& method, const std::string& description) {
  std::vector<std::string> names;
  for (WeightMethod m : {WeightMethod::Distance, WeightMethod::Envelope,
                         WeightMethod::HeatDiffusion, WeightMethod::Geodesic}) {
    names.emplace_back(weight_method_name(m));
  }
  app.add_option_function<std::string>(
         "--weights", [&method](const std::string& name) { method = *parse_weight_method(name); },
         description)
      ->check(CLI::IsMember(names))
      ->type_name("METHOD");
}

void add_bvh_scale_option(CLI::App& app, float& scale) {
  scale = 0.0f;  // automatic unless given
  app.add_option("--scale", scale,
                 "BVH units to metres (default: from each skeleton's size: metres, inches, "
                 "centimetres or millimetres)")
      ->check(number_over(0.0, 1000.0))
      ->type_name("S");
}

int check_settings(const CLI::App& app, const ControllerSettings& settings) {
  if (Status s = settings.validate(); !s) return usage_error(app, s.message());
  return -1;
}

Result<std::shared_ptr<const ControllerDatabase>> load_controller_database(
    const std::string& path) {
  Result<Database> loaded = load_database(path);
  if (!loaded) return Error{loaded.message()};
  return ControllerDatabase::create(std::make_shared<const Database>(std::move(loaded).value()));
}

}  // namespace mm::cli
