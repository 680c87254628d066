#!/usr/bin/env python3
"""Keeps ros2/ranger_msgs the same interfaces as the ROS 1 package ranger_msgs/.

The ROS 2 files are the ROS 1 files with the one change ROS 2's IDL needs: the built-in `time`
and `duration` field types become builtin_interfaces/Time and builtin_interfaces/Duration.
Everything else (fields, constants, comments) is copied as it is.

    sync_interfaces.py            writes ros2/ranger_msgs/{msg,srv} from ranger_msgs/
    sync_interfaces.py --check    exit 1, naming each file, when they differ (the ros2 stage's test)
"""
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROS1 = os.path.join(HERE, os.pardir, os.pardir, "ranger_msgs")
BUILTIN = {"time": "builtin_interfaces/Time", "duration": "builtin_interfaces/Duration"}


def to_ros2(text):
    def field(match):
        indent, type_, array, rest = match.groups()
        return indent + BUILTIN.get(type_, type_) + (array or "") + rest
    return "\n".join(re.sub(r"^(\s*)([A-Za-z_][\w/]*)(\[[^\]]*\])?(\s+\w.*)$", field, line)
                     if not line.lstrip().startswith("#") else line
                     for line in text.split("\n"))


def expected():
    out = {}
    for kind in ("msg", "srv"):
        for name in sorted(os.listdir(os.path.join(ROS1, kind))):
            with open(os.path.join(ROS1, kind, name), encoding="utf-8") as f:
                out[os.path.join(kind, name)] = to_ros2(f.read())
    return out


def main(argv):
    check = "--check" in argv
    want = expected()
    differ = []
    for kind in ("msg", "srv"):
        present = set(os.listdir(os.path.join(HERE, kind))) if os.path.isdir(
            os.path.join(HERE, kind)) else set()
        for name in present:
            if os.path.join(kind, name) not in want:
                differ.append(f"{kind}/{name}: not in ranger_msgs/{kind}")
    for rel, text in want.items():
        path = os.path.join(HERE, rel)
        have = open(path, encoding="utf-8").read() if os.path.exists(path) else None
        if have == text:
            continue
        if check:
            differ.append(f"{rel}: differs from ranger_msgs/{rel} (run {os.path.basename(__file__)})")
        else:
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
    for d in differ:
        print(d, file=sys.stderr)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
