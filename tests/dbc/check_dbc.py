#!/usr/bin/python3
"""Cross-checks libranger_can/dbc/ranger.dbc against the C++ codec.

Random payloads (plus edge patterns) for every message in the DBC are written to a candump log,
decoded by `ranger_can decode --json` and by cantools (installed from PyPI into a virtual
environment this script creates, or reuses), and every signal is compared with the C++ field it
describes. Also checked: the DBC and the codec know exactly the same IDs with the same DLCs, and
every JSON field the codec prints for a frame is covered by some DBC signal.

usage: check_dbc.py --cli PATH/ranger_can --dbc ranger.dbc --venv DIR --work DIR [--frames N]
Exit status 0 when everything agrees, 1 on any disagreement (each one printed), 2 on set-up errors.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys

IN_VENV_FLAG = "--in-venv"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cli", required=True, help="the ranger_can executable")
    p.add_argument("--dbc", required=True, help="the DBC file to check")
    p.add_argument("--venv", required=True, help="virtual environment for cantools (created if absent)")
    p.add_argument("--work", required=True, help="directory for the generated log")
    p.add_argument("--frames", type=int, default=400, help="random payloads per message")
    p.add_argument("--seed", type=int, default=20240611)
    p.add_argument(IN_VENV_FLAG, action="store_true", help=argparse.SUPPRESS)
    return p.parse_args(argv)


def die(msg, code=2):
    print(f"check_dbc: {msg}", file=sys.stderr)
    sys.exit(code)


# ---- virtual environment ----------------------------------------------------------------------

def ensure_venv_and_reexec(args):
    py = os.path.join(args.venv, "bin", "python")
    if not os.path.exists(py):
        print(f"check_dbc: creating virtual environment {args.venv}", flush=True)
        r = subprocess.run(["/usr/bin/python3", "-m", "venv", args.venv])
        if r.returncode != 0:
            die("cannot create the virtual environment (Debian: apt-get install python3-venv)")
    probe = subprocess.run([py, "-c", "import cantools"], capture_output=True)
    if probe.returncode != 0:
        print("check_dbc: installing cantools from PyPI into the virtual environment", flush=True)
        r = subprocess.run([py, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                            "cantools"])
        if r.returncode != 0:
            die("pip could not install cantools from PyPI (is the network reachable?)")
    os.execv(py, [py, os.path.abspath(__file__)] + sys.argv[1:] + [IN_VENV_FLAG])


# ---- what each DBC signal means on the C++ side -----------------------------------------------
# A rule maps (dbc_value, json_object) -> (cpp_value_for_display, agrees: bool).

def close(a, b):
    return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))


def same(key, index=None):
    def rule(v, o):
        c = o[key] if index is None else o[key][index]
        return c, isinstance(c, (int, float)) and not isinstance(c, bool) and close(v, c)
    rule.keys = {key}
    return rule


def degrees_of(key, index=None):
    """DBC in degrees (the manual's 0.01 deg), C++ in radians; same sign convention."""
    def rule(v, o):
        c = o[key] if index is None else o[key][index]
        return c, close(math.radians(v), c)
    rule.keys = {key}
    return rule


def flag(key):
    def rule(v, o):
        return o[key], o[key] is (v != 0)
    rule.keys = {key}
    return rule


def bit_named(list_key, name):
    def rule(v, o):
        present = name in o[list_key]
        return present, present == (v != 0)
    rule.keys = {list_key}
    return rule


WHEELS = ["front_right", "rear_right", "rear_left", "front_left"]
# JSON fields that describe the frame rather than a signal, or are derived from other fields.
META = {"t", "iface", "id", "name", "dlc", "data"}
DERIVED = {"mode_name", "vehicle_status_name", "control_mode_name", "description", "critical",
           "status", "error_bits", "driver_status", "alarm1", "alarm2", "warning1", "warning2"}
# Fields that are not carried by a signal but by the frame ID (checked separately).
BY_ID = {"motor", "battery", "first_sensor"}


def rules_for(message):
    """(expected C++ frame name, {signal name: rule}, {C++ key: expected value from the ID})."""
    n = message.name
    sigs = [s.name for s in message.signals]
    if n == "MotionCommand":
        return "motion_command", {"linear_speed": same("linear_speed"),
                                  "spin_speed": same("spin_speed"),
                                  "steering_angle": degrees_of("steering_angle")}, {}
    if n in ("MotionModeCommand", "ControlModeCommand"):
        name = "motion_mode_command" if n == "MotionModeCommand" else "control_mode_command"
        return name, {"mode": same("mode")}, {}
    if n == "ErrorClearCommand":
        return "error_clear_command", {"code": same("code")}, {}
    if n == "UltrasonicSetting":
        return "ultrasonic_setting", {"enable": flag("enable")}, {}
    if n == "UltrasonicSettingFeedback":
        return "ultrasonic_setting_feedback", {"enabled": flag("enabled")}, {}
    if n == "SystemStatus":
        rules = {"vehicle_status": same("vehicle_status"), "control_mode": same("control_mode"),
                 "battery_voltage": same("battery_voltage")}
        for s in message.signals:
            if s.length == 1:
                rules[s.name] = bit_named("errors", s.name)
        return "system_status", rules, {}
    if n == "MotionFeedback":
        return "motion_feedback", {"speed": same("speed"),
                                   "steering_angle": degrees_of("steering_angle")}, {}
    if n.startswith("MotorHighSpeed"):
        return "motor_high_speed", {"rpm": same("rpm"), "current": same("current"),
                                    "position": same("position")}, {"motor": int(n[-1])}
    if n.startswith("MotorLowSpeed"):
        rules = {"driver_voltage": same("driver_voltage"),
                 "driver_temperature": same("driver_temperature"),
                 "motor_temperature": same("motor_temperature")}
        for s in message.signals:
            if s.length == 1:
                rules[s.name] = bit_named("driver_status_names", s.name)
        return "motor_low_speed", rules, {"motor": int(n[-1])}
    if n == "SteeringAngles":
        return "steering_angles", {f"angle_{w}": degrees_of("angles", i)
                                   for i, w in enumerate(WHEELS)}, {}
    if n == "WheelSpeeds":
        return "wheel_speeds", {f"speed_{w}": same("speeds", i) for i, w in enumerate(WHEELS)}, {}
    if n == "MotionModeFeedback":
        return "motion_mode", {"mode": same("mode"), "switching": flag("switching")}, {}
    if n.startswith("Ultrasonic") and n[-4:] in ("1to4", "5to8"):
        first = int(n[-4])
        return "ultrasonic", {f"distance_{first + i}": same("raw", i) for i in range(4)}, \
            {"first_sensor": first}
    if n.startswith("Bms"):
        battery = 0 if "Pack" in n else int(n[len("BmsBattery")])
        if n.endswith("Alarm"):
            rules = {}
            for s in sigs:
                kind, _, bit = s.partition("_")
                rules[s] = bit_named("alarms" if kind == "alarm" else "warnings", bit)
            return "bms_alarm", rules, {"battery": battery}
        return "bms", {k: same(k) for k in ("soc", "soh", "voltage", "current", "temperature")}, \
            {"battery": battery}
    return None, {}, {}


# ---- the check --------------------------------------------------------------------------------

def payloads(length, count, rng):
    edge = [bytes([0x00] * length), bytes([0xFF] * length), bytes([0x80] + [0x00] * (length - 1)),
            bytes([0x7F] + [0xFF] * (length - 1)), bytes(([0x80, 0x00] * 4)[:length]),
            bytes(([0x7F, 0xFF] * 4)[:length]), bytes(([0x55, 0xAA] * 4)[:length])]
    return edge + [bytes(rng.getrandbits(8) for _ in range(length)) for _ in range(count)]


def main():
    args = parse_args(sys.argv[1:])
    if not args.in_venv:
        ensure_venv_and_reexec(args)
    import cantools  # noqa: E402  (only inside the virtual environment)

    db = cantools.database.load_file(args.dbc)  # strict: overlapping signals are refused
    rng = random.Random(args.seed)
    messages = sorted(db.messages, key=lambda m: m.frame_id)

    frames = []  # (id, payload, message or None)
    for m in messages:
        for p in payloads(m.length, args.frames, rng):
            frames.append((m.frame_id, p, m))
    dbc_ids = {m.frame_id for m in messages}
    for other in range(0x800):  # every other standard ID must be unknown to the codec as well
        if other not in dbc_ids:
            frames.append((other, bytes(rng.getrandbits(8) for _ in range(8)), None))

    os.makedirs(args.work, exist_ok=True)
    log_path = os.path.join(args.work, "dbc_check.log")
    with open(log_path, "w") as f:
        for i, (fid, p, _) in enumerate(frames):
            f.write(f"({1700000000 + i // 1000}.{i % 1000:06d}) can0 {fid:03X}#{p.hex().upper()}\n")
    r = subprocess.run([args.cli, "decode", "--json", log_path], capture_output=True, text=True)
    if r.returncode != 0 or r.stderr:
        die(f"'{args.cli} decode --json {log_path}' failed (exit {r.returncode}): {r.stderr}", 1)
    lines = r.stdout.splitlines()
    if len(lines) != len(frames):
        die(f"{len(frames)} frames in, {len(lines)} JSON lines out", 1)

    problems = []
    comparisons = 0
    covered_signals = {}
    for (fid, payload, m), line in zip(frames, lines):
        o = json.loads(line)
        where = f"ID 0x{fid:03X} data {payload.hex().upper()}"
        if o["id"] != fid:
            problems.append(f"{where}: JSON line is for ID {o['id']}")
            continue
        if m is None:
            if o["name"] != "unknown":
                problems.append(f"{where}: not in the DBC, but the codec calls it '{o['name']}'")
            continue
        if "error" in o:
            problems.append(f"{where} ({m.name}, DLC {m.length} in the DBC): codec says {o['error']}")
            continue
        expected_name, rules, by_id = rules_for(m)
        if expected_name is None:
            problems.append(f"{m.name}: no rule in check_dbc.py for this DBC message")
            continue
        if o["name"] != expected_name:
            problems.append(f"{where}: DBC message {m.name}, codec name '{o['name']}'")
        for key, value in by_id.items():
            if o.get(key) != value:
                problems.append(f"{where}: {key} = {o.get(key)}, expected {value} from the ID")
        decoded = m.decode(payload, decode_choices=False, scaling=True)
        missing = set(decoded) - set(rules)
        extra = set(rules) - set(decoded)
        if missing or extra:
            problems.append(f"{m.name}: DBC signals {sorted(missing)} unchecked, "
                            f"{sorted(extra)} expected but absent")
        checked_keys = set()
        for sig_name, rule in rules.items():
            if sig_name not in decoded:
                continue
            checked_keys |= rule.keys
            cpp, ok = rule(decoded[sig_name], o)
            comparisons += 1
            covered_signals.setdefault(m.name, set()).add(sig_name)
            if not ok:
                problems.append(f"{where} {m.name}.{sig_name}: DBC {decoded[sig_name]!r}, "
                                f"C++ {cpp!r}")
        uncovered = set(o) - META - DERIVED - BY_ID - checked_keys
        if uncovered:
            problems.append(f"{m.name}: C++ fields {sorted(uncovered)} have no DBC signal")
        if len(problems) > 200:
            break

    if problems:
        unique = list(dict.fromkeys(problems))
        print(f"check_dbc: {len(unique)} disagreement(s) between {args.dbc} and the C++ codec:")
        for p in unique[:40]:
            print("  " + p)
        if len(unique) > 40:
            print(f"  ... and {len(unique) - 40} more")
        sys.exit(1)
    n_signals = sum(len(s) for s in covered_signals.values())
    print(f"check_dbc: OK: {len(messages)} DBC messages, {n_signals} signals, "
          f"{len(frames)} frames, {comparisons} signal comparisons with cantools "
          f"{cantools.__version__}; {0x800 - len(dbc_ids)} other standard IDs unknown to both")


if __name__ == "__main__":
    main()
