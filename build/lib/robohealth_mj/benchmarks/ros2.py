"""ROS 2 over DDS on loopback: arms per monitor process at 20 Hz with no message lost, and the
latency from a robot's publish to the diagnosis on ``/diagnostics``.

Publishers run in a child process (replaying a recording, stamps set to the wall clock at publish,
so the monitor reads each sample's age directly); the monitor runs here. CPU is reported apart
for each side (process time over wall time, in cores)."""

from __future__ import annotations

import itertools
import multiprocessing as mp
import time
from typing import Any

import numpy as np


def _publisher(
    domain: int, arms: int, samples: list, seconds: float, layout: str, ready, go, out
) -> None:
    from robohealth_mj.ros2.bus import Bus, BusConfig
    from robohealth_mj.ros2.node import ArmPublisher

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1", depth=50))
    from robohealth_mj.bags.topics import BagTopics

    pubs = [ArmPublisher(bus, f"arm{k + 1}", layout=layout) for k in range(arms)]
    topics = BagTopics.load()
    ready.set()
    go.wait()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    ticks = int(seconds * 20)
    for tick in range(ticks):
        due = wall0 + tick / 20.0
        delay = due - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        base = samples[tick % len(samples)]
        sample = base.__class__("bench", tick, time.time(), base.x, base.fault, base.segment)
        built = [m for _, m in pubs[0].messages(sample, topics)]  # stamped now
        for pub in pubs:
            pub.publish_built(built)
    out.put(
        {
            "ticks": ticks,
            "cpu_cores": (time.process_time() - cpu0) / (time.perf_counter() - wall0),
            "late_s": max(0.0, time.perf_counter() - (wall0 + ticks / 20.0)),
        }
    )
    time.sleep(1.0)


def run_once(
    model: str, samples: list, arms: int, seconds: float, domain: int, layout: str
) -> dict[str, Any]:
    from robohealth_mj.ros2.bus import Bus, BusConfig
    from robohealth_mj.ros2.node import MonitorNode
    from robohealth_mj.runtime.runtime import ModelRuntime

    ctx = mp.get_context("spawn")
    ready, go, out = ctx.Event(), ctx.Event(), ctx.Queue()
    child = ctx.Process(
        target=_publisher, args=(domain, arms, samples, seconds, layout, ready, go, out)
    )
    child.start()
    latencies: list[float] = []

    def on_diagnosis(arm: str, sample, d) -> None:
        latencies.append(time.time() - sample.t)

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1", depth=50))
    arm_names = [f"arm{k + 1}" for k in range(arms)]
    node = MonitorNode(
        bus, ModelRuntime(model), arm_names, on_diagnosis=on_diagnosis, layout=layout
    )
    ready.wait(60)
    time.sleep(1.5)  # discovery
    go.set()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    deadline = wall0 + seconds + 2.0
    expected = int(seconds * 20) * arms
    while time.perf_counter() < deadline and sum(s.samples for s in node.arms.values()) < expected:
        if not node.poll():
            time.sleep(0.005)  # as the monitor's default poll_s
    wall = time.perf_counter() - wall0
    cpu = time.process_time() - cpu0
    published = out.get(timeout=30)
    child.join(10)
    bus.close()
    got = sum(s.samples for s in node.arms.values())
    problems = sum(s.problems for s in node.arms.values())
    lat = np.array(latencies) * 1e3 if latencies else np.array([np.nan])
    return {
        "arms": arms,
        "messages_per_s": arms * (15 if layout == "per_sensor" else 2) * 20,
        "published_samples": published["ticks"] * arms,
        "diagnosed": got,
        "lost": published["ticks"] * arms - got,
        "problems": problems,
        "latency_p50_ms": float(np.percentile(lat, 50)),
        "latency_p99_ms": float(np.percentile(lat, 99)),
        "monitor_cpu_cores": cpu / wall,
        "publisher_cpu_cores": published["cpu_cores"],
        "publisher_late_s": published["late_s"],
        "monitor_seconds": {k: v / wall for k, v in node.seconds.items()},  # cores per phase
    }


def bench_ros2(
    model: str, data: str, arms_list: list[int], seconds: float, layouts: list[str]
) -> list[dict]:
    from robohealth_mj.data.arrays import resolve_recordings
    from robohealth_mj.data.read import read_samples

    samples = list(itertools.islice(read_samples(resolve_recordings([data])[0]), 400))
    domains = itertools.count(150)
    rows = []
    print(
        f"{'layout':>10} {'arms':>5} {'msg/s':>7} {'lost':>6} {'bad':>4} {'p50 ms':>7} "
        f"{'p99 ms':>7} {'monitor CPU':>11} {'publisher CPU':>13}   monitor time by phase"
    )
    for layout, arms in itertools.product(layouts, arms_list):
        r = run_once(model, samples, arms, seconds, next(domains), layout)
        r["layout"] = layout
        rows.append(r)
        print(
            f"{layout:>10} {r['arms']:>5} {r['messages_per_s']:>7} {r['lost']:>6} "
            f"{r['problems']:>4} {r['latency_p50_ms']:>7.1f} {r['latency_p99_ms']:>7.1f} "
            f"{r['monitor_cpu_cores']:>10.2f}c {r['publisher_cpu_cores']:>12.2f}c   "
            + "  ".join(f"{k} {v:.2f}c" for k, v in r["monitor_seconds"].items()),
            flush=True,
        )
    return rows
