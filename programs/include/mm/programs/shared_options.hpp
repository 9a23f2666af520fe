#pragma once
// The options several commands share, declared once: the controller's (`mm eval`,
// `mm crowd-bench`, `mm-viewer`), the generated body's weights (`mm export`, `mm-viewer`) and
// the BVH scale (`mm build`, `mm export`); and loading a database for controllers.

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "mm/controller/controller.hpp"
#include "mm/offline/bone_weights.hpp"

namespace mm::cli {

// `--set NAME=VALUE`, repeatable: any controller setting by its field name, applied in order.
// No '=', an unknown name or an unreadable value is a usage error naming the option.
void add_set_option(CLI::App& app, ControllerSettings& settings);

// `--ik on|off`: foot locking with IK.
void add_ik_option(CLI::App& app, ControllerSettings& settings);

// `--dt SECONDS` in (0, 1]: seconds per update; `default_text` says what happens without it
// ("default 1/60").
void add_dt_option(CLI::App& app, float& dt, const std::string& default_text);

// `--weights METHOD`: the generated body's skinning weights, one of the method names.
void add_weights_option(CLI::App& app, WeightMethod& method, const std::string& description);

// `--scale S` in (0, 1000]: BVH units to metres; without it, 0 (units found per file).
void add_bvh_scale_option(CLI::App& app, float& scale);

// After parsing: the settings as a whole (ranges, a known search method); -1 when they are
// good, else the usage error's exit code (2) after printing the message.
int check_settings(const CLI::App& app, const ControllerSettings& settings);

// Loads the database file and makes the controllers' shared data; the message names the file.
Result<std::shared_ptr<const ControllerDatabase>> load_controller_database(const std::string& path);

}  // namespace mm::cli
