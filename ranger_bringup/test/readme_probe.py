#!/usr/bin/env python3
"""Waits until a ROS graph shows what a README command promises, for readme_commands.py.

    readme_probe.py TIMEOUT CONDITIONS_JSON

Runs against the master of ROS_MASTER_URI (its own process, so that each README session can have
a master of its own). CONDITIONS_JSON is a list of objects, each one of:
  {"node": NAME}                      the node is registered
  {"no_node": NAME}                   the node is not registered (checked once the rest hold)
  {"topic": T, "type": PKG/MSG, "field": F, "equals": V}
                                      the latest message's field F equals V
  {"topic": T, "type": PKG/MSG, "field": F, "in": [V...]}
                                      the latest message's field F is one of the values
  {"topic": T, "type": "diagnostic_msgs/DiagnosticArray", "names": [N...]}
                                      every status name N has been seen on T
  {"topic": T, "type": "diagnostic_msgs/DiagnosticArray", "status": N, "level": L,
   "message_contains": S}             status N was last reported at level L, its message naming S
  {"topic": T, "type": "nav_msgs/Odometry", "moved_more_than": M}
                                      the pose is farther than M (m) from the origin
  {"topic": T, "type": "nav_msgs/Odometry", "at_rest_within": M}
                                      the pose is within M of the origin (checked once the rest
                                      hold)
Exit status 0 when every condition holds within TIMEOUT seconds, 1 otherwise (the conditions
that did not hold are printed), 2 on bad arguments."""

import json
import math
import sys
import threading
import time


class TopicWatch:
    def __init__(self, topic, type_name):
        import rospy
        import roslib.message

        self.lock = threading.Lock()
        self.latest = None
        self.statuses = {}  # diagnostics: name -> (level, message)
        msg_class = roslib.message.get_message_class(type_name)
        if msg_class is None:
            raise SystemExit(f"readme_probe: unknown message type {type_name}")
        self.sub = rospy.Subscriber(topic, msg_class, self._on, queue_size=20)

    def _on(self, msg):
        with self.lock:
            self.latest = msg
            for s in getattr(msg, "status", []):
                self.statuses[s.name] = (int(s.level), s.message)


def field_of(msg, path):
    for part in path.split("."):
        msg = getattr(msg, part)
    return msg


def distance(msg):
    p = msg.pose.pose.position
    return math.hypot(p.x, p.y)


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    timeout = float(argv[1])
    conditions = json.loads(argv[2])

    import rosgraph
    import rospy

    end = time.monotonic() + timeout
    while not rosgraph.is_master_online():  # the launch under test may still be starting it
        if time.monotonic() > end:
            print(f"not within {timeout:g} s: a ROS master at {rosgraph.get_master_uri()}")
            return 1
        time.sleep(0.2)
    rospy.init_node("readme_probe", anonymous=True, disable_signals=True, disable_rosout=True)
    master = rosgraph.Master(rospy.get_name())
    watches = {}
    for c in conditions:
        if "topic" in c and c["topic"] not in watches:
            watches[c["topic"]] = TopicWatch(c["topic"], c["type"])

    def nodes():
        try:
            state = master.getSystemState()
        except Exception:  # noqa: BLE001 - the master may be starting or gone
            return set()
        return {n for group in state for _, members in group for n in members}

    def holds(c, final):
        if "node" in c:
            return c["node"] in nodes()
        if "no_node" in c:
            return not final or c["no_node"] not in nodes()
        w = watches[c["topic"]]
        with w.lock:
            msg, statuses = w.latest, dict(w.statuses)
        if "names" in c:
            return set(c["names"]) <= set(statuses)
        if "status" in c:
            level, message = statuses.get(c["status"], (None, ""))
            return level == c["level"] and c.get("message_contains", "") in message
        if msg is None:
            return False
        if "field" in c and "in" in c:
            return field_of(msg, c["field"]) in c["in"]
        if "field" in c:
            return field_of(msg, c["field"]) == c["equals"]
        if "moved_more_than" in c:
            return distance(msg) > c["moved_more_than"]
        if "at_rest_within" in c:
            return not final or distance(msg) <= c["at_rest_within"]
        raise SystemExit(f"readme_probe: unknown condition {c}")

    while True:
        if all(holds(c, final=False) for c in conditions):
            failed = [c for c in conditions if not holds(c, final=True)]
            if not failed:
                return 0
            break
        if time.monotonic() > end:
            failed = [c for c in conditions if not holds(c, final=False)]
            break
        time.sleep(0.1)
    for c in failed:
        print(f"not within {timeout:g} s: {json.dumps(c)}")
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
