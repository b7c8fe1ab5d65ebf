"""Soak test: a fleet under bad input for a while, checked row by row.

A share of the streams misbehave, each in one way, on a fixed schedule (periods in ticks):

=============  ================================================================  ================
kind           what the stream does                                              flagged reason
=============  ================================================================  ================
nan            every 20th sample carries a NaN                                   ``NaN or Inf``
gap            every 40th tick skips three sample indices                        ``gap``
backwards      every 30th tick re-sends an old sample (time goes backwards)      ``backwards``
node_order     every 25th sample comes with its nodes reversed                   ``node``
burst          every 50th tick sends 12 samples at once (8 are taken in order)   ``burst``
stop_resume    falls silent for 40 ticks of every 300, then carries on           ``gap``
=============  ================================================================  ================

The rest are healthy. Every injected bad row must come back flagged with its reason, every healthy
stream must be decided on every tick once its window is full, the step must stay within the tick,
and the process's resident memory must not grow.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from robohealth_mj.benchmarks.streams import TICK_S
from robohealth_mj.runtime.fleet import DECIDED, INVALID, FleetRuntime

KINDS = ("nan", "gap", "backwards", "node_order", "burst", "stop_resume")
EXPECTED = {
    "nan": "NaN or Inf",
    "gap": "gap",
    "backwards": "backwards",
    "node_order": "node",
    "burst": "burst",
    "stop_resume": "gap",
}
BURST = 12


def rss_mb() -> float:
    """Resident set size of this process (Linux), MB."""
    with open("/proc/self/status", encoding="ascii") as handle:
        for line in handle:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


@dataclass
class SoakReport:
    streams: int
    ticks: int
    rows: int = 0
    injected: dict[str, int] = field(default_factory=dict)
    missed: dict[str, int] = field(default_factory=dict)  # injected rows not flagged as expected
    healthy_undecided: int = 0  # healthy-stream rows after warm-up without a decision
    step_ms: list[float] = field(default_factory=list)
    rss_mb: list[float] = field(default_factory=list)

    def summary(self) -> dict:
        times = np.array(self.step_ms)
        settled = self.rss_mb[len(self.rss_mb) // 4 :] or self.rss_mb
        return {
            "streams": self.streams,
            "ticks": self.ticks,
            "rows": self.rows,
            "injected": self.injected,
            "missed": self.missed,
            "healthy_undecided": self.healthy_undecided,
            "step_p50_ms": float(np.percentile(times, 50)),
            "step_p99_ms": float(np.percentile(times, 99)),
            "step_max_ms": float(times.max()),
            "late_ticks": int((times > TICK_S * 1e3).sum()),
            "rss_start_mb": settled[0],
            "rss_end_mb": self.rss_mb[-1],
            "rss_growth_mb": self.rss_mb[-1] - settled[0],
        }


def soak(
    fleet: FleetRuntime,
    x: np.ndarray,
    streams: int,
    ticks: int,
    bad_share: float = 0.1,
    paced: bool = False,
    seed: int = 0,
) -> SoakReport:
    """Run the scenario for ``ticks`` ticks on ``fleet`` (which needs room for ``streams``)."""
    rng = np.random.default_rng(seed)
    ids = [f"arm{k:05d}" for k in range(streams)]
    slots = fleet.register(ids)
    kind = np.full(streams, -1)
    bad = rng.permutation(streams)[: max(len(KINDS), int(bad_share * streams))]
    kind[bad] = np.arange(len(bad)) % len(KINDS)
    offsets = rng.integers(0, len(x), streams)
    index = np.zeros(streams, np.int64)  # next sample index per stream
    report = SoakReport(
        streams, ticks, injected=dict.fromkeys(KINDS, 0), missed=dict.fromkeys(KINDS, 0)
    )
    healthy = kind < 0
    next_tick = time.perf_counter()
    for k in range(ticks):
        is_kind = {name: kind == KINDS.index(name) for name in KINDS}
        silent = is_kind["stop_resume"] & (k % 300 >= 60) & (k % 300 < 100)
        index[is_kind["gap"] & (k % 40 == 39)] += 3  # skip three samples
        index[silent] += 1  # time passes for a silent stream
        send = ~silent
        s_rows = np.flatnonzero(send)
        row_slot, row_index = slots[s_rows], index[s_rows].copy()
        row_x = x[(offsets[s_rows] + row_index) % len(x)].copy()
        expect = np.full(len(s_rows), -1)  # expected kind of a flagged row
        nan = is_kind["nan"][s_rows] & (k % 20 == 19)
        row_x[nan, 7, 3] = np.nan
        expect[nan] = KINDS.index("nan")
        order = is_kind["node_order"][s_rows] & (k % 25 == 24)
        row_x[order] = row_x[order][:, ::-1]
        expect[order] = KINDS.index("node_order")
        layout_ok = ~order
        back = is_kind["backwards"][s_rows] & (k % 30 == 29) & (row_index > 5)
        row_index[back] -= 5
        expect[back] = KINDS.index("backwards")
        gap_now = (is_kind["gap"][s_rows] & (k % 40 == 39)) | (
            is_kind["stop_resume"][s_rows] & (k % 300 == 100)
        )
        expect[gap_now] = np.where(is_kind["gap"][s_rows][gap_now], 1, 5)
        index[s_rows[~back]] += 1
        # bursts: extra samples of the same streams after their regular one
        burst = s_rows[is_kind["burst"][s_rows] & (k % 50 == 49)]
        extra_slot, extra_index, extra_expect = [], [], []
        for s in burst.tolist():
            for j in range(BURST - 1):
                extra_slot.append(slots[s])
                extra_index.append(index[s] + j)
                extra_expect.append(KINDS.index("burst") if j + 1 >= fleet.max_burst else -1)
            index[s] += BURST - 1
        if extra_slot:
            ei = np.array(extra_index)
            burst_of = np.repeat(burst, BURST - 1)
            row_slot = np.concatenate([row_slot, extra_slot])
            row_x = np.concatenate([row_x, x[(offsets[burst_of] + ei) % len(x)]])
            row_index = np.concatenate([row_index, ei])
            expect = np.concatenate([expect, extra_expect])
            layout_ok = np.concatenate([layout_ok, np.ones(len(ei), bool)])
        t = (row_index + 1) * TICK_S
        start = time.perf_counter()
        result = fleet.step(row_slot, row_index, t, row_x.astype(np.float32), layout_ok)
        report.step_ms.append((time.perf_counter() - start) * 1e3)
        report.rows += len(result)
        _check(report, result, expect, healthy[s_rows], len(s_rows), k >= fleet.window + 1)
        if k % 20 == 0:
            report.rss_mb.append(rss_mb())
        if paced:
            next_tick += TICK_S
            delay = next_tick - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
    report.rss_mb.append(rss_mb())
    return report


def _check(report, result, expect, healthy_sent, regular, warmed) -> None:
    """Count injected rows and those not flagged with their reason; healthy rows undecided."""
    for row in np.flatnonzero(expect >= 0).tolist():
        name = KINDS[expect[row]]
        report.injected[name] += 1
        reason = result.reasons.get(row, "")
        if result.status[row] != INVALID or EXPECTED[name] not in reason:
            report.missed[name] += 1
    if warmed:
        status = result.status[:regular]
        report.healthy_undecided += int((healthy_sent & (status != DECIDED)).sum())
