#pragma once
// The parallel loop of build-time work lives in the runtime (mm/runtime/workers.hpp), shared by
// the database builder and the search structures.
#include "mm/runtime/workers.hpp"
