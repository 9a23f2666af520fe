#pragma once
// What `mm eval` and `mm crowd-bench` share: loading a database for controllers, and the
// `--set NAME=VALUE` option.

#include <memory>
#include <string>

#include "mm/controller/controller.hpp"

namespace mm::cli {

// Loads the database file and makes the controllers' shared data; the message names the file.
Result<std::shared_ptr<const ControllerDatabase>> load_controller_database(const std::string& path);

// Applies one `--set NAME=VALUE` argument to `settings`; fails with a message for the usage
// error (no '=', an unknown name, an unreadable value).
Status apply_set_option(const std::string* argument, ControllerSettings& settings);

}  // namespace mm::cli
