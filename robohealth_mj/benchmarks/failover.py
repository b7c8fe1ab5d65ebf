"""A monitor group under kill and restart, on loopback: ``bench ros2 --monitors 3 --kill 1``.

A child process publishes every arm (the aggregated layout, stamped at publish, as ``bench ros2``
does); the monitors run as the command a user starts (``python -m robohealth_mj.monitor
source=ros2 ros2.group.enable=true``), each under its own stable member name; this process reads
every arm's ``/health_diagnosis`` and tells the monitors apart by the writer each diagnosis came
from. Each cycle kills one monitor with SIGKILL (in turn, the one with the most arms first),
then restarts it:

- *recovered*: from the kill to the first diagnosis of each of its arms by another monitor (the
  first with a decision comes a window later: the taker starts the arm's window afresh);
- *twice*: ticks of any arm diagnosed by two monitors from 3 s after the kill to the restart;
- *lost*: ticks an arm missed between its first and its latest diagnosis (every arm gets every
  tick's stamp: the stamps some arm got and this one did not), less its gap after a kill (the
  ticks after the last one the killed monitor diagnosed and before the first its taker did).
  Counted in stamps, not arrival times, so a monitor that lags under load (its ticks in flight
  when killed, or still on their way) does not look like one that drops ticks;
- *restored*: from the restart until every arm is diagnosed by one monitor again and the
  restarted one holds what it held before.
"""

from __future__ import annotations

import itertools
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class Arrivals:
    """Every diagnosis this process has read: per arm, (arrival, stamp, writer, decided)."""

    rows: dict[str, list[tuple[float, int, int, bool]]] = field(
        default_factory=lambda: defaultdict(list)
    )

    def writers_since(self, arm: str, since: float) -> set[int]:
        return {w for t, _, w, _ in self.rows[arm] if t >= since}

    def first_after(self, arm: str, since: float, not_from: set[int], decided=False) -> float:
        """When the arm was first diagnosed after ``since`` by a writer not in ``not_from``
        (inf: not yet)."""
        for t, _, w, d in self.rows[arm]:
            if t >= since and w not in not_from and (d or not decided):
                return t
        return float("inf")

    def twice(self, since: float, until: float) -> int:
        """Ticks (arm, stamp) that two writers diagnosed, among those read in the interval."""
        count = 0
        for rows in self.rows.values():
            by_stamp: dict[int, set[int]] = defaultdict(set)
            for t, s, w, _ in rows:
                if since <= t < until:
                    by_stamp[s].add(w)
            count += sum(len(ws) > 1 for ws in by_stamp.values())
        return count

    def gap(self, arm: str, killed: float, victim: set[int]) -> tuple[int, int]:
        """The stamps an arm lost to a kill, as an open interval: after the last tick the killed
        monitor (writers ``victim``) diagnosed, before the first another writer diagnosed since."""
        rows = self.rows[arm]
        last = max((s for _, s, w, _ in rows if w in victim), default=-1)
        taken = [s for t, s, w, _ in rows if t >= killed and w not in victim]
        return last, min(taken, default=sys.maxsize)

    def lost(self, gaps: dict[str, list[tuple[int, int]]]) -> int:
        """Ticks an arm missed that another arm got, between its own first and latest diagnosis,
        outside its ``gaps`` (open stamp intervals)."""
        every = {s for rows in self.rows.values() for _, s, _, _ in rows}
        missed = 0
        for arm, rows in self.rows.items():
            got = {s for _, s, _, _ in rows}
            if not got:
                continue
            first, latest = min(got), max(got)
            missed += sum(
                first < s < latest and not any(a < s < b for a, b in gaps.get(arm, ()))
                for s in every - got
            )
        return missed


class Listener:
    """Reads every arm's ``/health_diagnosis`` (reliable, so the listener loses nothing)."""

    def __init__(self, domain: int, arms: list[str]) -> None:
        from robohealth_mj.bags.topics import BagTopics
        from robohealth_mj.ros2.bus import Bus, BusConfig
        from robohealth_mj.ros2.idl import TYPES
        from robohealth_mj.ros2.node import arm_topics

        config = BusConfig(domain_id=domain, interface="127.0.0.1", depth=1000,
                           reliable_subscriptions=True)  # fmt: skip
        self.bus = Bus(config)
        kind = TYPES["diagnostic_msgs/msg/DiagnosticArray"]
        topics = BagTopics.load()
        self.readers = {a: self.bus.reader(arm_topics(a, topics).health_diagnosis, kind)
                        for a in arms}  # fmt: skip
        self.arrivals = Arrivals()

    def listen(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (now := time.monotonic()) < end:
            for arm, reader in self.readers.items():
                for msg in reader.take(N=256):
                    stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
                    decided = not msg.status[0].message.startswith("no decision")
                    handle = msg.sample_info.publication_handle
                    self.arrivals.rows[arm].append((now, stamp, handle, decided))
            time.sleep(0.01)

    def current_writers(self, window_s: float = 1.0) -> dict[str, set[int]]:
        since = time.monotonic() - window_s
        return {a: self.arrivals.writers_since(a, since) for a in self.readers}

    def wait_settled(self, timeout_s: float, window_s: float = 1.0) -> dict[str, int] | None:
        """Listen until every arm has been diagnosed by one writer alone for ``window_s``;
        its writer per arm, or None at the timeout."""
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            self.listen(0.25)
            writers = self.current_writers(window_s)
            if all(len(w) == 1 for w in writers.values()):
                return {a: next(iter(w)) for a, w in writers.items()}
        return None


def _monitor_command(model: str, domain: int, arms: int, member: str, handover_s: float) -> list:
    return [sys.executable, "-m", "robohealth_mj.monitor", f"model={model}", "source=ros2",
            "duration_s=0", f"ros2.domain_id={domain}", "ros2.interface=127.0.0.1",
            f"ros2.count={arms}", "ros2.layout=aggregated", "ros2.reliable_subscriptions=true",
            "ros2.depth=50", "ros2.group.enable=true", f"ros2.group.member={member}",
            f"ros2.group.handover_s={handover_s}", "threads=1"]  # fmt: skip


class Monitors:
    """The monitor processes, each logging to its own file (no pipe to fill and stall it)."""

    def __init__(self, model: str, domain: int, arms: int, count: int, logs: Path,
                 handover_s: float) -> None:  # fmt: skip
        self.model, self.domain, self.arms, self.logs = model, domain, arms, logs
        self.handover_s = handover_s
        self.names = [f"monitor{k}" for k in range(count)]
        self.procs: dict[str, subprocess.Popen] = {}
        self.starts: dict[str, int] = defaultdict(int)

    def start(self, name: str) -> None:
        self.starts[name] += 1
        log = open(self.logs / f"{name}.{self.starts[name]}.log", "w")  # noqa: SIM115
        command = _monitor_command(self.model, self.domain, self.arms, name, self.handover_s)
        self.procs[name] = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        log.close()

    def wait_listening(
        self, name: str, idle: Callable[[float], Any] = time.sleep, timeout_s: float = 60.0
    ) -> None:
        """Until the monitor says it is on the bus (its model loaded, its share taken), calling
        ``idle(seconds)`` meanwhile (the listener's ``listen``: a reader left unread for the
        seconds a loaded machine takes to start a monitor overflows and looks like loss)."""
        log = self.logs / f"{name}.{self.starts[name]}.log"
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if "ros2 monitor:" in log.read_text():
                return
            if self.procs[name].poll() is not None:
                raise RuntimeError(f"{name} exited: {log.read_text()[-2000:]}")
            idle(0.1)
        raise TimeoutError(f"{name} did not start in {timeout_s:.0f} s ({log})")

    def kill(self, name: str) -> None:
        self.procs[name].send_signal(signal.SIGKILL)
        self.procs[name].wait(timeout=10)

    def stop(self) -> None:
        for proc in self.procs.values():
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        for proc in self.procs.values():
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()


def failover(
    model: str, samples: list, monitors: int = 3, arms: int = 30, cycles: int = 10,
    domain: int = 170, handover_s: float = 3.0, logs: Path | None = None,
) -> list[dict[str, Any]]:  # fmt: skip
    """Kill and restart the group's monitors ``cycles`` times; one row of figures per cycle."""
    from robohealth_mj.benchmarks.ros2 import _publisher
    from robohealth_mj.ros2.group import share

    ctx = mp.get_context("spawn")
    names = [f"arm{k + 1}" for k in range(arms)]
    cycle_s = 4.0 + 3.0 + handover_s + 6.0
    ready, go, out = ctx.Event(), ctx.Event(), ctx.Queue()
    seconds = 30.0 + cycles * (cycle_s + 10.0)  # the publisher outlives the cycles; stopped after
    publisher = ctx.Process(target=_publisher, args=(domain, arms, samples, seconds, "aggregated",
                                                     ready, go, out))  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="failover_") as tmp:
        group = Monitors(model, domain, arms, monitors, Path(logs or tmp), handover_s)
        listener = Listener(domain, names)
        rows: list[dict[str, Any]] = []
        try:
            publisher.start()
            ready.wait(60)
            go.set()
            for name in group.names:
                group.start(name)
            for name in group.names:
                group.wait_listening(name, listener.listen)
            before = listener.wait_settled(30.0 + handover_s)
            if before is None:
                raise RuntimeError(f"the group did not settle: {listener.current_writers()}")
            gaps: dict[str, list[tuple[int, int]]] = defaultdict(list)
            # the victims in turn, the one watching the most arms first
            victims = sorted(group.names, key=lambda m: -len(share(names, group.names, m)))
            for cycle in range(cycles):
                victim = victims[cycle % monitors]
                theirs = share(names, group.names, victim)
                handles = {before[a] for a in theirs}
                killed = time.monotonic()
                group.kill(victim)
                listener.listen(4.0)
                recovered = [listener.arrivals.first_after(a, killed, handles) - killed
                             for a in theirs]  # fmt: skip
                decided = [listener.arrivals.first_after(a, killed, handles, True) - killed
                           for a in theirs]  # fmt: skip
                for a in theirs:
                    gaps[a].append(listener.arrivals.gap(a, killed, handles))
                restarted = time.monotonic()
                twice = listener.arrivals.twice(killed + 3.0, restarted)
                group.start(victim)
                group.wait_listening(victim, listener.listen)
                after = listener.wait_settled(handover_s + 15.0)
                restored = time.monotonic() - restarted
                moved = {a for a in names if after is not None and after[a] != before[a]}
                rows.append({
                    "cycle": cycle + 1, "killed": victim, "arms": len(theirs),
                    "recovered_max_s": max(recovered), "recovered_median_s":
                    float(np.median(recovered)), "decided_max_s": max(decided),
                    "twice_after_3s": twice,
                    "lost": listener.arrivals.lost(gaps),
                    "restored_s": restored if after is not None else float("inf"),
                    "shares_restored": after is not None and moved == set(theirs),
                })  # fmt: skip
                _print_cycle(rows[-1])
                before = after if after is not None else before
        finally:
            group.stop()
            publisher.terminate()
            publisher.join(10)
            listener.bus.close()
    return rows


def _print_cycle(r: dict[str, Any]) -> None:
    print(f"{r['cycle']:>5} {r['killed']:>9} {r['arms']:>4} {r['recovered_max_s']:>13.2f} "
          f"{r['recovered_median_s']:>11.2f} {r['decided_max_s']:>12.2f} "
          f"{r['twice_after_3s']:>6} {r['lost']:>5} {r['restored_s']:>10.2f} "
          f"{r['shares_restored']!s:>7}", flush=True)  # fmt: skip


def bench_failover(model: str, data: str, monitors: int, arms: int, cycles: int) -> list[dict]:
    """``bench ros2 --monitors N --kill 1``: the table, then each figure against its target."""
    from robohealth_mj.data.arrays import resolve_recordings
    from robohealth_mj.data.read import read_samples
    from robohealth_mj.runtime.ready import resolve_model

    model = str(resolve_model(model))
    samples = list(itertools.islice(read_samples(resolve_recordings([data])[0]), 400))
    print(f"{monitors} monitors, {arms} arms (aggregated layout, 20 Hz), {cycles} kill/restart "
          f"cycles on loopback, {os.cpu_count()} cores")  # fmt: skip
    print(
        f"{'cycle':>5} {'killed':>9} {'arms':>4} {'recovered s':>13} {'median s':>11} "
        f"{'decided s':>12} {'twice':>6} {'lost':>5} {'restored s':>10} {'shares':>7}"
    )
    rows = failover(model, samples, monitors, arms, cycles)
    worst = max(r["recovered_max_s"] for r in rows)
    print(
        f"every arm diagnosed again within {worst:.2f} s of a kill (target 2 s); "
        f"{sum(r['twice_after_3s'] for r in rows)} ticks diagnosed twice after 3 s (target 0); "
        f"{sum(r['lost'] for r in rows)} ticks lost outside the gaps (target 0); shares "
        f"restored after {sum(r['shares_restored'] for r in rows)} of {len(rows)} restarts"
    )
    return rows
