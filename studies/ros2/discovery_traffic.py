"""What DDS discovery costs per arm: the bytes on loopback while a robot participant with K arms
and a monitor participant for them find each other, and while they then sit idle (issue 66,
part 4: sizing a fleet of 10,000 arms, docs/deployment.md).

Two child processes on a fresh domain: one opens K arms' writers in a layout (the robot), the
other the monitor's readers and diagnosis writers for them (``MonitorNode`` without a model).
Each first makes its participant alone; once the two have had ``settle`` seconds to find each
other, both open their endpoints. The loopback interface's received bytes and packets
(``/proc/net/dev``) are read around each step: the participants' discovery, then the endpoints'
(each endpoint announced to the other participant, acknowledged), then ``idle`` seconds with no
data (periodic announcements and liveliness). Endpoint bytes are given per endpoint, the idle
rate taken off.

    .venv/bin/python studies/ros2/discovery_traffic.py [--arms 10 50] [--layouts ...]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time


def _loopback() -> tuple[int, int]:
    """Received bytes and packets of the loopback interface so far."""
    with open("/proc/net/dev") as f:
        for line in f:
            name, _, rest = line.partition(":")
            if name.strip() == "lo":
                fields = rest.split()
                return int(fields[0]), int(fields[1])
    raise RuntimeError("no loopback interface in /proc/net/dev")


def _robot(domain: int, arms: int, layout: str, ready, go, stop) -> None:
    from robohealth_mj.ros2.bus import Bus, BusConfig
    from robohealth_mj.ros2.node import ArmPublisher

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1"))
    ready.put(0)
    go.wait()
    pubs = [ArmPublisher(bus, f"arm{k + 1}", layout=layout) for k in range(arms)]
    ready.put(sum(len(p.writers) for p in pubs))
    stop.wait()
    bus.close()


def _monitor(domain: int, arms: int, layout: str, ready, go, stop) -> None:
    from robohealth_mj.ros2.bus import Bus, BusConfig
    from robohealth_mj.ros2.node import MonitorNode

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1"))
    ready.put(0)
    go.wait()
    names = "ur_driver" if layout == "ur_driver" else "schema"
    node = MonitorNode(bus, None, [f"arm{k + 1}" for k in range(arms)], layout=layout,
                       joint_names=names)  # fmt: skip
    ready.put(sum(len(s.readers) for s in node.arms.values()) + len(node.diagnosis_writers) + 1)
    stop.wait()
    bus.close()


def measure(domain: int, arms: int, layout: str, settle: float, idle: float) -> dict:
    ctx = mp.get_context("spawn")
    ready, go, stop = ctx.Queue(), ctx.Event(), ctx.Event()
    procs = [ctx.Process(target=f, args=(domain, arms, layout, ready, go, stop))
             for f in (_robot, _monitor)]  # fmt: skip
    for p in procs:
        p.start()
    ready.get(timeout=120), ready.get(timeout=120)  # both participants exist
    time.sleep(settle)  # ... and have found each other
    bytes0, _ = _loopback()
    time.sleep(idle)  # idle: two participants, no endpoints
    bytes1, packets1 = _loopback()
    go.set()
    endpoints = ready.get(timeout=120) + ready.get(timeout=120)
    time.sleep(settle)
    bytes2, packets2 = _loopback()
    time.sleep(idle)
    bytes3, packets3 = _loopback()
    stop.set()
    for p in procs:
        p.join(30)
    idle_rate = (bytes1 - bytes0) / idle
    found = (bytes2 - bytes1) - idle_rate * settle  # endpoints' discovery, less the idle traffic
    return {"layout": layout, "arms": arms, "endpoints": endpoints,
            "endpoint_kb": found / 1e3, "endpoint_packets": packets2 - packets1,
            "bytes_per_endpoint": found / endpoints,
            "idle_b_s": idle_rate, "idle_with_endpoints_b_s": (bytes3 - bytes2) / idle,
            "idle_packets_s": (packets3 - packets2) / idle}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", type=int, nargs="+", default=[10, 50])
    parser.add_argument("--layouts", nargs="+", default=["per_sensor", "aggregated", "ur_driver"])
    parser.add_argument("--settle", type=float, default=5.0)
    parser.add_argument("--idle", type=float, default=10.0)
    parser.add_argument("--domain", type=int, default=190)
    args = parser.parse_args()
    print(
        f"{'layout':>10} {'arms':>5} {'endpoints':>9} {'endpoint kB':>11} {'packets':>8} "
        f"{'B/endpoint':>10} {'idle B/s':>8} {'idle B/s, endpoints':>19} {'pkt/s':>6}"
    )
    domain = args.domain
    for layout in args.layouts:
        for arms in args.arms:
            r = measure(domain, arms, layout, args.settle, args.idle)
            domain += 1
            print(f"{layout:>10} {arms:>5} {r['endpoints']:>9} {r['endpoint_kb']:>11.1f} "
                  f"{r['endpoint_packets']:>8} {r['bytes_per_endpoint']:>10.0f} "
                  f"{r['idle_b_s']:>8.0f} {r['idle_with_endpoints_b_s']:>19.0f} "
                  f"{r['idle_packets_s']:>6.1f}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
