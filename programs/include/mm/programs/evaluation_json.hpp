#pragma once
// The JSON of one `mm eval` run: every metric under its key (evaluation.hpp defines them), and
// the run's settings. `mm eval --json` writes it and the Python module's mm.evaluate returns
// it, so both give the same keys and values.

#include <string>

#include <nlohmann/json.hpp>

#include "mm/programs/evaluation.hpp"

namespace mm {

// The metrics alone, one key each.
nlohmann::json evaluation_metrics_json(const EvaluationMetrics& metrics);

// The metrics plus the run's "script" (the path as given), "dt", "ik" and "start" ([x, z]).
nlohmann::json evaluation_run_json(const EvaluationMetrics& metrics, const std::string& script,
                                   const EvaluationOptions& options);

}  // namespace mm
