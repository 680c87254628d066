// ranger_can._ranger_can: the pybind11 mapping of libranger_can. Nothing here decides anything:
// each function calls the library (or the ranger_can tool's sub-commands, for candump decoding
// and odometry replay) and converts values; the Python package (ranger_can/__init__.py) adds the
// context manager, the clean-up at interpreter exit and the exception classes.
//
// Errors: every ranger::Error becomes ranger_can.RangerError carrying the library's message and
// its code name. Waiting (wait_snapshot, wait_for, wait_sent, the tool's commands) releases the
// GIL; nothing Python ever runs on the driver's thread.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/diagnostics.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/control/rearm.hpp"
#include "ranger_can/control/vocabulary.hpp"
#include "ranger_can/frontend/answers.hpp"
#include "ranger_can/frontend/cmd_vel_type.hpp"
#include "ranger_can/frontend/publication.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

#include "cli_commands.hpp"
#include "options.hpp"
#include "ros2_wire.hpp"
#include "session.hpp"
#include "views.hpp"

namespace py = pybind11;

namespace ranger::python {
namespace {

// A library error on its way to Python (translated into ranger_can.RangerError).
struct LibraryError {
  Error error;
};

std::string_view code_name(Errc c) {
  switch (c) {
    case Errc::kUnknownId:
      return "unknown_id";
    case Errc::kBadDlc:
      return "bad_dlc";
    case Errc::kOutOfRange:
      return "out_of_range";
    case Errc::kNotFinite:
      return "not_finite";
    case Errc::kInvalidArgument:
      return "invalid_argument";
    case Errc::kParseError:
      return "parse_error";
    case Errc::kIoError:
      return "io_error";
    case Errc::kNoSuchInterface:
      return "no_such_interface";
    case Errc::kNotCanInterface:
      return "not_can_interface";
    case Errc::kInterfaceDown:
      return "interface_down";
    case Errc::kWouldBlock:
      return "would_block";
    case Errc::kTimeout:
      return "timeout";
    case Errc::kPermissionDenied:
      return "permission_denied";
  }
  return "error";
}

template <typename T>
T value_or_throw(Result<T> r) {
  if (!r) throw LibraryError{r.error()};
  return std::move(*r);
}

void check(const Status& st) {
  if (!st) throw LibraryError{st.error()};
}

[[noreturn]] void invalid(std::string message) {
  throw LibraryError{Error{Errc::kInvalidArgument, std::move(message)}};
}

std::chrono::nanoseconds to_ns(double s) {
  if (!(s >= 0.0)) return std::chrono::nanoseconds(0);
  return from_seconds(std::min(s, 1e6));
}

// time.monotonic() seconds <-> the steady clock (both CLOCK_MONOTONIC).
SteadyTime steady_time(double s) {
  return SteadyTime(std::chrono::duration_cast<SteadyDuration>(std::chrono::duration<double>(s)));
}
double seconds_of(SteadyTime t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}

TypeSpelling parse_spelling(const std::string& text) {
  if (auto s = kTypeSpellingNames.parse(text)) return *s;
  invalid("type spelling \"" + text + "\" unknown: one of " +
          text::join(kTypeSpellingNames.names()));
}

// A decision of the cmd_vel type rule, with the spelling of its rule for the type's name.
struct CmdVelDecision {
  CmdVelTypeDecision decision;
  TypeSpelling spelling;
};

protocol::MotionMode parse_mode(const std::string& text) {
  if (auto m = protocol::kMotionModeNames.parse(text)) return *m;
  invalid("motion mode \"" + text + "\" unknown: one of " +
          text::join(protocol::kMotionModeNames.names()));
}

protocol::LightMode parse_light(const std::string& text) {
  if (auto m = protocol::kLightModeNames.parse(text)) return *m;
  invalid("light mode \"" + text + "\" unknown: one of " +
          text::join(protocol::kLightModeNames.names()));
}

template <typename T>
std::optional<std::string> name_of(const std::optional<T>& v) {
  if (!v) return std::nullopt;
  return std::string(protocol::to_string(*v));
}

// A Python parameter value (bool, int, float, str, a list of them; a dict) as the library reads
// parameters (ranger::ParameterValue); anything else is named in the error.
ParameterValue to_value(const std::string& name, const py::handle& h) {
  if (py::isinstance<py::bool_>(h)) return h.cast<bool>();
  if (py::isinstance<py::int_>(h)) return ParameterValue(h.cast<long long>());
  if (py::isinstance<py::float_>(h)) return h.cast<double>();
  if (py::isinstance<py::str>(h)) return h.cast<std::string>();
  if (py::isinstance<py::dict>(h)) return ParameterValue::dictionary();
  if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    std::vector<ParameterValue> items;
    for (const auto& item : h.cast<py::sequence>())
      items.push_back(to_value(name, item));
    return items;
  }
  invalid("parameter " + name + " = " + py::repr(h).cast<std::string>() +
          ": expected a bool, a number, a string or a list of them");
}

// A parameter value as Python sees it.
py::object to_python(const ParameterValue& v) {
  using K = ParameterValue::Kind;
  switch (v.kind) {
    case K::kBool:
      return py::bool_(v.boolean);
    case K::kInteger:
      return py::int_(v.integer);
    case K::kNumber:
      return py::float_(v.number);
    case K::kText:
      return py::str(v.text);
    case K::kList: {
      py::list out;
      for (const ParameterValue& item : v.items)
        out.append(to_python(item));
      return std::move(out);
    }
    case K::kDictionary:
      return py::dict();
    case K::kOther:
      break;
  }
  return py::none();
}

// The node's own values of a setup (the rows without a driver setting that a front end uses), by
// the table's names: what the ROS 2 node publishes with.
py::dict node_values(const NodeParameters& n) {
  py::dict d;
  d["port_name"] = n.port_name;
  d["odom_frame"] = n.odom_frame;
  d["base_frame"] = n.base_frame;
  d["frame_prefix"] = n.frame_prefix;
  d["publish_odom_tf"] = n.publish_odom_tf;
  d["publish_rate"] = n.publish_rate;
  d["state_publish_rate"] = n.state_publish_rate;
  d["publish_cmd"] = n.publish_cmd;
  d["cmd_vel_stamped"] = std::string(to_string(n.cmd_vel_stamped));
  d["pose_covariance_diagonal"] =
      std::vector<double>(n.pose_covariance_diagonal.begin(), n.pose_covariance_diagonal.end());
  d["twist_covariance_diagonal"] =
      std::vector<double>(n.twist_covariance_diagonal.begin(), n.twist_covariance_diagonal.end());
  d["ultrasonic/field_of_view"] = n.ultrasonic.field_of_view;
  d["ultrasonic/min_range"] = n.ultrasonic.min_range;
  d["ultrasonic/max_range"] = n.ultrasonic.max_range;
  return d;
}

// A diagnostic group as Python sees it, with the hardware_id every group of a report carries.
struct DiagnosticView {
  DiagnosticGroup group;
  std::string hardware_id;
};

// The DriverSnapshot as Python sees it: properties read it on demand.
class Snapshot {
 public:
  explicit Snapshot(std::shared_ptr<const DriverSnapshot> s) : s_(std::move(s)) {}
  const DriverSnapshot& s() const { return *s_; }
  const ControllerState& c() const { return s_->controller; }

 private:
  std::shared_ptr<const DriverSnapshot> s_;
};

// The Python-visible owner: a Session, and what a front end needs of its setup.
class PySession {
 public:
  explicit PySession(std::unique_ptr<Session> s) : s_(std::move(s)) {}
  Session& s() { return *s_; }
  const Setup& setup() const { return s_->setup(); }

  // How long a request of `kind` may take before a front end gives up waiting: the driver's
  // own answer budget for it.
  double budget(const std::string& kind) {
    if (const auto k = kRequestKindNames.parse(kind)) {
      return seconds(s_->driver().answer_budget(*k));
    }
    invalid("request kind \"" + kind + "\" unknown");
  }

 private:
  std::unique_ptr<Session> s_;
};

struct CliResult {
  int exit_code = 0;
  std::string out, err;
};

CliResult run_cli(const std::vector<std::string>& args, const std::string& input) {
  std::istringstream in(input);
  std::ostringstream out, err;
  CliResult r;
  r.exit_code = cli::run_main(args, cli::Io{in, out, err});
  r.out = out.str();
  r.err = err.str();
  return r;
}

// Whether a row's lo and hi hold (numbers and number lists).
bool has_range(const Parameter& p) {
  return p.type == ParameterType::kInteger || p.type == ParameterType::kNumber ||
         p.type == ParameterType::kSeconds || p.type == ParameterType::kNumberList;
}

// The library's tables as they are: the parameter rows and the diagnostic groups.
void bind_tables(py::module_& m) {
  // A row of the library's parameter table (frontend/node_parameters.hpp), as it is.
  using P = Parameter;
  py::class_<P>(m, "ParameterRow")
      .def_readonly("name", &P::name)
      .def_property_readonly("type", [](const P& p) { return python_type(p.type); })
      .def_property_readonly("table_type",
                             [](const P& p) { return std::string(to_string(p.type)); })
      .def_readonly("unit", &P::unit)
      .def_property_readonly("lo", [](const P& p) { return p.range.lo; })
      .def_property_readonly("hi", [](const P& p) { return p.range.hi; })
      .def_property_readonly("lo_open", [](const P& p) { return p.range.lo_open; })
      .def_property_readonly("hi_open", [](const P& p) { return p.range.hi_open; })
      .def_property_readonly("has_range", &has_range)
      .def_property_readonly("default", [](const P& p) { return to_python(p.default_value); })
      .def_readonly("default_note", &P::default_note)
      .def_property_readonly("valid", [](const P& p) { return valid_text(p); })
      .def_readonly("choices", &P::choices)
      .def_readonly("size", &P::size)
      .def_readonly("meaning", &P::meaning)
      .def_property_readonly("driver_setting", [](const P& p) { return p.get != nullptr; })
      .def_property_readonly("markdown", [](const P& p) { return markdown_row(p); })
      .def("__repr__", [](const P& p) { return "ParameterRow(" + p.name + ")"; });
  py::class_<DiagnosticView>(m, "DiagnosticGroup")
      .def_property_readonly("name", [](const DiagnosticView& d) { return d.group.name; })
      .def_property_readonly(
          "level", [](const DiagnosticView& d) { return static_cast<int>(d.group.level); })
      .def_property_readonly(
          "level_name",
          [](const DiagnosticView& d) { return std::string(to_string(d.group.level)); })
      .def_property_readonly("message", [](const DiagnosticView& d) { return d.group.message; })
      .def_property_readonly("values", [](const DiagnosticView& d) { return d.group.values; })
      .def_readonly("hardware_id", &DiagnosticView::hardware_id)
      .def("value",
           [](const DiagnosticView& d, const std::string& key) -> std::optional<std::string> {
             const std::string* v = d.group.value(key);
             if (!v) return std::nullopt;
             return *v;
           })
      .def("__str__", [](const DiagnosticView& d) { return to_text(d.group); })
      .def("__repr__", [](const DiagnosticView& d) {
        return "DiagnosticGroup(" + d.group.name + ": " + std::string(to_string(d.group.level)) +
               ")";
      });
}

// The motion estimate as serialised ROS 2 messages (ros2_wire.hpp): what the ROS 2 node publishes
// as bytes.
void bind_wire(py::module_& m) {
  using E = MotionWireEncoder;
  py::class_<E>(m, "MotionWireEncoder")
      .def(py::init([](std::string odom_frame, std::string base_frame,
                       std::vector<std::string> joint_names, std::vector<double> pose_diagonal,
                       std::vector<double> twist_diagonal) {
             if (joint_names.size() != 2 * static_cast<std::size_t>(kWheelCount)) {
               invalid("MotionWireEncoder: joint_names must name the " +
                       std::to_string(2 * kWheelCount) +
                       " joints (steering 1-4, then wheels 1-4), not " +
                       std::to_string(joint_names.size()));
             }
             MotionWireSetup setup{
                 std::move(odom_frame), std::move(base_frame), std::move(joint_names), {}, {}};
             for (auto [given, into] :
                  {std::pair{&pose_diagonal, &setup.pose_covariance_diagonal},
                   std::pair{&twist_diagonal, &setup.twist_covariance_diagonal}}) {
               if (given->size() != into->size()) {
                 invalid("MotionWireEncoder: a covariance diagonal has 6 values, not " +
                         std::to_string(given->size()));
               }
               std::copy(given->begin(), given->end(), into->begin());
             }
             return E(std::move(setup));
           }),
           py::arg("odom_frame"), py::arg("base_frame"), py::arg("joint_names"),
           py::arg("pose_covariance_diagonal"), py::arg("twist_covariance_diagonal"))
      .def("odometry", [](const E& e, const OdometryValues& v) { return py::bytes(e.odometry(v)); })
      .def("transform",
           [](const E& e, const OdometryValues& v) { return py::bytes(e.transform(v)); })
      .def("joint_state",
           [](const E& e, const JointValues& v) { return py::bytes(e.joint_state(v)); })
      // (odom, tf, joint_states) of an update: bytes where its part is new, else None.
      .def("encode", [](const E& e, const MotionUpdate& u) {
        py::object odom = py::none(), tf = py::none(), joints = py::none();
        if (u.snapshot && u.odometry) {
          const OdometryValues v = odometry_values(*u.snapshot);
          odom = py::bytes(e.odometry(v));
          tf = py::bytes(e.transform(v));
        }
        if (u.snapshot && u.joints) joints = py::bytes(e.joint_state(joint_values(*u.snapshot)));
        return py::make_tuple(odom, tf, joints);
      });
  // cmd_vel's bytes -> (linear x, y, z, angular x, y, z), or None where the rmw must read them.
  m.def(
      "read_twist",
      [](py::bytes data) -> py::object {
        const auto twist = read_twist(std::string_view(data));
        if (!twist) return py::none();
        const auto& t = *twist;
        return py::make_tuple(t[0], t[1], t[2], t[3], t[4], t[5]);
      },
      py::arg("data"));
}

}  // namespace
}  // namespace ranger::python

using namespace ranger;
using namespace ranger::python;

PYBIND11_MODULE(_ranger_can, m) {
  m.doc() = "libranger_can, the RANGER driver library (use the ranger_can package)";

  // The exception classes live in ranger_can/_errors.py; errors are translated into them.
  py::module_ errors = py::module_::import("ranger_can._errors");
  static py::object ranger_error = errors.attr("RangerError");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const LibraryError& e) {
      py::object exc = ranger_error(e.error.message, std::string(code_name(e.error.code)));
      PyErr_SetObject(ranger_error.ptr(), exc.ptr());
    }
  });

  // ---- values ----
  py::class_<OdometryView>(m, "Odometry")
      .def_readonly("x", &OdometryView::x)
      .def_readonly("y", &OdometryView::y)
      .def_readonly("yaw", &OdometryView::yaw)
      .def_readonly("vx", &OdometryView::vx)
      .def_readonly("vy", &OdometryView::vy)
      .def_readonly("wz", &OdometryView::wz)
      .def_readonly("stamp_ns", &OdometryView::stamp_ns)
      .def_readonly("distance", &OdometryView::distance)
      .def_readonly("pose_variance", &OdometryView::pose_variance)
      .def_readonly("twist_variance", &OdometryView::twist_variance)
      .def_readonly("source", &OdometryView::source)
      .def_readonly("steps", &OdometryView::steps)
      .def_readonly("last_gap", &OdometryView::last_gap)
      .def_readonly("last_gap_end_ns", &OdometryView::last_gap_end_ns)
      .def_readonly("gaps", &OdometryView::gaps)
      .def("__repr__", [](const OdometryView& o) {
        std::ostringstream out;
        out << "Odometry(x=" << o.x << ", y=" << o.y << ", yaw=" << o.yaw << ", vx=" << o.vx
            << ", vy=" << o.vy << ", wz=" << o.wz << ")";
        return out.str();
      });
  py::class_<JointsView>(m, "Joints")
      .def_readonly("steering_names", &JointsView::steering_names)
      .def_readonly("wheel_names", &JointsView::wheel_names)
      .def_readonly("steering_position", &JointsView::steering_position)
      .def_readonly("steering_velocity", &JointsView::steering_velocity)
      .def_readonly("wheel_position", &JointsView::wheel_position)
      .def_readonly("wheel_velocity", &JointsView::wheel_velocity)
      .def_readonly("has_steering", &JointsView::has_steering)
      .def_readonly("has_wheels", &JointsView::has_wheels)
      .def_readonly("stamp_ns", &JointsView::stamp_ns);
  py::class_<MotorView>(m, "Motor")
      .def_readonly("motor", &MotorView::motor)
      .def_readonly("joint", &MotorView::joint)
      .def_readonly("rpm", &MotorView::rpm)
      .def_readonly("current", &MotorView::current)
      .def_readonly("position", &MotorView::position)
      .def_readonly("driver_voltage", &MotorView::driver_voltage)
      .def_readonly("driver_temperature", &MotorView::driver_temperature)
      .def_readonly("motor_temperature", &MotorView::motor_temperature)
      .def_readonly("driver_status", &MotorView::driver_status)
      .def_readonly("driver_status_names", &MotorView::driver_status_names)
      .def_readonly("high_speed_stamp_ns", &MotorView::high_speed_stamp_ns)
      .def_readonly("low_speed_stamp_ns", &MotorView::low_speed_stamp_ns);
  py::class_<BatteryView>(m, "Battery")
      .def_readonly("battery", &BatteryView::battery)
      .def_readonly("present", &BatteryView::present)
      .def_readonly("soc", &BatteryView::soc)
      .def_readonly("soh", &BatteryView::soh)
      .def_readonly("voltage", &BatteryView::voltage)
      .def_readonly("current", &BatteryView::current)
      .def_readonly("temperature", &BatteryView::temperature)
      .def_readonly("alarm1", &BatteryView::alarm1)
      .def_readonly("alarm2", &BatteryView::alarm2)
      .def_readonly("warning1", &BatteryView::warning1)
      .def_readonly("warning2", &BatteryView::warning2)
      .def_readonly("alarms", &BatteryView::alarms)
      .def_readonly("warnings", &BatteryView::warnings)
      .def_readonly("stamp_ns", &BatteryView::stamp_ns);
  py::class_<UltrasonicView>(m, "UltrasonicReading")
      .def_readonly("sensor", &UltrasonicView::sensor)
      .def_readonly("raw", &UltrasonicView::raw)
      .def_readonly("range", &UltrasonicView::range)
      .def_readonly("status", &UltrasonicView::status)
      .def_readonly("stamp_ns", &UltrasonicView::stamp_ns);
  py::class_<IdentificationView>(m, "Identification")
      .def_readonly("phase", &IdentificationView::phase)
      .def_readonly("revision", &IdentificationView::revision)
      .def_readonly("message", &IdentificationView::message)
      .def_readonly("evidence", &IdentificationView::evidence)
      .def_readonly("undecided", &IdentificationView::undecided)
      .def_readonly("decided", &IdentificationView::decided)
      .def_readonly("confidence", &IdentificationView::confidence)
      .def_readonly("done", &IdentificationView::done)
      .def_readonly("elapsed", &IdentificationView::elapsed);
  py::class_<RemoteView>(m, "RemoteState")
      .def_readonly("swa", &RemoteView::swa)
      .def_readonly("swb", &RemoteView::swb)
      .def_readonly("swc", &RemoteView::swc)
      .def_readonly("swd", &RemoteView::swd)
      .def_readonly("left_vertical", &RemoteView::left_vertical)
      .def_readonly("left_horizontal", &RemoteView::left_horizontal)
      .def_readonly("right_vertical", &RemoteView::right_vertical)
      .def_readonly("right_horizontal", &RemoteView::right_horizontal)
      .def_readonly("knob", &RemoteView::knob)
      .def_readonly("stamp_ns", &RemoteView::stamp_ns)
      .def_readonly("received_ns", &RemoteView::received_ns);
  py::class_<LightsView>(m, "Lights")
      .def_readonly("can_control", &LightsView::can_control)
      .def_readonly("front", &LightsView::front)
      .def_readonly("rear", &LightsView::rear)
      .def_readonly("front_brightness", &LightsView::front_brightness)
      .def_readonly("rear_brightness", &LightsView::rear_brightness);
  py::class_<FrameView>(m, "FrameCount")
      .def_readonly("id", &FrameView::id)
      .def_readonly("name", &FrameView::name)
      .def_readonly("frames", &FrameView::frames)
      .def_readonly("rejected", &FrameView::rejected)
      .def_readonly("padded", &FrameView::padded);
  py::class_<OutcomeView>(m, "RequestOutcome")
      .def_readonly("id", &OutcomeView::id)
      .def_readonly("kind", &OutcomeView::kind)
      .def_readonly("what", &OutcomeView::what)
      .def_readonly("state", &OutcomeView::state)
      .def_readonly("message", &OutcomeView::message)
      .def_readonly("error_word", &OutcomeView::error_word)
      .def_property_readonly("done", &OutcomeView::done)
      .def("__repr__", [](const OutcomeView& o) {
        return "RequestOutcome(" + o.kind + " #" + std::to_string(o.id) + ": " + o.state +
               (o.message.empty() ? "" : ", " + o.message) + ")";
      });
  py::class_<EventView>(m, "Event")
      .def_readonly("sequence", &EventView::sequence)
      .def_readonly("time_ns", &EventView::time_ns)
      .def_readonly("kind", &EventView::kind)
      .def_readonly("severity", &EventView::severity)
      .def_readonly("text", &EventView::text)
      .def_readonly("json", &EventView::json)
      .def("__repr__", [](const EventView& e) {
        return "Event(" + e.severity + " " + e.kind + ": " + e.text + ")";
      });
  py::class_<GroundTruthView>(m, "GroundTruth")
      .def_readonly("x", &GroundTruthView::x)
      .def_readonly("y", &GroundTruthView::y)
      .def_readonly("yaw", &GroundTruthView::yaw)
      .def_readonly("vx", &GroundTruthView::vx)
      .def_readonly("vy", &GroundTruthView::vy)
      .def_readonly("wz", &GroundTruthView::wz)
      .def_readonly("distance_travelled", &GroundTruthView::distance_travelled)
      .def_readonly("yaw_travelled", &GroundTruthView::yaw_travelled)
      .def_readonly("control_mode", &GroundTruthView::control_mode)
      .def_readonly("motion_mode", &GroundTruthView::motion_mode)
      .def_readonly("emergency_stop", &GroundTruthView::emergency_stop)
      .def_readonly("motion_allowed", &GroundTruthView::motion_allowed)
      .def_readonly("motion_refused_reason", &GroundTruthView::motion_refused_reason)
      .def_readonly("stamp_ns", &GroundTruthView::stamp_ns)
      .def_readonly("lights", &GroundTruthView::lights);
  py::class_<SentMotion>(m, "SentMotion")
      .def_property_readonly("vx", [](const SentMotion& s) { return s.achieved.vx; })
      .def_property_readonly("vy", [](const SentMotion& s) { return s.achieved.vy; })
      .def_property_readonly("wz", [](const SentMotion& s) { return s.achieved.wz; })
      .def_readonly("wall", &SentMotion::wall)
      .def_readonly("shutdown", &SentMotion::shutdown);
  py::class_<MotionUpdate>(m, "MotionUpdate")
      .def_property_readonly("snapshot",
                             [](const MotionUpdate& u) -> std::optional<Snapshot> {
                               if (!u.snapshot) return std::nullopt;
                               return Snapshot(u.snapshot);
                             })
      .def_property_readonly("odometry",
                             [](const MotionUpdate& u) -> std::optional<OdometryValues> {
                               if (!u.odometry) return std::nullopt;
                               return odometry_values(*u.snapshot);
                             })
      .def_property_readonly("joints",
                             [](const MotionUpdate& u) -> std::optional<JointValues> {
                               if (!u.joints) return std::nullopt;
                               return joint_values(*u.snapshot);
                             })
      .def_property_readonly(
          "new_estimate",
          [](const MotionUpdate& u) { return u.snapshot != nullptr && (u.odometry || u.joints); })
      .def_readonly("sent", &MotionUpdate::sent)
      .def("__repr__", [](const MotionUpdate& u) {
        return std::string("MotionUpdate(") + (u.odometry ? "odometry " : "") +
               (u.joints ? "joints " : "") + std::to_string(u.sent.size()) + " sent)";
      });
  py::class_<BatteryReport>(m, "BatteryReport")
      .def_readonly("present", &BatteryReport::present)
      .def_property_readonly("stamp_ns",
                             [](const BatteryReport& r) { return r.stamp.count(); })  // 0: none
      .def_readonly("voltage", &BatteryReport::voltage)
      .def_readonly("current", &BatteryReport::current)
      .def_readonly("temperature", &BatteryReport::temperature)
      .def_readonly("percentage", &BatteryReport::percentage)
      .def_property_readonly("power_supply_status",
                             [](const BatteryReport& r) { return static_cast<int>(r.status); })
      .def_property_readonly("power_supply_health",
                             [](const BatteryReport& r) { return static_cast<int>(r.health); })
      .def_property_readonly("cell_voltage",
                             [](const BatteryReport& r) {
                               return std::vector<double>(r.cell_voltage.begin(),
                                                          r.cell_voltage.end());
                             })
      .def_property_readonly("cell_temperature", [](const BatteryReport& r) {
        return std::vector<double>(r.cell_temperature.begin(), r.cell_temperature.end());
      });
  // A front end's fixed-rate schedule (frontend/publication.hpp); times in s of time.monotonic()
  // (CLOCK_MONOTONIC, the steady clock's).
  py::class_<PublicationSchedule>(m, "PublicationSchedule")
      .def(py::init([](double rate_hz) {
             if (!(rate_hz > 0.0)) invalid("PublicationSchedule: the rate must be > 0 Hz");
             return PublicationSchedule(rate_hz);
           }),
           py::arg("rate_hz"))
      .def(
          "start", [](PublicationSchedule& p, double now) { p.start(steady_time(now)); },
          py::arg("now"))
      .def(
          "due", [](const PublicationSchedule& p, double now) { return p.due(steady_time(now)); },
          py::arg("now"))
      .def(
          "advance",
          [](PublicationSchedule& p, double now, std::optional<double> rate_hz) {
            if (rate_hz) {
              if (!(*rate_hz > 0.0)) invalid("PublicationSchedule: the rate must be > 0 Hz");
              p.set_rate(*rate_hz);
            }
            p.advance(steady_time(now));
          },
          py::arg("now"), py::arg("rate_hz") = py::none())
      .def_property_readonly("wake_at",
                             [](const PublicationSchedule& p) { return seconds_of(p.wake_at()); });
  // Which message cmd_vel is taken as (frontend/cmd_vel_type.hpp): the rule and its lines; type
  // names in `spelling`'s form ("ros2": geometry_msgs/msg/Twist, the ROS 2 graph's).
  py::class_<CmdVelDecision>(m, "CmdVelTypeDecision")
      .def_property_readonly("change",
                             [](const CmdVelDecision& d) {
                               return std::string(kCmdVelTypeChangeNames.name(d.decision.change));
                             })
      .def_property_readonly("taken",
                             [](const CmdVelDecision& d) -> std::optional<std::string> {
                               if (!d.decision.taken) return std::nullopt;
                               return type_name(*d.decision.taken, d.spelling);
                             })
      .def_property_readonly("stamped",
                             [](const CmdVelDecision& d) -> std::optional<bool> {
                               if (!d.decision.taken) return std::nullopt;
                               return *d.decision.taken == CmdVelType::kTwistStamped;
                             })
      .def_property_readonly("line", [](const CmdVelDecision& d) { return d.decision.line; });
  py::class_<CmdVelTypeRule>(m, "CmdVelTypeRule")
      .def(py::init([](const std::string& setting, const std::string& spelling) {
             const auto s = kCmdVelStampedNames.parse(setting);
             if (!s) {
               invalid("cmd_vel_stamped \"" + setting + "\" unknown: one of " +
                       text::join(kCmdVelStampedNames.names()));
             }
             return CmdVelTypeRule(*s, parse_spelling(spelling));
           }),
           py::arg("setting"), py::arg("spelling") = "ros2")
      .def(
          "start",
          [](CmdVelTypeRule& r, const std::vector<std::string>& publisher_types) {
            return CmdVelDecision{r.start(publisher_types), r.spelling()};
          },
          py::arg("publisher_types"))
      .def(
          "on_publishers",
          [](CmdVelTypeRule& r, const std::vector<std::string>& publisher_types,
             std::optional<double> since_last_message) {
            std::optional<std::chrono::steady_clock::duration> since;
            if (since_last_message) since = to_ns(*since_last_message);
            return CmdVelDecision{r.on_publishers(publisher_types, since), r.spelling()};
          },
          py::arg("publisher_types"), py::arg("since_last_message") = py::none())
      .def(
          "on_message",
          [](CmdVelTypeRule& r, const std::string& type) {
            const auto t = parse_cmd_vel_type(type);
            if (!t) invalid(cmd_vel_type_refused_line(type, r.spelling()));
            return CmdVelDecision{r.on_message(*t), r.spelling()};
          },
          py::arg("type"))
      .def_property_readonly("follows_publishers", &CmdVelTypeRule::follows_publishers)
      .def_property_readonly(
          "setting", [](const CmdVelTypeRule& r) { return std::string(to_string(r.setting())); })
      .def_property_readonly("taken", [](const CmdVelTypeRule& r) -> std::optional<std::string> {
        if (!r.taken()) return std::nullopt;
        return type_name(*r.taken(), r.spelling());
      });
  m.def(
      "cmd_vel_type_names",
      [](const std::string& spelling) {
        std::vector<std::string> out;
        for (const CmdVelType t : kCmdVelTypeNames.values())
          out.push_back(type_name(t, parse_spelling(spelling)));
        return out;
      },
      py::arg("spelling") = "ros2");
  bind_tables(m);
  bind_wire(m);
  py::class_<CliResult>(m, "CliResult")
      .def_readonly("exit_code", &CliResult::exit_code)
      .def_readonly("out", &CliResult::out)
      .def_readonly("err", &CliResult::err);

  // ---- the snapshot ----
  using S = Snapshot;
  py::class_<S>(m, "Snapshot")
      .def_property_readonly("sequence", [](const S& s) { return s.s().sequence; })
      .def_property_readonly("now_ns", [](const S& s) { return s.s().now.count(); })
      .def_property_readonly("port", [](const S& s) { return s.s().bus_name; })
      .def_property_readonly("bus_open", [](const S& s) { return s.s().bus_open; })
      .def_property_readonly("read_only", [](const S& s) { return s.s().read_only; })
      .def_property_readonly("bus_error", [](const S& s) { return s.s().bus_error; })
      .def_property_readonly("bus_state",
                             [](const S& s) { return std::string(to_string(s.s().bus.state)); })
      .def_property_readonly("link", [](const S& s) { return std::string(to_string(s.c().link)); })
      .def_property_readonly("control_mode", [](const S& s) { return name_of(s.c().control_mode); })
      .def_property_readonly("control_mode_raw", [](const S& s) { return s.c().control_mode_raw; })
      .def_property_readonly("vehicle_status",
                             [](const S& s) { return name_of(s.c().vehicle_status); })
      .def_property_readonly("vehicle_status_raw",
                             [](const S& s) -> std::optional<int> {
                               const auto& st = s.s().feedback.system_status;
                               if (!st) return std::nullopt;
                               return st->value.vehicle_status_raw;
                             })
      .def_property_readonly("motion_mode", [](const S& s) { return name_of(s.c().motion_mode); })
      .def_property_readonly("chassis_mode", [](const S& s) { return name_of(s.c().chassis_mode); })
      .def_property_readonly("chassis_mode_raw",
                             [](const S& s) -> std::optional<int> {
                               const auto& mm = s.s().feedback.motion_mode;
                               if (!mm) return std::nullopt;
                               return mm->value.mode_raw;
                             })
      .def_property_readonly("switching", [](const S& s) { return s.c().chassis_switching; })
      .def_property_readonly("mode_override",
                             [](const S& s) { return name_of(s.c().mode_override); })
      .def_property_readonly("refusal",
                             [](const S& s) { return std::string(to_string(s.c().refusal)); })
      // system_state's link_up and motion_inhibited_reason ("" while motion is accepted).
      .def_property_readonly("link_up",
                             [](const S& s) { return s.c().link == LinkState::kConnected; })
      .def_property_readonly("motion_inhibited_reason",
                             [](const S& s) { return refusal_name(s.c()); })
      // sensor_msgs/BatteryState's facts (ranger::battery_report).
      .def_property_readonly("battery_report",
                             [](const S& s) { return battery_report(s.s().feedback, s.s().now); })
      .def_property_readonly(
          "refusal_detail",
          [](const S& s) { return describe_refusal(s.c(), s.s().identification.get()); })
      .def_property_readonly("rearm_required", [](const S& s) { return s.c().rearm_required(); })
      .def_property_readonly("latched_causes",
                             [](const S& s) { return cause_names(s.c().latched_causes); })
      .def_property_readonly("active_causes",
                             [](const S& s) { return cause_names(s.c().active_causes); })
      .def_property_readonly("reclaim_blocked", [](const S& s) { return s.c().reclaim_blocked; })
      .def_property_readonly("awaiting_command_mode",
                             [](const S& s) { return s.c().awaiting_command_mode; })
      .def_property_readonly("cmd_timed_out", [](const S& s) { return s.c().cmd_timed_out; })
      .def_property_readonly("steer_first_factor",
                             [](const S& s) { return s.c().steer_first_factor; })
      .def_property_readonly("faults", [](const S& s) { return s.c().faults; })
      .def_property_readonly("error_word", [](const S& s) { return s.c().error_bits; })
      .def_property_readonly(
          "error_layout",
          [](const S& s) { return std::string(to_string(s.s().profile.error_word)); })
      .def_property_readonly(
          "error_names",
          [](const S& s) { return fault_names(s.c().error_bits, s.s().profile.error_word); })
      .def_property_readonly("battery_voltage",
                             [](const S& s) -> std::optional<double> {
                               const auto& st = s.s().feedback.system_status;
                               if (!st) return std::nullopt;
                               return st->value.battery_voltage;
                             })
      .def_property_readonly("battery_soc", [](const S& s) { return s.c().battery_soc; })
      .def_property_readonly("park_requested", [](const S& s) { return s.c().park_requested; })
      .def_property_readonly("parked", [](const S& s) { return s.c().parked(); })
      .def_property_readonly("ultrasonic_enabled",
                             [](const S& s) { return s.c().ultrasonic_enabled; })
      .def_property_readonly("identifying",
                             [](const S& s) -> std::optional<std::string> {
                               if (!s.c().identifying) return std::nullopt;
                               return std::string(to_string(*s.c().identifying));
                             })
      .def_property_readonly("standstill_probe", [](const S& s) { return s.c().standstill_probe; })
      .def_property_readonly("quiet", [](const S& s) { return s.c().quiet; })
      .def_property_readonly("implausible_reason",
                             [](const S& s) { return s.c().implausible_reason; })
      .def_property_readonly("motion_known", [](const S& s) { return s.s().motion_known; })
      .def_property_readonly("odometry", [](const S& s) { return odometry_view(s.s()); })
      .def_property_readonly("joints", [](const S& s) { return joints_view(s.s()); })
      .def_property_readonly("motors", [](const S& s) { return motors_view(s.s()); })
      .def_property_readonly("batteries", [](const S& s) { return batteries_view(s.s()); })
      .def_property_readonly("ultrasonic", [](const S& s) { return ultrasonic_view(s.s()); })
      .def_property_readonly("protocol",
                             [](const S& s) { return std::string(to_string(s.s().protocol)); })
      .def_property_readonly("profile", [](const S& s) { return describe(s.s().profile); })
      .def_property_readonly("profile_revision", [](const S& s) { return s.s().profile.revision; })
      .def_property_readonly("drivable_modes",
                             [](const S& s) {
                               std::vector<std::string> out;
                               for (auto m : drivable_modes(s.s().profile))
                                 out.emplace_back(protocol::to_string(m));
                               return out;
                             })
      .def_property_readonly("identification",
                             [](const S& s) { return identification_view(s.s()); })
      .def_property_readonly("plausibility_warnings",
                             [](const S& s) {
                               std::vector<std::string> out;
                               for (const auto& w : s.s().plausibility.warnings)
                                 out.push_back(w.text());
                               return out;
                             })
      .def_property_readonly("plausibility_stop",
                             [](const S& s) -> std::optional<std::string> {
                               if (!s.s().plausibility.stop) return std::nullopt;
                               return s.s().plausibility.stop->text();
                             })
      .def_property_readonly("vendor_frames",
                             [](const S& s) { return std::string(to_string(s.s().vendor_frames)); })
      .def_property_readonly("remote", [](const S& s) { return remote_view(s.s()); })
      .def_property_readonly("lights", [](const S& s) { return lights_view(s.s()); })
      .def_property_readonly("drive_mode", [](const S& s) { return name_of(s.s().drive_mode); })
      .def_property_readonly("drive_mode_raw",
                             [](const S& s) -> std::optional<int> {
                               if (!s.s().drive_mode) return std::nullopt;
                               return static_cast<int>(*s.s().drive_mode);
                             })
      .def_property_readonly(
          "wheel_odometers",  // front left, front right, rear left, rear right (m; NaN: none)
          [](const S& s) { return wheel_odometers(s.s().feedback); })
      .def_property_readonly("bms_alarms",
                             [](const S& s) { return pack_bms_alarms(s.s().feedback).alarms; })
      .def_property_readonly("bms_warnings",
                             [](const S& s) { return pack_bms_alarms(s.s().feedback).warnings; })
      .def_property_readonly("firmware_version", [](const S& s) { return s.s().firmware.text; })
      .def_property_readonly(
          "firmware_state", [](const S& s) { return std::string(to_string(s.s().firmware.state)); })
      .def_property_readonly("frames", [](const S& s) { return frames_view(s.s()); })
      .def_property_readonly("requests",
                             [](const S& s) {
                               std::vector<OutcomeView> out;
                               for (const auto& r : s.s().requests)
                                 out.push_back(outcome_view(r));
                               return out;
                             })
      .def_property_readonly("loop_iterations", [](const S& s) { return s.s().loop_iterations; })
      .def("__repr__", [](const S& s) {
        return "Snapshot(#" + std::to_string(s.s().sequence) + ", link " +
               std::string(to_string(s.c().link)) + ", refusal " +
               std::string(to_string(s.c().refusal)) + ")";
      });

  // ---- the driver ----
  py::class_<PySession>(m, "_Session")
      .def(py::init([](const std::string& port, const py::dict& params, bool record_sent,
                       const std::string& display_prefix) {
             std::map<std::string, ParameterValue> values;
             for (const auto& [k, v] : params) {
               const std::string name = py::str(k);
               values[name] = to_value(name, v);
             }
             Setup setup = value_or_throw(make_setup(port, std::move(values), display_prefix));
             // publish_cmd: the frames sent are what cmd_vel_out publishes.
             setup.record_sent = record_sent || setup.node.publish_cmd;
             return std::make_unique<PySession>(value_or_throw(Session::open(setup)));
           }),
           py::arg("port"), py::arg("params"), py::arg("record_sent") = false,
           py::arg("display_prefix") = "")
      .def("start", [](PySession& p) { p.s().start(); })
      .def(
          "stop", [](PySession& p) { p.s().stop(); }, py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("started", [](PySession& p) { return p.s().started(); })
      .def_property_readonly("stopped", [](PySession& p) { return p.s().stopped(); })
      .def_property_readonly("stop_sent", [](PySession& p) { return p.s().stop_sent(); })
      .def_property_readonly("port", [](const PySession& p) { return p.setup().node.port_name; })
      .def_property_readonly("model",
                             [](const PySession& p) { return p.setup().node.protocol.model; })
      .def_property_readonly(
          "model_display_name",
          [](const PySession& p) { return p.setup().node.protocol.model_display_name; })
      .def_property_readonly("protocol",
                             [](const PySession& p) { return p.setup().node.protocol.protocol; })
      .def_property_readonly("protocol_source",
                             [](const PySession& p) { return p.setup().node.protocol.source; })
      .def_property_readonly(
          "startup_lines",
          [](const PySession& p) {
            py::list out;
            for (const LogLine& l : describe_protocol_setup(p.setup().node))
              out.append(py::make_tuple(std::string(to_string(l.severity)), l.text));
            return out;
          })
      .def_property_readonly("settings",
                             [](const PySession& p) { return node_values(p.setup().node); })
      .def_property_readonly("is_sim", [](PySession& p) { return p.s().sim() != nullptr; })
      .def_property_readonly("geometry",
                             [](const PySession& p) {
                               const auto& g = p.setup().node.driver.controller.geometry;
                               return py::make_tuple(g.wheelbase, g.track, g.wheel_radius);
                             })
      .def_property_readonly("max_linear_speed",
                             [](const PySession& p) {
                               return p.setup().node.driver.controller.limits.max_linear_speed;
                             })
      .def("budget", &PySession::budget, py::arg("kind"))
      .def("snapshot", [](PySession& p) { return Snapshot(p.s().snapshot()); })
      .def(
          "wait_snapshot",
          [](PySession& p, std::uint64_t sequence, double timeout) {
            std::shared_ptr<const DriverSnapshot> s;
            {
              py::gil_scoped_release release;
              s = p.s().wait_snapshot(sequence, to_ns(timeout));
            }
            return Snapshot(std::move(s));
          },
          py::arg("sequence"), py::arg("timeout"))
      .def(
          "command",
          [](PySession& p, double vx, double vy, double wz, std::optional<std::string> mode,
             double vz, double wx, double wy, std::optional<double> age) {
            // All six components: the driver refuses NaN/inf in any of them (naming it).
            MotionRequest r{BodyTwist{vx, vy, wz}, std::nullopt, OutOfPlaneTwist{vz, wx, wy}};
            if (mode) r.mode = parse_mode(*mode);
            // A stamped twist's age (s): older than cmd_vel_timeout, the driver refuses it
            // (stale_command in the snapshot); NaN is no age.
            if (age && std::isfinite(*age)) {
              r.age = std::chrono::duration_cast<std::chrono::nanoseconds>(
                  std::chrono::duration<double>(*age));
            }
            check(p.s().driver().command(r));
          },
          py::arg("vx"), py::arg("vy"), py::arg("wz"), py::arg("mode") = py::none(),
          py::arg("vz") = 0.0, py::arg("wx") = 0.0, py::arg("wy") = 0.0,
          py::arg("age") = py::none())
      .def(
          "set_motion_mode",
          [](PySession& p, std::optional<std::string> mode) {
            std::optional<MotionMode> m;
            if (mode) m = parse_mode(*mode);
            // The driver refuses a mode the settings in use cannot drive, naming the ones they do.
            check(p.s().driver().set_motion_mode(m));
          },
          py::arg("mode"))
      .def("clear_errors",
           [](PySession& p, int code) {
             if (code < 0 || code > 255)
               invalid("clear_errors: code " + std::to_string(code) + " outside 0..255");
             return value_or_throw(p.s().driver().clear_errors(static_cast<std::uint8_t>(code)));
           })
      .def("set_ultrasonic",
           [](PySession& p, bool on) { return p.s().driver().set_ultrasonic(on); })
      .def("resume", [](PySession& p) { return p.s().driver().resume(); })
      .def(
          "set_lights",
          [](PySession& p, const std::string& front, long long front_brightness,
             const std::string& rear, long long rear_brightness) {
            // The library's one check of a brightness (0..100), as every front end's.
            const LightsRequest r = value_or_throw(lights_request(
                parse_light(front), front_brightness, parse_light(rear), rear_brightness));
            return value_or_throw(p.s().driver().set_lights(r));
          },
          py::arg("front"), py::arg("front_brightness"), py::arg("rear"),
          py::arg("rear_brightness"))
      .def("set_park", [](PySession& p, bool on) { return p.s().driver().set_park(on); })
      .def(
          "set_drive_mode",
          [](PySession& p, const std::string& mode) {
            const auto m = protocol::kDriveModeNames.parse(mode);
            if (!m) {
              invalid("drive mode \"" + mode + "\" unknown: one of " +
                      text::join(protocol::kDriveModeNames.names()));
            }
            return p.s().driver().set_drive_mode(*m);
          },
          py::arg("mode"))
      .def("request_firmware_version",
           [](PySession& p) { return p.s().driver().request_firmware_version(); })
      .def(
          "wait_for",
          [](PySession& p, std::uint64_t id, double timeout) {
            RequestOutcome o;
            {
              py::gil_scoped_release release;
              o = p.s().driver().wait_for(id, to_ns(timeout));
            }
            return outcome_view(o);
          },
          py::arg("id"), py::arg("timeout"))
      .def("inject",
           [](PySession& p, const std::string& line) { return value_or_throw(p.s().inject(line)); })
      .def("ground_truth",
           [](PySession& p) -> std::optional<GroundTruthView> {
             if (!p.s().sim()) return std::nullopt;
             return ground_truth_view(p.s().sim()->snapshot());
           })
      .def(
          "events_since",
          [](PySession& p, std::uint64_t after) {
            std::vector<DriverEvent> events;
            const std::uint64_t missed = p.s().driver().events_since(after, events);
            std::vector<EventView> out;
            for (const auto& e : events)
              out.push_back(event_view(e));
            return py::make_tuple(out, missed);
          },
          py::arg("after"))
      .def(
          "wait_motion",
          [](PySession& p, double period, double timeout) {
            if (!(period > 0.0)) invalid("wait_motion: the period must be > 0 s");
            py::gil_scoped_release release;
            return p.s().wait_motion(to_ns(period), to_ns(timeout));
          },
          py::arg("period"), py::arg("timeout"))
      .def(
          "diagnostics",
          [](PySession& p, const std::string& ns) {
            std::vector<DiagnosticView> out;
            const std::string id = p.s().hardware_id(ns);
            for (DiagnosticGroup& g : p.s().diagnostics(ns))
              out.push_back(DiagnosticView{std::move(g), id});
            return out;
          },
          py::arg("namespace"))
      .def("hardware_id", [](PySession& p, const std::string& ns) { return p.s().hardware_id(ns); })
      .def("take_sent", [](PySession& p) { return p.s().take_sent(); })
      .def(
          "wait_sent",
          [](PySession& p, double timeout) {
            py::gil_scoped_release release;
            return p.s().wait_sent(to_ns(timeout));
          },
          py::arg("timeout"));

  // ---- tables and names ----
  m.def("parameters", &node_parameters, py::return_value_policy::copy);
  m.def(
      "check_parameter",
      [](const std::string& name, const py::handle& value) {
        return to_python(value_or_throw(check_value(name, to_value(name, value))));
      },
      py::arg("name"), py::arg("value"));
  m.def("diagnostic_group_names", [] {
    return std::vector<std::string>(kDiagnosticGroups.begin(), kDiagnosticGroups.end());
  });
  m.def("model_names", &model_names);
  m.def("variant_names", &sim::variant_names);
  m.def("protocol_names", [] {
    std::vector<std::string> out = {"auto"};
    for (const auto& n : protocol_revision_names())
      out.push_back(n);
    return out;
  });
  m.def("motion_modes", [] { return protocol::kMotionModeNames.names(); });
  m.def("light_modes", [] { return protocol::kLightModeNames.names(); });
  // The front ends' numbers (ranger_msgs' constants): SetMotionMode's (None: automatic),
  // SetLights', SetDriveMode's, each with the library's name.
  m.def("motion_mode_numbers", [] {
    std::vector<std::pair<int, std::optional<std::string>>> out;
    for (const auto& [number, mode] : motion_mode_numbers()) {
      out.emplace_back(
          number, mode ? std::optional<std::string>(protocol::to_string(*mode)) : std::nullopt);
    }
    return out;
  });
  m.def("light_mode_numbers", [] {
    std::vector<std::pair<int, std::string>> out;
    for (const auto& row : protocol::kLightModeNames)
      out.emplace_back(static_cast<int>(row.value), std::string(row.name));
    return out;
  });
  m.def("drive_mode_numbers", [] {
    std::vector<std::pair<int, std::string>> out;
    for (const auto& row : protocol::kDriveModeNames)
      out.emplace_back(static_cast<int>(row.value), std::string(row.name));
    return out;
  });
  m.def("refusal_names", [] { return kMotionRefusalNames.names(); });
  m.def("event_kinds", [] { return kEventKindNames.names(); });
  m.def("fault_names", [] {
    std::vector<std::string> out;
    for (const auto& f : protocol::kFaultTable)
      out.emplace_back(protocol::to_string(f.fault));
    return out;
  });
  m.def("driver_status_bit_names", [] {
    std::vector<std::string> out;
    for (const auto& b : protocol::driver_status_bits())
      out.emplace_back(b.name);
    return out;
  });
  m.def("bms_status_bit_names", [] {
    std::vector<std::string> out;
    for (const auto& b : protocol::bms_status1_bits())
      out.emplace_back(b.name);
    for (const auto& b : protocol::bms_status2_bits())
      out.emplace_back(b.name);
    return out;
  });
  m.def("chassis_command_names", &sim::chassis_command_names);
  m.def("steering_joint_names", [] {
    return std::vector<std::string>(kSteeringJointNames.begin(), kSteeringJointNames.end());
  });
  m.def("wheel_joint_names",
        [] { return std::vector<std::string>(kWheelJointNames.begin(), kWheelJointNames.end()); });
  m.def("error_clear_description", &protocol::error_clear_description);
  // The front ends' words (frontend/answers.hpp), as the ROS 1 node answers with them.
  m.def(
      "unknown_motion_mode_number",
      [](int number, const Snapshot& s) {
        return unknown_motion_mode_number(number, s.s().profile);
      },
      py::arg("number"), py::arg("snapshot"));
  m.def(
      "motion_mode_pinned",
      [](std::optional<std::string> mode) {
        return motion_mode_pinned(mode ? std::optional<MotionMode>(parse_mode(*mode))
                                       : std::nullopt);
      },
      py::arg("mode"));
  m.def(
      "resume_refused_offline",
      [](const Snapshot& s, const std::string& port) -> std::optional<std::string> {
        const auto refused = resume_refused_offline(s.s(), port);
        if (!refused) return std::nullopt;
        return refused->message;
      },
      py::arg("snapshot"), py::arg("port"));
  m.def(
      "clear_errors_answer",
      [](int code, const OutcomeView& outcome, const Snapshot& s) {
        if (code < 0 || code > 255)
          invalid("clear_errors: code " + std::to_string(code) + " out of range [0, 255]");
        const ServiceAnswer a = clear_errors_answer(static_cast<std::uint8_t>(code),
                                                    outcome.outcome, s.s().profile.error_word);
        return py::make_tuple(a.success, a.message);
      },
      py::arg("code"), py::arg("outcome"), py::arg("snapshot"));
  m.def(
      "request_answer",  // any request's answer after the wait, by its kind
      [](const OutcomeView& outcome) {
        const ServiceAnswer a = request_answer(outcome.outcome);
        return py::make_tuple(a.success, a.message);
      },
      py::arg("outcome"));
  m.def(
      "ultrasonic_request_refused",
      [](bool enable, bool disable) -> std::optional<std::string> {
        const auto refused = ultrasonic_request_refused(enable, disable);
        if (!refused) return std::nullopt;
        return refused->message;
      },
      py::arg("enable"), py::arg("disable"));
  m.def(
      "lights_request_refused",  // SetLights' numbers checked: why not, or None
      [](long long front_mode, long long front_brightness, long long rear_mode,
         long long rear_brightness) -> std::optional<std::string> {
        const auto r = lights_request(front_mode, front_brightness, rear_mode, rear_brightness);
        if (r) return std::nullopt;
        return r.error().message;
      },
      py::arg("front_mode"), py::arg("front_brightness"), py::arg("rear_mode"),
      py::arg("rear_brightness"));
  m.def(
      "drive_mode_request",  // SetDriveMode's number: its name; RangerError naming the valid ones
      [](long long number) {
        return std::string(protocol::to_string(value_or_throw(drive_mode_request(number))));
      },
      py::arg("number"));
  m.def(
      "answer_line",  // a service's answer as its one log line: (severity, text)
      [](const std::string& service, bool success, const std::string& message) {
        const LogLine l = answer_line(service, ServiceAnswer{success, message});
        return py::make_tuple(std::string(to_string(l.severity)), l.text);
      },
      py::arg("service"), py::arg("success"), py::arg("message"));
  m.def("answer_event_kinds", [] {  // the driver's events that are a service's answer
    std::vector<std::string> out;
    for (const auto& row : kEventKindNames) {
      if (is_answer_event(row.value)) out.emplace_back(row.name);
    }
    return out;
  });
  m.def(
      "pose_covariance",  // floor on the diagonal + the x, y, yaw variance (row-major 6x6)
      [](const std::array<double, 6>& floor, const std::array<double, 3>& variance) {
        return pose_covariance(variance, floor);
      },
      py::arg("floor"), py::arg("variance"));
  m.def("diagonal_covariance", &diagonal_covariance, py::arg("diagonal"));
  m.def("range_reading", &range_reading, py::arg("raw"), py::arg("max_range"));
  m.def("resume_answered", [] {  // what resume answers once the driver re-armed
    RequestOutcome answered;
    answered.state = RequestOutcome::State::kAnswered;
    return resume_answer(answered).message;
  });
  m.def(
      "error_names",
      [](std::uint32_t word, const std::string& layout) {
        ProtocolProfile p;
        check(set_setting(p, "error_word", layout));
        return fault_names(word, p.error_word);
      },
      py::arg("error_word"), py::arg("layout"));
  m.def(
      "_cli",
      [](const std::vector<std::string>& args, const std::string& input) {
        py::gil_scoped_release release;
        return run_cli(args, input);
      },
      py::arg("args"), py::arg("input") = "");
  m.attr("__version__") = cli::version();
}
