"""ROS 2 over DDS on loopback: arms per monitor process at 20 Hz with no message lost, and the
latency from a robot's publish to the diagnosis on ``/diagnostics``.

Publishers run in a child process (replaying a recording, stamps set to the wall clock at publish,
so the monitor reads each sample's age directly); the monitors run in their own processes, each
a share of the arms (scale-out: ``--monitors 1 2``). ``--layouts ur_driver``: the UR driver's
topics at the controller's rate (``--driver-hz``, 500), 25 joint and 25 controller states an arm
per model tick. CPU is reported apart
for each side (process time over wall time, in cores). ``--graphs open secured``: each row on an
open graph and on an SROS2-secured one (a keystore made for the run: the robot's and the
monitor's enclaves with their grants, the default governance: encrypted and signed), one after
the other in the same run."""

from __future__ import annotations

import itertools
import multiprocessing as mp
import tempfile
import time
from typing import Any

import numpy as np

# messages an arm sends per 20 Hz tick (ur_driver: per controller cycle, joint and controller state)
MESSAGES_PER_TICK = {"per_sensor": 15, "aggregated": 2, "joints": 3, "ur_driver": 2}


def _publisher(
    domain: int, arms: int, samples: list, seconds: float, layout: str, ready, go, out,
    security=None, driver_hz: float = 500.0,
) -> None:  # fmt: skip
    from robohealth_mj.ros2.bus import Bus, BusConfig
    from robohealth_mj.ros2.node import ArmPublisher

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1", depth=50, security=security))
    from robohealth_mj.bags.topics import BagTopics

    pubs = [ArmPublisher(bus, f"arm{k + 1}", layout=layout) for k in range(arms)]
    topics = BagTopics.load()
    ready.set()
    go.wait()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    ticks = int(seconds * 20)
    # the UR driver's layout: joint states and controller states at the controller's rate
    # (driver_hz), stamped on the controller's schedule as a driver stamps its cycles (a late
    # publisher then shows as latency, and the monitor's tick grid holds `ticks` ticks); the
    # others: one sample's messages a tick, stamped when sent
    driver = layout == "ur_driver"
    per_tick = max(1, round(driver_hz / 20)) if driver else 1
    epoch0 = time.time()
    for step in range(ticks * per_tick):
        due = wall0 + step / (20.0 * per_tick)
        delay = due - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        base = samples[step // per_tick % len(samples)]
        stamp = epoch0 + step / (20.0 * per_tick) if driver else time.time()
        sample = base.__class__("bench", step, stamp, base.x, base.fault, base.segment)
        built = pubs[0].serialized([m for _, m in pubs[0].messages(sample, topics)])  # stamped now
        for pub in pubs:
            pub.publish_serialized(built)
    out.put(
        {
            "ticks": ticks,
            "cpu_cores": (time.process_time() - cpu0) / (time.perf_counter() - wall0),
            "late_s": max(0.0, time.perf_counter() - (wall0 + ticks / 20.0)),
        }
    )
    time.sleep(1.0)


def _monitor(
    domain: int, model: str, arms: list[str], seconds: float, layout: str, expected: int,
    health_hz: float, diagnose_wait_s: float, ready, go, out, security=None,
) -> None:  # fmt: skip
    """One monitor process: its share of the arms, until every sample came or time ran out."""
    from robohealth_mj.ros2.bus import Bus, BusConfig
    from robohealth_mj.ros2.node import MonitorNode, poll_paced
    from robohealth_mj.runtime.runtime import ModelRuntime

    latencies: list[float] = []

    def on_diagnosis(arm: str, sample, d) -> None:
        latencies.append(time.time() - sample.t)

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1", depth=50, security=security))
    names = "ur_driver" if layout == "ur_driver" else "schema"  # as the publisher names joints
    node = MonitorNode(bus, ModelRuntime(model), arms, on_diagnosis=on_diagnosis, layout=layout,
                       health_diagnosis_hz=health_hz, diagnose_wait_s=diagnose_wait_s,
                       joint_names=names)  # fmt: skip
    ready.set()
    go.wait()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    deadline = wall0 + seconds + 3.5
    while time.perf_counter() < deadline and sum(s.samples for s in node.arms.values()) < expected:
        poll_paced(node, 0.005)  # as the monitor's default poll_s
    wall = time.perf_counter() - wall0
    out.put({
        "diagnosed": sum(s.samples for s in node.arms.values()),
        "problems": sum(s.problems for s in node.arms.values()),
        "latencies": latencies,
        "cpu_cores": (time.process_time() - cpu0) / wall,
        "seconds": {k: v / wall for k, v in node.seconds.items()},
    })  # fmt: skip
    bus.close()


def run_once(
    model: str, samples: list, arms: int, seconds: float, domain: int, layout: str,
    monitors: int = 1, health_hz: float = 20.0, diagnose_wait_s: float = 0.02,
    security: dict | None = None, driver_hz: float = 500.0,
) -> dict[str, Any]:  # fmt: skip
    """Publishers in one child process; ``monitors`` monitor processes, each a stable-hash
    share of the arms (as ``ros2.partition=k/n`` splits them); CPU per side in cores.
    ``security``: the robot's and the monitor's enclaves (:func:`secured_graph`)."""
    security = security or {}
    from robohealth_mj.ros2.node import in_partition

    ctx = mp.get_context("spawn")
    go, out = ctx.Event(), ctx.Queue()
    names = [f"arm{k + 1}" for k in range(arms)]
    ticks = int(seconds * 20)
    shares = [[a for a in names if in_partition(a, f"{k}/{monitors}" if monitors > 1 else None)]
              for k in range(monitors)]  # fmt: skip
    children, readies, results = [], [], ctx.Queue()
    for share in shares:
        ready = ctx.Event()
        children.append(ctx.Process(target=_monitor, args=(
            domain, model, share, seconds, layout, ticks * len(share), health_hz,
            diagnose_wait_s, ready, go,
            results, security.get("monitor"))))  # fmt: skip
        readies.append(ready)
    publisher_ready = ctx.Event()
    children.append(ctx.Process(
        target=_publisher,
        args=(domain, arms, samples, seconds, layout, publisher_ready, go, out,
              security.get("robot"), driver_hz),
    ))  # fmt: skip
    for child in children:
        child.start()
    for ready in [*readies, publisher_ready]:
        ready.wait(120)
    time.sleep(1.5 if not security else 4.0)  # discovery (and the handshakes)
    go.set()
    published = out.get(timeout=seconds + 60)
    parts = [results.get(timeout=seconds + 60) for _ in shares]
    for child in children:
        child.join(10)
    got = sum(p["diagnosed"] for p in parts)
    rate = driver_hz if layout == "ur_driver" else 20.0  # each arm's messages per second
    latencies = [v for p in parts for v in p["latencies"]]
    lat = np.array(latencies) * 1e3 if latencies else np.array([np.nan])
    phases: dict[str, float] = {}
    for p in parts:
        for k, v in p["seconds"].items():
            phases[k] = phases.get(k, 0.0) + v
    return {
        "arms": arms,
        "monitors": monitors,
        "messages_per_s": round(arms * MESSAGES_PER_TICK[layout] * rate),
        "published_samples": published["ticks"] * arms,
        "diagnosed": got,
        "lost": published["ticks"] * arms - got,
        "problems": sum(p["problems"] for p in parts),
        "latency_p50_ms": float(np.percentile(lat, 50)),
        "latency_p99_ms": float(np.percentile(lat, 99)),
        "monitor_cpu_cores": sum(p["cpu_cores"] for p in parts),
        "publisher_cpu_cores": published["cpu_cores"],
        "publisher_late_s": published["late_s"],
        "monitor_seconds": phases,  # cores per phase, summed over the monitors
    }


def secured_graph(root: Any, domain: int, arms: int, layout: str) -> dict[str, Any]:
    """A keystore for one benchmark row: the robot's and the monitor's enclaves, each with
    what ``python -m robohealth_mj.keystore`` grants them for these arms and layout."""
    from robohealth_mj.common.config import compose_config
    from robohealth_mj.ros2.grants import monitor_grant, robot_grant
    from robohealth_mj.ros2.keystore import create_enclave, create_keystore
    from robohealth_mj.ros2.security import resolve_security

    cfg = compose_config("keystore", [f"ros2.count={arms}", f"ros2.layout={layout}"]).ros2
    keystore = create_keystore(f"{root}/keys_{domain}", domain)
    out = {}
    for role, grant in (("robot", robot_grant), ("monitor", monitor_grant)):
        create_enclave(keystore, f"/bench/{role}", grant(cfg))
        settings = {"enable": True, "strategy": "Enforce", "keystore": str(keystore.root),
                    "enclave": f"/bench/{role}"}  # fmt: skip
        out[role] = resolve_security(settings, domain, environ={})
    return out


def bench_ros2(
    model: str, data: str, arms_list: list[int], seconds: float, layouts: list[str],
    monitors: list[int] | None = None, health_hz: float = 20.0, diagnose_wait_s: float = 0.02,
    graphs: list[str] | None = None, driver_hz: float = 500.0,
) -> list[dict]:  # fmt: skip
    from robohealth_mj.data.arrays import resolve_recordings
    from robohealth_mj.data.read import read_samples
    from robohealth_mj.runtime.ready import resolve_model

    model = resolve_model(model)  # a file, or a ready model by name (full, stock, ur_driver)
    samples = list(itertools.islice(read_samples(resolve_recordings([data])[0]), 400))
    domains = itertools.count(150)
    rows = []
    print(
        f"{'graph':>7} {'layout':>10} {'mon':>3} {'arms':>5} {'msg/s':>7} {'lost':>6} {'bad':>4} "
        f"{'p50 ms':>7} {'p99 ms':>7} {'monitor CPU':>11} {'publisher CPU':>13}   "
        "monitor time by phase"
    )
    with tempfile.TemporaryDirectory(prefix="bench_sros2_") as root:
        for layout, n, arms, graph in itertools.product(
            layouts, monitors or [1], arms_list, graphs or ["open"]
        ):
            domain = next(domains)
            security = secured_graph(root, domain, arms, layout) if graph == "secured" else None
            r = run_once(model, samples, arms, seconds, domain, layout, n, health_hz,
                         diagnose_wait_s, security, driver_hz)  # fmt: skip
            r["layout"], r["graph"] = layout, graph
            rows.append(r)
            _print_row(r, n)
    return rows


def _print_row(r: dict, n: int) -> None:
    print(
        f"{r['graph']:>7} {r['layout']:>10} {n:>3} {r['arms']:>5} {r['messages_per_s']:>7} "
        f"{r['lost']:>6} {r['problems']:>4} {r['latency_p50_ms']:>7.1f} "
        f"{r['latency_p99_ms']:>7.1f} {r['monitor_cpu_cores']:>10.2f}c "
        f"{r['publisher_cpu_cores']:>12.2f}c   "
        + "  ".join(f"{k} {v:.2f}c" for k, v in r["monitor_seconds"].items()),
        flush=True,
    )
