// Helpers shared by the libFuzzer targets: turning fuzz bytes into the hostile values a driver
// must survive, and a failure macro that works in release builds.
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace ranger::fuzz {

// Aborts (libFuzzer records the input as a crash) when a property does not hold. Not assert():
// the fuzzers are built with NDEBUG.
#define FUZZ_CHECK(cond)                                                                 \
  do {                                                                                   \
    if (!(cond)) {                                                                       \
      std::fprintf(stderr, "%s:%d: property violated: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                      \
    }                                                                                    \
  } while (0)

// A double from the input: usually a raw bit pattern (any NaN payload, infinity, denormal, huge
// or tiny value), sometimes one of the values that tend to break saturation and rounding.
inline double consume_double(FuzzedDataProvider& in) {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static const double kSpecial[] = {0.0,
                                    -0.0,
                                    std::numeric_limits<double>::quiet_NaN(),
                                    kInf,
                                    -kInf,
                                    1e9,
                                    -1e9,
                                    1e300,
                                    -1e300,
                                    std::numeric_limits<double>::max(),
                                    std::numeric_limits<double>::lowest(),
                                    std::numeric_limits<double>::min(),
                                    std::numeric_limits<double>::denorm_min(),
                                    2.6,
                                    -2.6,
                                    2.6000000001,
                                    32.767,
                                    32.768,
                                    -32.769,
                                    1.0,
                                    -1.0,
                                    0.0004999,
                                    0.0005,
                                    M_PI / 2,
                                    -M_PI / 2,
                                    M_PI,
                                    1e-9,
                                    65.535,
                                    327.67,
                                    327.68};
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return kSpecial[in.ConsumeIntegralInRange<std::size_t>(
          0, sizeof(kSpecial) / sizeof(kSpecial[0]) - 1)];
    case 1:  // a "reasonable" value: where most of the logic's branches are
      return in.ConsumeFloatingPointInRange<double>(-5.0, 5.0);
    default: {
      const auto bits = in.ConsumeIntegral<std::uint64_t>();
      double d;
      std::memcpy(&d, &bits, sizeof d);
      return d;
    }
  }
}

// The sign of x as -1, 0 or +1 (0 for NaN).
inline int sign_of(double x) {
  return (x > 0) - (x < 0);
}

}  // namespace ranger::fuzz
