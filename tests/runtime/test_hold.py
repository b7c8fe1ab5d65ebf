"""Decisions every k ticks: the model runs on about 1/k of the streams a tick, staggered, each
decision is the model's on a window at most k - 1 ticks old, and a restarted window is decided
afresh."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime
from robohealth_mj.runtime.hold import DecisionHold


def _replay(fleet: FleetRuntime, x: np.ndarray, streams: int, ticks: int, skip: dict):
    """Class probabilities ``[ticks, streams, C]`` (NaN undecided) and the rows the model ran
    on each tick; ``skip[t] = k``: stream k sends nothing at tick t (a gap)."""
    calls: list[int] = []
    infer = fleet.engine.infer
    fleet.engine.infer = lambda slots: (calls.append(len(slots)), infer(slots))[1]
    slots = fleet.register([f"s{k}" for k in range(streams)])
    offsets = 97 * np.arange(streams) % (len(x) - ticks)
    probs = np.full((ticks, streams, len(fleet.classes)), np.nan)
    per_tick = []
    for t in range(ticks):
        send = np.array([skip.get(t) != k for k in range(streams)])
        before = len(calls)
        r = fleet.step(slots[send], np.full(send.sum(), t), np.full(send.sum(), 0.05 * (t + 1)),
                       x[offsets[send] + t])  # fmt: skip
        per_tick.append(sum(calls[before:]))
        decided = r.status == DECIDED
        probs[t, np.flatnonzero(send)[decided]] = r.probs[decided]
    return probs, np.array(per_tick)


def test_held_decisions_are_the_models_on_a_recent_window_and_spread_over_ticks(deployed):
    rec = load_recordings([deployed["heldout"]])
    k, streams, ticks, skip = 3, 12, 90, {40: 5}
    every, _ = _replay(FleetRuntime(deployed["structural_onnx"]), rec.x, streams, ticks, skip)
    held, calls = _replay(
        FleetRuntime(deployed["structural_onnx"], decide_every=k), rec.x, streams, ticks, skip
    )
    decided = ~np.isnan(every[..., 0])
    assert np.array_equal(decided, ~np.isnan(held[..., 0]))  # the same ticks are decided
    for s in range(streams):
        fresh = 0  # ticks since the held outputs were the model's own
        for t in np.flatnonzero(decided[:, s]):
            same = [u for u in range(t - k + 1, t + 1) if u >= 0 and decided[u, s]
                    and np.allclose(held[t, s], every[u, s], atol=1e-6)]  # fmt: skip
            assert same, (s, t)  # the model's decision on a window at most k - 1 ticks old
            fresh = 0 if np.allclose(held[t, s], every[t, s], atol=1e-6) else fresh + 1
            assert fresh < k
    # after the gap, stream 5's first decision is its new window's own
    first = np.flatnonzero(decided[41:, 5])[0] + 41
    np.testing.assert_allclose(held[first, 5], every[first, 5], atol=1e-6)
    # steady state: about 1/k of the streams a tick, never all of them at once
    steady = calls[60:]
    assert steady.max() <= streams // k + 2 and steady.sum() == pytest.approx(
        len(steady) * streams / k, rel=0.15
    )


def test_decision_hold_refuses_a_tick_count_below_one_and_grows():
    with pytest.raises(ValueError, match="decide_every must be at least 1"):
        DecisionHold(0, 4)
    hold = DecisionHold(2, 2)
    out = hold.decide(np.array([0, 1]), lambda s: [np.asarray(s, float)[:, None] + 10])
    np.testing.assert_array_equal(out[0][:, 0], [10, 11])
    hold.ensure(5)
    out = hold.decide(np.array([4]), lambda s: [np.asarray(s, float)[:, None] + 10])
    np.testing.assert_array_equal(out[0][:, 0], [14])


def test_the_monitor_refuses_a_bad_decide_every_in_one_line():
    args = [sys.executable, "-m", "robohealth_mj.monitor", "decide_every=0", "duration_s=1"]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=120)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "decide_every: 0 is not a whole number of ticks >= 1" in lines[0]


def test_two_shard_threads_hold_as_one_thread_does(deployed):
    """Shard threads decide disjoint slots at once, the first tick included (the held arrays
    are made once, whichever thread gets there first)."""
    rec = load_recordings([deployed["heldout"]])
    one = FleetRuntime(deployed["structural_onnx"], decide_every=3)
    two = FleetRuntime(deployed["structural_onnx"], decide_every=3, shards=2, capacity=140)
    a, _ = _replay(one, rec.x, 140, 20, {})
    b, _ = _replay(two, rec.x, 140, 20, {})
    assert (~np.isnan(a)).sum() > 140 * 10
    np.testing.assert_allclose(a, b, atol=1e-6)
    two.close()
