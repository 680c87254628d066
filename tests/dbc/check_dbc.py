#!/usr/bin/python3
"""Cross-checks one of libranger_can/dbc/ranger_<revision>.dbc against the C++ codec.

Payloads for every message in the DBC (edge patterns, random bytes, and random values inside
each signal's range) are written to a candump log, decoded by `ranger_can decode --json
--protocol REVISION` and by cantools (installed from PyPI into a virtual environment this script
creates, or reuses), and every signal is compared with the C++ field it describes. Also checked:
the DBC's messages are the frame table's of the revision (protocol.hpp's kFrameTable, parsed
here: identifiers, the revision's column of lengths, sender, GenMsgCycleTime = the nominal
period); the DBC and the codec
know the same IDs with the same lengths (a DBC length longer than the
codec's layout shows as extra bytes, a shorter one as an error); every JSON field the codec prints
for a frame is covered by some DBC signal (or is one the revision leaves reserved); a steering
angle outside the DBC's stated range is refused by the codec as impossible content, one inside it
is decoded.

Then the planted-mistake self-check: the same comparison against copies of the DBC with one
mistake planted each (a wrong scale, a flipped sign, two error bits swapped, a missing signal)
must report disagreements; a check that misses one of them proves nothing.

usage: check_dbc.py --cli PATH/ranger_can --dbc ranger_REV.dbc --protocol REV --venv DIR
                    --work DIR [--other-dbc ranger_OTHER.dbc ...] [--frames N]
Exit status 0 when everything agrees, 1 on any disagreement (each one printed), 2 on set-up errors.
"""
import argparse
import json
import math
import os
import random
import re
import subprocess
import sys

IN_VENV_FLAG = "--in-venv"
# The revisions in the order of the frame table's length columns (profile.hpp's FrameLayout).
REVISIONS = ("manual", "agx_v2", "mini_v3")


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    checking = "--venv-only" not in argv  # the checks' arguments are needed only to check
    p.add_argument("--cli", required=checking, help="the ranger_can executable")
    p.add_argument("--dbc", required=checking, help="the DBC file to check")
    p.add_argument("--protocol", required=checking, choices=list(REVISIONS),
                   help="the protocol revision the DBC describes (ranger_can --protocol)")
    p.add_argument("--other-dbc", action="append", default=[],
                   help="another revision's DBC (repeatable): its IDs that this DBC does not "
                   "list are known to the codec under every profile and are not checked here")
    p.add_argument("--venv", required=True, help="virtual environment for cantools (created if absent)")
    p.add_argument("--venv-only", action="store_true",
                   help="only create or complete the virtual environment, then exit (scripts/test.sh "
                        "does it beside its first build)")
    p.add_argument("--work", required=checking, help="directory for the generated log")
    p.add_argument("--frames", type=int, default=400, help="random payloads per message")
    p.add_argument("--frame-table", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "libranger_can", "include",
        "ranger_can", "wire", "protocol.hpp"), help="the header holding the frame table")
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
    if args.venv_only:
        sys.exit(0)
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


# How a revision's steering angles relate to the codec's convention (rad, positive = right):
# the manual's are positive right, agx_v2's and mini_v3's positive left.
STEERING_SIGN = {"manual": 1.0, "agx_v2": -1.0, "mini_v3": -1.0}


def angle_of(key, unit, sign, index=None):
    """DBC in degrees or radians with the revision's sign, C++ in radians, positive right."""
    def rule(v, o):
        c = o[key] if index is None else o[key][index]
        rad = math.radians(v) if unit == "deg" else v
        return c, close(sign * rad, c)
    rule.keys = {key}
    return rule


def flag(key):
    def rule(v, o):
        return o[key], o[key] is (v != 0)
    rule.keys = {key}
    return rule


def bit_named(list_key, name, inverted=False):
    """A 1-bit signal whose C++ side is a name in a list (present when the bit is set, or when it
    is clear for an inverted bit)."""
    def rule(v, o):
        present = name in o[list_key]
        return present, present == ((v != 0) != inverted)
    rule.keys = {list_key}
    return rule


def odometer_m(key_m, key_raw):
    """A distance in metres (the MINI 3.0's odometers): the codec's metres, and its raw value the
    same distance in millimetres."""
    def rule(v, o):
        c = o.get(key_m)
        ok = isinstance(c, (int, float)) and close(v, c) and o.get(key_raw) == round(v * 1000)
        return c, ok
    rule.keys = {key_m, key_raw}
    return rule


def version_char(i):
    """0x4A1: char_i of the DBC against the C++ text (trailing NUL bytes are padding), or the
    request (byte 0 = 0x01, nothing else)."""
    def rule(v, o):
        if o.get("request"):
            return "request", v == (1 if i == 0 else 0)
        text = o.get("text", "")
        c = ord(text[i]) if i < len(text) else 0
        return c, c == v
    rule.keys = {"text", "request"}
    return rule


WHEELS = ["front_right", "rear_right", "rear_left", "front_left"]
# JSON fields that describe the frame rather than a signal, or are derived from other fields.
META = {"t", "iface", "id", "name", "dlc", "data"}
DERIVED = {"mode_name", "vehicle_status_name", "control_mode_name", "description", "critical",
           "status", "error_bits", "driver_status", "alarm1", "alarm2", "warning1", "warning2",
           "front_mode_name", "rear_mode_name", "swa_name", "swb_name", "swc_name", "swd_name",
           "drive_mode_name"}
# Fields that are not carried by a signal but by the frame ID (checked separately).
BY_ID = {"motor", "battery", "first_sensor", "axle"}
# Fields the codec reads under every profile that a revision leaves reserved (and its DBC does
# not describe): agx_v2's yaw rate and lateral speed in the manual's reserved bytes.
RESERVED = {"manual": {"motion_command": {"yaw_rate"},
                       "motion_feedback": {"yaw_rate", "lateral_speed"}},
            "agx_v2": {},
            # The MINI 3.0: 0x111 bytes 4-5 zero, 0x221's lateral speed reserved (zero), the
            # lights' bytes 2-7 (0x231: 2-6) reserved.
            "mini_v3": {"motion_command": {"spin_speed"},
                        "motion_feedback": {"lateral_speed"},
                        "light_command": {"front_custom", "rear_mode", "rear_custom", "counter"},
                        "light_state": {"front_custom", "rear_mode", "rear_custom"}}}
# Signals whose DBC range is the plausible range: outside it the codec refuses the frame.
PLAUSIBLE = {"MotionFeedback": {"steering_angle"},
             "SteeringAngles": {f"angle_{w}" for w in WHEELS}}
IMPOSSIBLE = "beyond any model's reach"


def rules_for(message, revision):
    """(expected C++ frame name, {signal name: rule}, {C++ key: expected value from the ID})."""
    n = message.name
    sigs = [s.name for s in message.signals]
    unit = {s.name: s.unit for s in message.signals}
    sign = STEERING_SIGN[revision]
    if n == "MotionCommand":
        rules = {"linear_speed": same("linear_speed"),
                 "steering_angle": angle_of("steering_angle", unit.get("steering_angle"), sign)}
        if "spin_speed" in sigs:
            rules["spin_speed"] = same("spin_speed")
        if "lateral_speed" in sigs:  # agx_v2's name for bytes 4-5 (the manual's spin speed)
            rules["lateral_speed"] = same("spin_speed")
        if "yaw_rate" in sigs:
            rules["yaw_rate"] = same("yaw_rate")
        return "motion_command", rules, {}
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
        if "counter" in sigs:
            rules["counter"] = same("counter")
        for s in message.signals:
            if s.length == 1:
                rules[s.name] = bit_named("errors", s.name)
        return "system_status", rules, {}
    if n == "MotionFeedback":
        rules = {"speed": same("speed"),
                 "steering_angle": angle_of("steering_angle", unit.get("steering_angle"), sign)}
        for k in ("yaw_rate", "lateral_speed"):
            if k in sigs:
                rules[k] = same(k)
        return "motion_feedback", rules, {}
    if n.startswith("MotorHighSpeed"):
        return "motor_high_speed", {"rpm": same("rpm"), "current": same("current"),
                                    "position": same("position")}, {"motor": int(n[-1])}
    if n.startswith("MotorLowSpeed"):
        rules = {"driver_voltage": same("driver_voltage"),
                 "driver_temperature": same("driver_temperature"),
                 "motor_temperature": same("motor_temperature")}
        for s in message.signals:
            if s.name == "driver_enabled":  # agx_v2: the codec reports the manual's disabled bit
                rules[s.name] = bit_named("driver_status_names", "driver_disabled", inverted=True)
            elif s.length == 1:
                rules[s.name] = bit_named("driver_status_names", s.name)
        return "motor_low_speed", rules, {"motor": int(n[-1])}
    if n == "SteeringAngles":
        return "steering_angles", {f"angle_{w}": angle_of("angles", unit[f"angle_{w}"], sign, i)
                                   for i, w in enumerate(WHEELS)}, {}
    if n == "WheelSpeeds":
        return "wheel_speeds", {f"speed_{w}": same("speeds", i) for i, w in enumerate(WHEELS)}, {}
    if n == "MotionModeFeedback":
        rules = {"mode": same("mode"), "switching": flag("switching")}
        if "drive_mode" in sigs:  # the MINI 3.0's third byte
            rules["drive_mode"] = same("drive_mode")
        return "motion_mode", rules, {}
    if n == "DriveModeCommand":
        return "drive_mode_command", {"mode": same("mode")}, {}
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
    if n in ("LightCommand", "LightState"):
        rules = {"enable": flag("enable")}
        rules.update({k: same(k) for k in ("front_mode", "front_custom", "rear_mode",
                                           "rear_custom", "counter") if k in sigs})
        return ("light_command" if n == "LightCommand" else "light_state"), rules, {}
    if n == "RemoteControlState":
        return "remote_control", {s: same(s) for s in sigs}, {}
    if n in ("Odometer", "RearOdometer"):
        name, axle = ("odometer", "front") if n == "Odometer" else ("rear_odometer", "rear")
        if "left_distance" in sigs:  # in metres (the MINI 3.0's mm)
            return name, {"left_distance": odometer_m("left_distance", "left_wheel"),
                          "right_distance": odometer_m("right_distance", "right_wheel")}, \
                {"axle": axle}
        return name, {"left_wheel": same("left_wheel"),
                      "right_wheel": same("right_wheel")}, {"axle": axle}
    if n == "Version":
        return "version", {f"char_{i}": version_char(i) for i in range(8)}, {}
    return None, {}, {}


# ---- the frames -------------------------------------------------------------------------------

def in_range_payload(m, rng):
    """A payload whose every signal holds a random raw value inside the DBC's range."""
    values = {}
    for s in m.signals:
        lo = math.ceil((s.minimum - s.offset) / s.scale - 1e-9)
        hi = math.floor((s.maximum - s.offset) / s.scale + 1e-9)
        values[s.name] = rng.randint(lo, hi) * s.scale + s.offset
    return m.encode(values, scaling=True, strict=False)


def payloads(m, count, rng):
    length = m.length
    edge = [bytes([0x00] * length), bytes([0xFF] * length), bytes([0x80] + [0x00] * (length - 1)),
            bytes([0x7F] + [0xFF] * (length - 1)), bytes(([0x80, 0x00] * 4)[:length]),
            bytes(([0x7F, 0xFF] * 4)[:length]), bytes(([0x55, 0xAA] * 4)[:length])]
    raw = [bytes(rng.getrandbits(8) for _ in range(length)) for _ in range(count // 2)]
    ranged = [bytes(in_range_payload(m, rng)) for _ in range(count - count // 2)]
    return edge + raw + ranged


# ---- the comparison ---------------------------------------------------------------------------

def compare(db, frames, lines, revision):
    """Every disagreement between `db` and the codec's JSON `lines` for `frames`."""
    problems = []
    comparisons = 0
    covered_signals = {}
    refused = 0
    by_id = {m.frame_id: m for m in db.messages}
    for (fid, payload), line in zip(frames, lines):
        o = json.loads(line)
        where = f"ID 0x{fid:03X} data {payload.hex().upper()}"
        if o["id"] != fid:
            problems.append(f"{where}: JSON line is for ID {o['id']}")
            continue
        m = by_id.get(fid)
        if m is None:
            if o["name"] != "unknown":
                problems.append(f"{where}: not in the DBC, but the codec calls it '{o['name']}'")
            continue
        if "extra_bytes" in o:
            problems.append(f"{where} ({m.name}): the DBC's length {m.length} exceeds the codec's "
                            f"layout by {o['extra_bytes']} byte(s)")
            continue
        decoded = m.decode(payload, decode_choices=False, scaling=True)
        implausible = [s for s in sorted(PLAUSIBLE.get(m.name, ()))
                       if s in decoded and not (m.get_signal_by_name(s).minimum - 1e-9
                                                <= decoded[s]
                                                <= m.get_signal_by_name(s).maximum + 1e-9)]
        if implausible:
            if IMPOSSIBLE not in o.get("error", ""):
                problems.append(f"{where} ({m.name}): {implausible[0]} = "
                                f"{decoded[implausible[0]]!r} is outside the DBC's range, but the "
                                f"codec says {o.get('error', 'nothing')!r}")
            refused += 1
            continue
        if "error" in o:
            problems.append(f"{where} ({m.name}, DLC {m.length} in the DBC): codec says {o['error']}")
            continue
        expected_name, rules, by_id_keys = rules_for(m, revision)
        if expected_name is None:
            problems.append(f"{m.name}: no rule in check_dbc.py for this DBC message")
            continue
        if o["name"] != expected_name:
            problems.append(f"{where}: DBC message {m.name}, codec name '{o['name']}'")
        for key, value in by_id_keys.items():
            if o.get(key) != value:
                problems.append(f"{where}: {key} = {o.get(key)}, expected {value} from the ID")
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
            try:
                cpp, ok = rule(decoded[sig_name], o)
            except (KeyError, IndexError, TypeError) as e:
                cpp, ok = f"<{e!r}>", False
            comparisons += 1
            covered_signals.setdefault(m.name, set()).add(sig_name)
            if not ok:
                problems.append(f"{where} {m.name}.{sig_name}: DBC {decoded[sig_name]!r}, "
                                f"C++ {cpp!r}")
        reserved = RESERVED[revision].get(expected_name, set())
        uncovered = set(o) - META - DERIVED - BY_ID - checked_keys - reserved
        if uncovered:
            problems.append(f"{m.name}: C++ fields {sorted(uncovered)} have no DBC signal")
        if len(problems) > 200:
            break
    return problems, comparisons, covered_signals, refused


# ---- planted mistakes -------------------------------------------------------------------------

def block_of(text, frame_id):
    """(start, end) of the BO_ block of `frame_id` in the DBC text."""
    start = text.index(f"BO_ {frame_id} ")
    end = text.find("\n\n", start)
    return start, (len(text) if end < 0 else end)


def plant_scale(text):
    """The BMS pack voltage with the other revision's scale (0.01 <-> 0.1 V)."""
    a, b = block_of(text, 0x361)
    block = text[a:b]
    new = re.sub(r"(SG_ voltage : \d+\|16@0\+ )\((0\.01|0\.1),0\)",
                 lambda m: m.group(1) + ("(0.1,0)" if m.group(2) == "0.01" else "(0.01,0)"), block)
    return text[:a] + new + text[b:]


def plant_sign(text):
    """0x221's steering angle with the opposite sign."""
    a, b = block_of(text, 0x221)
    block = text[a:b]
    new = re.sub(r"(SG_ steering_angle : \d+\|16@0- )\(([0-9.]+),0\) \[([-0-9.]+)\|([-0-9.]+)\]",
                 lambda m: f"{m.group(1)}(-{m.group(2)},0) [{m.group(3)}|{m.group(4)}]", block)
    return text[:a] + new + text[b:]


def plant_swapped_bits(text):
    """The first two error bits of 0x211 with each other's names."""
    a, b = block_of(text, 0x211)
    block = text[a:b]
    names = re.findall(r"SG_ (\w+) : \d+\|1@", block)
    x, y = names[0], names[1]
    new = block.replace(f"SG_ {x} :", "SG_ @@ :").replace(f"SG_ {y} :", f"SG_ {x} :")
    new = new.replace("SG_ @@ :", f"SG_ {y} :")
    return text[:a] + new + text[b:]


def plant_missing_signal(text):
    """0x221 without its speed signal."""
    a, b = block_of(text, 0x221)
    block = "\n".join(l for l in text[a:b].split("\n") if not l.startswith(" SG_ speed :"))
    return text[:a] + block + text[b:]


PLANTED = [("BMS voltage scale of the other revision", plant_scale),
           ("0x221 steering sign flipped", plant_sign),
           ("two 0x211 error bits swapped", plant_swapped_bits),
           ("0x221 speed signal missing", plant_missing_signal)]


# ---- main -------------------------------------------------------------------------------------

# ---- the frame table ----------------------------------------------------------------------------

def frame_table(header):
    """kFrameTable of protocol.hpp, one entry per identifier: {id: row}."""
    with open(header) as f:
        text = f.read()
    consts = {m.group(1): int(m.group(2), 0) for m in re.finditer(
        r"inline constexpr (?:std::uint32_t|std::uint8_t|int) (k\w+) = (0x[0-9A-Fa-f]+|\d+);", text)}
    start = text.index("kFrameTable[] = {")
    body = text[start:text.index("};", start)]
    row_re = re.compile(r'\{([^{}",]+),\s*([^,]+),\s*(\d+),\s*"(\w+)",\s*Direction::k(\w+),'
                        r'\s*(\d+),\s*\{([\d, ]+)\}\}')
    table = {}
    for m in row_re.finditer(body):
        first = eval(m.group(1), {}, dict(consts))  # our own source: constants and + only
        count = eval(m.group(2), {}, dict(consts))
        stride = int(m.group(3))
        lengths = [int(w) for w in m.group(7).split(",")]
        if len(lengths) != len(REVISIONS):
            die(f"{header}: row {m.group(4)} has {len(lengths)} lengths, not one per revision "
                f"({', '.join(REVISIONS)})")
        row = {"name": m.group(4), "direction": m.group(5), "period": int(m.group(6)),
               "lengths": lengths}
        for i in range(count):
            table[first + i * stride] = row
    if not table:
        die(f"no frame table found in {header}")
    return table


def check_frame_table(messages, table, protocol):
    """The DBC's messages against the frame table's frames of `protocol` (its column of lengths)."""
    column = REVISIONS.index(protocol)
    expected = {i: dict(r, length=r["lengths"][column]) for i, r in table.items()
                if r["lengths"][column] > 0}
    senders = {"ToChassis": "Host", "FromChassis": "Chassis"}
    problems = []
    for m in messages:
        r = expected.get(m.frame_id)
        where = f"ID 0x{m.frame_id:03X} {m.name}"
        if r is None:
            problems.append(f"{where}: in the DBC, not a {protocol} frame of the frame table")
            continue
        sender = m.senders[0] if m.senders else ""
        if r["direction"] in senders and sender != senders[r["direction"]]:
            problems.append(f"{where}: sent by {sender} in the DBC, {r['direction']} in the table")
        if r["direction"] != "Both" and m.length != r["length"]:
            problems.append(f"{where}: length {m.length} in the DBC, {r['length']} in the table")
        if (m.cycle_time or 0) != r["period"]:
            problems.append(f"{where}: GenMsgCycleTime {m.cycle_time or 0} in the DBC, period "
                            f"{r['period']} ms in the table")
    dbc_ids = {m.frame_id for m in messages}
    for i, r in sorted(expected.items()):
        if i not in dbc_ids:
            problems.append(f"ID 0x{i:03X} ({r['name']}): a {protocol} frame of the table, not in "
                            f"the DBC")
    return problems


def main():
    args = parse_args(sys.argv[1:])
    if not args.in_venv:
        ensure_venv_and_reexec(args)
    import cantools  # noqa: E402  (only inside the virtual environment)

    with open(args.dbc) as f:
        dbc_text = f.read()
    db = cantools.database.load_string(dbc_text)  # strict: overlapping signals are refused
    rng = random.Random(args.seed)
    messages = sorted(db.messages, key=lambda m: m.frame_id)
    other_ids = set()
    for other in args.other_dbc:
        other_ids |= {m.frame_id for m in cantools.database.load_file(other).messages}

    table_problems = check_frame_table(messages, frame_table(args.frame_table), args.protocol)
    if table_problems:
        print(f"check_dbc: {len(table_problems)} disagreement(s) between {args.dbc} and the frame "
              f"table ({args.frame_table}):")
        for p in table_problems:
            print("  " + p)
        sys.exit(1)

    frames = []  # (id, payload)
    for m in messages:
        for p in payloads(m, args.frames, rng):
            frames.append((m.frame_id, p))
    dbc_ids = {m.frame_id for m in messages}
    skipped = other_ids - dbc_ids
    for other in range(0x800):  # every other standard ID must be unknown to the codec as well
        if other not in dbc_ids and other not in skipped:
            frames.append((other, bytes(rng.getrandbits(8) for _ in range(8))))

    os.makedirs(args.work, exist_ok=True)
    log_path = os.path.join(args.work, f"dbc_check_{args.protocol}.log")
    with open(log_path, "w") as f:
        for i, (fid, p) in enumerate(frames):
            f.write(f"({1700000000 + i // 1000}.{i % 1000:06d}) can0 {fid:03X}#{p.hex().upper()}\n")
    cmd = [args.cli, "decode", "--json", "--protocol", args.protocol, log_path]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0 or r.stderr:
        die(f"'{' '.join(cmd)}' failed (exit {r.returncode}): {r.stderr}", 1)
    lines = r.stdout.splitlines()
    if len(lines) != len(frames):
        die(f"{len(frames)} frames in, {len(lines)} JSON lines out", 1)

    problems, comparisons, covered, refused = compare(db, frames, lines, args.protocol)
    if problems:
        unique = list(dict.fromkeys(problems))
        print(f"check_dbc: {len(unique)} disagreement(s) between {args.dbc} and the C++ codec "
              f"(--protocol {args.protocol}):")
        for p in unique[:40]:
            print("  " + p)
        if len(unique) > 40:
            print(f"  ... and {len(unique) - 40} more")
        sys.exit(1)

    # The self-check: every planted mistake must be caught.
    missed = []
    for what, plant in PLANTED:
        mutated = plant(dbc_text)
        if mutated == dbc_text:
            missed.append(f"{what}: could not be planted in {args.dbc}")
            continue
        found, _, _, _ = compare(cantools.database.load_string(mutated), frames, lines,
                                 args.protocol)
        if not found:
            missed.append(f"{what}: not noticed")
        else:
            print(f"check_dbc: self-check: planted mistake '{what}' caught "
                  f"({len(set(found))} disagreement(s))")
    if missed:
        print("check_dbc: the self-check failed; the comparison cannot be trusted:")
        for m in missed:
            print("  " + m)
        sys.exit(1)

    n_signals = sum(len(s) for s in covered.values())
    print(f"check_dbc: OK: {args.dbc} (--protocol {args.protocol}): {len(messages)} DBC messages, "
          f"{n_signals} signals, {len(frames)} frames ({refused} refused as impossible, as the "
          f"DBC's ranges say), {comparisons} signal comparisons with cantools "
          f"{cantools.__version__}; {0x800 - len(dbc_ids) - len(skipped)} other standard IDs "
          f"unknown to both, {len(skipped)} of the other revision not checked here; "
          f"{len(PLANTED)} planted mistakes caught")


if __name__ == "__main__":
    main()
