#pragma once
// Cold-path error handling: import, build and load return a Result carrying either a value or
// a message a user can act on. Hot paths (update, search) never return errors; they assert.

#include <string>
#include <utility>
#include <variant>
#include "mm/runtime/assert.hpp"

namespace mm {

// A human-readable failure: what went wrong and where (file, line, field).
struct Error {
  std::string message;
};

// Either a T or an Error. Test with ok() or operator bool before calling value().
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value)
      : state_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  Result(Error error) : state_(std::in_place_index<1>, std::move(error)) {}  // NOLINT

  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    MM_ASSERT(ok());
    return std::get<0>(state_);
  }
  const T& value() const& {
    MM_ASSERT(ok());
    return std::get<0>(state_);
  }
  T&& value() && {
    MM_ASSERT(ok());
    return std::get<0>(std::move(state_));
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }

  const Error& error() const {
    MM_ASSERT(!ok());
    return std::get<1>(state_);
  }
  const std::string& message() const { return error().message; }

 private:
  std::variant<T, Error> state_;
};

// Success or an Error, for operations with no value to return.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error.message)), failed_(true) {}  // NOLINT
  static Status success() { return {}; }

  bool ok() const { return !failed_; }
  explicit operator bool() const { return ok(); }
  const std::string& message() const { return error_; }

 private:
  std::string error_;
  bool failed_ = false;
};

}  // namespace mm
