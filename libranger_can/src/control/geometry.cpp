#include "ranger_can/control/geometry.hpp"

#include <cmath>
#include <string>

namespace ranger {

double VehicleGeometry::wheel_radius_from_centre() const {
  return std::hypot(wheelbase / 2.0, track / 2.0);
}

Status VehicleGeometry::validate() const {
  const struct {
    const char* name;
    double value;
  } fields[] = {{"wheelbase", wheelbase}, {"track", track}, {"wheel_radius", wheel_radius}};
  for (const auto& f : fields) {
    if (!std::isfinite(f.value) || f.value <= 0.0 || f.value > 10.0) {
      return Error{Errc::kOutOfRange, std::string("geometry: ") + f.name + " = " +
                                          std::to_string(f.value) +
                                          " is not in the valid range (0, 10] m"};
    }
  }
  return ok_status();
}

}  // namespace ranger
