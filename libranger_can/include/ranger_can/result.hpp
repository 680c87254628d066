// Errors as values. The library does not throw across its API: a driver loop for a moving
// vehicle must be able to log a bad frame and carry on, so every fallible call returns either
// its value or an Error whose message names the problem (the ID, the field, the interface).
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace ranger {

enum class Errc {
  kUnknownId,        // frame ID not part of the RANGER protocol
  kBadDlc,           // frame shorter than its ID's layout (a longer one is read), or a DLC above 8
  kOutOfRange,       // a value outside what the protocol can express (after saturation rules), or
                     // content no model can send (a steering angle beyond 100 deg)
  kNotFinite,        // NaN or infinity where a number was required
  kInvalidArgument,  // any other bad input (unknown enum value, empty name, ...)
  kParseError,       // malformed text input (candump line, CLI argument)
  kIoError,          // an OS call failed; message carries errno's text
  kNoSuchInterface,  // network interface does not exist
  kNotCanInterface,  // interface exists but is not CAN
  kInterfaceDown,    // interface exists but is down or vanished
  kWouldBlock,       // the transmit queue is full; the frame was dropped, not queued
  kTimeout,          // nothing arrived in time
  kPermissionDenied,
};

struct Error {
  Errc code;
  std::string message;
};

// A minimal `expected`: holds either a T or an Error. C++17 has no std::expected.
template <typename T>
class Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

// For calls that produce nothing but may fail.
struct Ok {};
using Status = Result<Ok>;
inline Status ok_status() {
  return Ok{};
}

}  // namespace ranger
