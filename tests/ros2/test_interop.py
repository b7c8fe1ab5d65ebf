"""The monitor meets a real ROS 2 node: rclpy on Fast DDS (ROS 2's default middleware, from the
``ros-rclpy`` wheels in a venv of their own, cached between runs) publishes what a UR driver
does, with the driver's joint names in its order, and listens to the diagnoses. Everything runs
in a network namespace with loopback only. Skipped, with the reason, where the wheels cannot be
installed or no namespace can be made."""

from __future__ import annotations

import itertools
import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("cyclonedds", reason="the ROS 2 bridge needs cyclonedds: pip install '.[ros2]'")

from robohealth_mj.bags.joints import joint_names
from robohealth_mj.data.read import read_samples
from robohealth_mj.schema import FEATURE_NAMES, JOINT_NAMES

ROS_WHEELS = ("ros-rclpy[fastrtps]", "ros-sensor-msgs", "ros-diagnostic-msgs")
NODE = Path(__file__).with_name("ur_driver_node.py")
# 3 s at 20 Hz; studies/ros2/interop.sh runs it longer for the latency figure
TICKS = int(os.environ.get("ROBOHEALTH_INTEROP_TICKS", "60"))


@pytest.fixture(scope="session")
def ros_python() -> Path:
    """The Python of a venv holding the ROS 2 wheels (``$ROBOHEALTH_ROS_VENV``, default
    ``~/.cache/robohealth_mj/ros_venv``): they install a ``.pth`` hook, so never into ours."""
    venv = Path(os.environ.get("ROBOHEALTH_ROS_VENV",
                               Path.home() / ".cache" / "robohealth_mj" / "ros_venv"))  # fmt: skip
    python, ready = venv / "bin" / "python", venv / ".robohealth_installed"
    if not ready.is_file():
        done = subprocess.run([sys.executable, "-m", "venv", "--clear", str(venv)],
                              capture_output=True, text=True, timeout=120)  # fmt: skip
        if done.returncode == 0:
            done = subprocess.run([str(python), "-m", "pip", "install", "--quiet", *ROS_WHEELS],
                                  capture_output=True, text=True, timeout=600)  # fmt: skip
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ["no output"])[-1]
            pytest.skip(f"the ROS 2 wheels ({', '.join(ROS_WHEELS)}) cannot be installed: {last}")
        ready.touch()
    return python


def _namespace_or_skip() -> None:
    probe = subprocess.run(["unshare", "-n", "true"], capture_output=True, text=True)
    if probe.returncode != 0:
        pytest.skip(f"no network namespace can be made here (unshare -n: {probe.stderr.strip()})")


def _driver_ticks(path: Path) -> dict:
    """The recording's joint channels as the UR driver publishes them: its names (the node puts
    each arm's tf_prefix before them) listed alphabetically (elbow_joint first), every array in
    that order."""
    names = joint_names("ur_driver")
    order = sorted(range(len(names)), key=lambda k: names[k])
    column = {f: FEATURE_NAMES.index(f) for f in ("pos", "vel", "effort")}
    ticks = []
    for s in itertools.islice(read_samples(path), TICKS):
        joints = s.x[: len(JOINT_NAMES)]

        def values(feature: str, joints=joints) -> list[float]:
            return [float(joints[k, column[feature]]) for k in order]

        stamp = round(s.t * 1e9)
        ticks.append({"sec": stamp // 10**9, "nanosec": stamp % 10**9, "position": values("pos"),
                      "velocity": values("vel"), "effort": values("effort")})  # fmt: skip
    return {"names": [names[k] for k in order], "ticks": ticks}


def run_interop(model: Path, data: Path, ros_python: Path, work: Path, arms: list[str]) -> dict:
    """The monitor (default settings, ``ros2.layout=ur_driver``) and the rclpy node publishing
    ``data``'s first ``TICKS`` ticks for each of ``arms``, in a network namespace with loopback
    only; what the node heard (``latency_ms``: per diagnosis) and the monitor's output."""
    ticks = work / "ticks.json"
    ticks.write_text(json.dumps(_driver_ticks(data)))
    heard, log = work / "heard.json", work / "monitor.log"
    monitor = [sys.executable, "-m", "robohealth_mj.monitor", f"model={model}", "source=ros2",
               "duration_s=0", "ros2.interface=127.0.0.1", f"ros2.arms=[{','.join(arms)}]",
               "ros2.layout=ur_driver", "ros2.tf_prefix='{arm}_'"]  # fmt: skip
    script = (
        "set -e; ip link set lo up; ip link set lo multicast on; "
        "ip route add 224.0.0.0/4 dev lo; "
        f"{shlex.join(monitor)} > {log} 2>&1 & monitor=$!; "
        f"{ros_python} {NODE} {ticks} {heard} {' '.join(arms)}; kill -TERM $monitor; "
        "wait $monitor"
    )
    done = subprocess.run(["unshare", "-n", "bash", "-c", script], capture_output=True,
                          text=True, timeout=180)  # fmt: skip
    output = log.read_text() if log.is_file() else ""
    assert done.returncode == 0, done.stderr[-2000:] + output[-2000:]
    return {"output": output, **json.loads(heard.read_text())}


@pytest.mark.slow
def test_a_fastdds_node_with_the_ur_driver_s_names_is_diagnosed_by_default(
    joint_states_deployed, ros_python, tmp_path
):
    """Default middleware settings on both sides, two arms with the UR driver's names, prefixes
    and order on /joint_states alone (a model of the reduced joint_states profile, so no
    controller state is awaited): every tick is diagnosed, and the node receives every
    diagnosis and /diagnostics."""
    _namespace_or_skip()
    arms = ["arm1", "arm2"]
    got = run_interop(joint_states_deployed["onnx"], Path(joint_states_deployed["heldout"]),
                      ros_python, tmp_path, arms)  # fmt: skip
    for arm in arms:
        assert f"{arm}: {TICKS} samples diagnosed, 0 bad inputs, 0 late" in got["output"], got[
            "output"
        ][-2000:]
        assert got[arm] == TICKS
    assert got["published"] == TICKS and got["diagnostics"] >= 1
    latency = sorted(got["latency_ms"])
    assert len(latency) == len(arms) * TICKS
    print(f"diagnosis latency over {len(latency)}: median {latency[len(latency) // 2]:.1f} ms, "
          f"p99 {latency[int(0.99 * (len(latency) - 1))]:.1f} ms")  # fmt: skip
