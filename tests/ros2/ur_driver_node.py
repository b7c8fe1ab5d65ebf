"""The other end of the interop test (``test_interop.py``), run by the ROS 2 wheels' own Python:
a real rclpy node on Fast DDS that publishes what the UR ROS 2 driver does for each arm
(``/<arm>/joint_states`` with the driver's joint names, its tf_prefix and its alphabetical order)
at 20 Hz, and listens to the monitor's ``/diagnostics`` and ``/<arm>/health_diagnosis``. It
writes what it heard and each diagnosis's latency (received minus published, by stamp).

    python ur_driver_node.py TICKS.json OUT.json ARM [ARM ...]
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
    out, arms = sys.argv[2], sys.argv[3:]
    rclpy.init()
    node = Node("ur_driver_stand_in")
    heard = {"diagnostics": 0, **{arm: 0 for arm in arms}}
    sent: dict[tuple[str, int], float] = {}  # (arm, stamp ns) -> when published
    latency_ms: list[float] = []

    def diagnosis(arm: str):
        def on(msg: DiagnosticArray) -> None:
            now = time.monotonic()
            heard[arm] += 1
            stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
            if (arm, stamp) in sent:
                latency_ms.append((now - sent[arm, stamp]) * 1e3)

        return on

    def count(_msg: DiagnosticArray) -> None:
        heard["diagnostics"] += 1

    node.create_subscription(DiagnosticArray, "/diagnostics", count, 10)
    states = {arm: node.create_publisher(JointState, f"/{arm}/joint_states", 10) for arm in arms}
    diagnoses = [node.create_subscription(DiagnosticArray, f"/{arm}/health_diagnosis",
                                          diagnosis(arm), 100) for arm in arms]  # fmt: skip
    deadline = time.monotonic() + 60.0  # discovery: until the monitor is matched both ways
    while time.monotonic() < deadline and not (
        all(p.get_subscription_count() for p in states.values())
        and all(d.get_publisher_count() for d in diagnoses)
    ):
        rclpy.spin_once(node, timeout_sec=0.05)
    settled = time.monotonic() + 2.0  # our side has matched; give the monitor's readers
    while time.monotonic() < settled:  # time to match ours, or the first ticks go to nobody
        rclpy.spin_once(node, timeout_sec=0.05)
    start = time.monotonic()
    for k, tick in enumerate(ticks["ticks"]):
        for arm in arms:
            msg = JointState()
            msg.header.stamp.sec, msg.header.stamp.nanosec = tick["sec"], tick["nanosec"]
            msg.name = [f"{arm}_{name}" for name in ticks["names"]]
            msg.position, msg.velocity, msg.effort = (
                tick["position"],
                tick["velocity"],
                tick["effort"],
            )
            sent[arm, tick["sec"] * 10**9 + tick["nanosec"]] = time.monotonic()
            states[arm].publish(msg)
        while time.monotonic() < start + (k + 1) * 0.05:  # 20 Hz, listening meanwhile
            rclpy.spin_once(node, timeout_sec=0.005)
    deadline = time.monotonic() + 30.0  # every diagnosis back, and a /diagnostics period
    while time.monotonic() < deadline and (
        min(heard[arm] for arm in arms) < len(ticks["ticks"]) or not heard["diagnostics"]
    ):
        rclpy.spin_once(node, timeout_sec=0.05)
    with open(out, "w") as f:
        json.dump({"published": len(ticks["ticks"]), **heard, "latency_ms": latency_ms}, f)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
