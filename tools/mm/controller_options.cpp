#include "controller_options.hpp"

#include "mm/database/database_file.hpp"

namespace mm::cli {

Result<std::shared_ptr<const ControllerDatabase>> load_controller_database(
    const std::string& path) {
  Result<Database> loaded = load_database(path);
  if (!loaded) return Error{loaded.message()};
  return ControllerDatabase::create(std::make_shared<const Database>(std::move(loaded).value()));
}

Status apply_set_option(const std::string* argument, ControllerSettings& settings) {
  const size_t equals = argument ? argument->find('=') : std::string::npos;
  if (equals == std::string::npos) return Error{"--set needs NAME=VALUE"};
  return set_controller_setting(settings, argument->substr(0, equals),
                                argument->substr(equals + 1));
}

}  // namespace mm::cli
