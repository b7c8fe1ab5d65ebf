"""What DDS alone costs at a live load: the publishers' process, and a monitor process that only
receives (``idle``: its readers exist, nothing is taken) or only takes (``take``: every ready
reader taken, nothing decoded, assembled or diagnosed).

    python studies/ros2/transport_floor.py --data DIR --arms 50 100 --seconds 10

The same publishers as ``bench ros2`` (one process replaying a recording, per-sensor layout,
15 messages an arm a tick at 20 Hz, loopback). The monitor's CPU here is a floor under any
monitor of that many arms in one process; with the publishers' CPU it says how many arms the
machine can carry at all while both run on it.
"""

from __future__ import annotations

import argparse
import itertools
import multiprocessing as mp
import time

from robohealth_mj.benchmarks.ros2 import _publisher
from robohealth_mj.data.arrays import resolve_recordings
from robohealth_mj.data.read import read_samples


def receive_only(domain: int, arms: list[str], seconds: float, take: bool, ready, go, out) -> None:
    from robohealth_mj.ros2.bus import Bus, BusConfig, ReadySet
    from robohealth_mj.ros2.cdr import take_raw
    from robohealth_mj.ros2.idl import TYPES
    from robohealth_mj.ros2.node import arm_topics, layout_topics

    bus = Bus(BusConfig(domain_id=domain, interface="127.0.0.1", depth=50))
    readers = [bus.reader(t, TYPES[k]) for arm in arms
               for t, k in layout_topics(arm_topics(arm), "per_sensor").items()]  # fmt: skip
    ready_set = ReadySet(bus, readers)
    ready.set()
    go.wait()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    taken = 0
    while time.perf_counter() < wall0 + seconds + 1.0:
        started = time.perf_counter()
        if take:
            for index in ready_set.wait(0.0):
                taken += len(take_raw(readers[index], 256))
        rest = 0.005 - (time.perf_counter() - started)  # as the monitor's poll period
        if rest > 0:
            time.sleep(rest)
    wall = time.perf_counter() - wall0
    out.put({"cpu_cores": (time.process_time() - cpu0) / wall, "taken": taken})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True, help="a recording to replay")
    parser.add_argument("--arms", type=int, nargs="+", default=[50, 100])
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args()
    samples = list(itertools.islice(read_samples(resolve_recordings([args.data])[0]), 400))
    ctx = mp.get_context("spawn")
    domains = itertools.count(190)
    print(f"{'monitor':>8} {'arms':>5} {'msg/s':>7} {'taken':>8} {'monitor CPU':>11} "
          f"{'publisher CPU':>13} {'publisher late s':>16}")  # fmt: skip
    for take, arms in itertools.product((False, True), args.arms):
        domain, names = next(domains), [f"arm{k + 1}" for k in range(arms)]
        go, published, received = ctx.Event(), ctx.Queue(), ctx.Queue()
        monitor_ready, publisher_ready = ctx.Event(), ctx.Event()
        children = [
            ctx.Process(target=receive_only, args=(domain, names, args.seconds, take,
                                                   monitor_ready, go, received)),
            ctx.Process(target=_publisher, args=(domain, arms, samples, args.seconds,
                                                 "per_sensor", publisher_ready, go, published)),
        ]  # fmt: skip
        for child in children:
            child.start()
        monitor_ready.wait(120)
        publisher_ready.wait(120)
        time.sleep(1.5)  # discovery
        go.set()
        pub, mon = published.get(timeout=args.seconds + 60), received.get(timeout=args.seconds + 60)
        for child in children:
            child.join(10)
        print(f"{'take' if take else 'idle':>8} {arms:>5} {arms * 300:>7} {mon['taken']:>8} "
              f"{mon['cpu_cores']:>10.2f}c {pub['cpu_cores']:>12.2f}c {pub['late_s']:>16.2f}",
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
