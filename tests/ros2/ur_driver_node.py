"""The other end of the interop test (``test_interop.py``), run by the ROS 2 wheels' own Python:
a real rclpy node on Fast DDS that publishes what a UR ROS 2 driver does (``/<arm>/joint_states``
with the driver's joint names in its alphabetical order, and the tracking error) at 20 Hz, and
listens to the monitor's ``/diagnostics`` and ``/<arm>/health_diagnosis``.

    python ur_driver_node.py TICKS.json ARM OUT.json
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from sensor_msgs.msg import JointState


def main() -> None:
    with open(sys.argv[1]) as f:
        ticks = json.load(f)
    arm, out = sys.argv[2], sys.argv[3]
    rclpy.init()
    node = Node("ur_driver_stand_in")
    states = node.create_publisher(JointState, f"/{arm}/joint_states", 10)
    errors = node.create_publisher(JointState, f"/{arm}/joint_tracking_error", 10)
    heard = {"diagnostics": 0, "health_diagnosis": 0}

    def count(key: str):
        return lambda _msg: heard.__setitem__(key, heard[key] + 1)

    node.create_subscription(DiagnosticArray, "/diagnostics", count("diagnostics"), 10)
    diagnoses = node.create_subscription(DiagnosticArray, f"/{arm}/health_diagnosis",
                                         count("health_diagnosis"), 100)  # fmt: skip
    deadline = time.monotonic() + 60.0  # discovery: until the monitor is matched both ways
    while time.monotonic() < deadline and not (
        states.get_subscription_count()
        and errors.get_subscription_count()
        and diagnoses.get_publisher_count()
    ):
        rclpy.spin_once(node, timeout_sec=0.05)
    settled = time.monotonic() + 2.0  # our side has matched; give the monitor's readers
    while time.monotonic() < settled:  # time to match ours, or the first ticks go to nobody
        rclpy.spin_once(node, timeout_sec=0.05)
    for tick in ticks["ticks"]:
        for publisher, fields in ((states, ("position", "velocity", "effort")),
                                  (errors, ("pos_error", "effort_residual"))):  # fmt: skip
            msg = JointState()
            msg.header.stamp.sec, msg.header.stamp.nanosec = tick["sec"], tick["nanosec"]
            msg.name = ticks["names"]
            msg.position = tick[fields[0]]
            if publisher is states:
                msg.velocity, msg.effort = tick["velocity"], tick["effort"]
            else:
                msg.effort = tick[fields[1]]
            publisher.publish(msg)
        deadline = time.monotonic() + 0.05
        while time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.01)
    deadline = time.monotonic() + 30.0  # every diagnosis back, and a /diagnostics period
    while time.monotonic() < deadline and (
        heard["health_diagnosis"] < len(ticks["ticks"]) or not heard["diagnostics"]
    ):
        rclpy.spin_once(node, timeout_sec=0.05)
    with open(out, "w") as f:
        json.dump({"published": len(ticks["ticks"]), **heard}, f)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
