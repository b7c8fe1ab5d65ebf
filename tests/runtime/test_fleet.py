"""The fleet runtime: ring-buffer windows, incremental = windowed inference, bulk validation and
bursts, alarms (debouncing, hysteresis), alarm-based on-line metrics and a short soak."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.benchmarks.common import fresh_variant
from robohealth_mj.benchmarks.soak import KINDS, soak
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.models.incremental import supports_incremental
from robohealth_mj.monitor import main as monitor_main
from robohealth_mj.runtime.alarms import CLEARED, HELD, NONE, RAISED, AlarmBank, AlarmPolicy
from robohealth_mj.runtime.fleet import (
    BUFFERED,
    DECIDED,
    INVALID,
    WARMING,
    FleetRuntime,
    execution_providers,
)
from robohealth_mj.runtime.online_eval import OnlineEvaluator
from robohealth_mj.runtime.runtime import HealthDiagnosis
from robohealth_mj.schema import FaultLabel

# Incremental and windowed inference agree to this (max |p_incremental - p_windowed|): float32
# two-pass window statistics against float64 running sums, and two float32 graphs against one.
TOLERANCE = 1e-4


def _replay(fleet: FleetRuntime, x: np.ndarray, streams: int, ticks: int, skip: dict | None = None):
    """Stream ``k`` replays ``x`` from offset ``37 k`` (wrapped to fit); ``skip`` {tick: stream}
    drops a sample (a gap). Returns probs [ticks, streams, C] (NaN where undecided)."""
    slots = fleet.register([f"s{k}" for k in range(streams)])
    offsets = (37 * np.arange(streams)) % (len(x) - ticks)
    probs = np.full((ticks, streams, len(fleet.classes)), np.nan, np.float32)
    for t in range(ticks):
        send = np.array([skip is None or skip.get(t) != k for k in range(streams)])
        r = fleet.step(slots[send], np.full(send.sum(), t), np.full(send.sum(), 0.05 * (t + 1)),
                       x[offsets[send] + t])  # fmt: skip
        decided = r.status == DECIDED
        probs[t, np.flatnonzero(send)[decided]] = r.probs[decided]
    return probs


def test_ring_buffer_windows_equal_the_batch_windows(deployed):
    rec = load_recordings([deployed["heldout"]])
    fleet = FleetRuntime(deployed["structural_onnx"], incremental=False)
    assert fleet.mode == "windowed"
    slots = fleet.register(["a", "b", "c"])
    offsets = np.array([0, 50, 120])
    for t in range(30):
        fleet.step(slots, np.full(3, t), np.full(3, 0.05 * (t + 1)), rec.x[offsets + t])
        if t + 1 >= fleet.window:
            got = fleet.engine.windows(slots)
            for k, off in enumerate(offsets):
                end = off + t
                assert rec.run[end - fleet.window + 1] == rec.run[end]  # one recording run
                expected = rec.x[end - fleet.window + 1 : end + 1]
                np.testing.assert_array_equal(got[k], expected)


def test_incremental_inference_equals_windowed_inference(deployed):
    rec = load_recordings([deployed["heldout"]])
    for graph in ("structural", "harness"):
        incremental = FleetRuntime(deployed[f"{graph}_onnx"])
        windowed = FleetRuntime(deployed[f"{graph}_onnx"], incremental=False)
        assert (incremental.mode, windowed.mode) == ("incremental", "windowed")
        skip = {20: 1, 45: 2}  # gaps restart those streams' windows
        a = _replay(incremental, rec.x, 4, 80, skip)
        b = _replay(windowed, rec.x, 4, 80, skip)
        assert np.array_equal(np.isnan(a), np.isnan(b))
        assert (~np.isnan(a)).sum() > 200
        assert np.nanmax(np.abs(a - b)) <= TOLERANCE


def _window_max_by_scan(engine, slots: np.ndarray) -> np.ndarray:
    """The definition the block maxima must meet: the maximum over the window's W records,
    the oldest counted with no step and with its ``g_first`` (an encoder with ``first_record``)
    or with the newest's ``g`` (one without: no record of its own), the others as recorded:
    ``[B, N, G + 3S]`` (g, |step|, signal, -signal)."""
    g, f0 = engine.g, engine.first
    out = []
    for slot in slots.tolist():
        order = (engine.head[slot] + np.arange(engine.window)) % engine.window  # oldest first
        raw = engine.raw[order, slot].copy()
        raw[0, :, :g] = engine.g_fixed[slot] if engine.first_record else raw[-1, :, :g]
        raw[0, :, g:] = 0.0
        signal = engine.z[order, slot][..., f0:]
        out.append(np.concatenate([raw, signal, -signal], axis=-1).max(axis=0))
    return np.stack(out)


@pytest.mark.parametrize("graph", ["structural", "harness"])
def test_block_window_maxima_equal_a_scan_of_the_window(deployed, graph):
    """The fleet keeps window maxima by blocks (three records a tick); through gaps (windows
    restarting at any block phase) and ticks that skip streams, the views they give (max of g;
    asinh of min, max and max |step| of each signal) equal those of a full scan, whether the
    encoder pools the oldest snapshot's record (structural) or not (harness)."""
    rec = load_recordings([deployed["heldout"]])
    fleet = FleetRuntime(deployed[f"{graph}_onnx"], chunk=4)
    engine, streams = fleet.engine, 11
    assert engine.first_record == (graph == "structural")
    g, s = engine.g, engine.s
    slots = fleet.register([f"s{k}" for k in range(streams)])
    rng = np.random.default_rng(3)
    index, checked = np.zeros(streams, np.int64), 0
    for _ in range(6 * fleet.window):
        send = rng.random(streams) < 0.85  # the others skip this tick: a gap, a restart
        index[~send] += 1
        who = np.flatnonzero(send)
        r = fleet.step(slots[who], index[who], 0.05 * (index[who] + 1), rec.x[index[who] + 5 * who])
        index[who] += 1
        full = slots[who][r.status == DECIDED]
        if not len(full):
            continue
        views = engine.views(full)[0]
        peak = _window_max_by_scan(engine, full)
        stats = views[..., 3 * g : 3 * g + 7 * s].reshape(len(full), -1, s, 7)
        np.testing.assert_array_equal(views[..., 2 * g : 3 * g], peak[..., :g])
        for column, expected in ((2, -peak[..., g + 2 * s :]), (3, peak[..., g + s : g + 2 * s]),
                                 (6, peak[..., g : g + s])):  # fmt: skip
            np.testing.assert_allclose(
                stats[..., column], np.arcsinh(expected), rtol=1e-6, atol=5e-7
            )
        checked += len(full)
    assert checked > 100


def _decisions(fleet: FleetRuntime, x: np.ndarray, streams: int, ticks: int) -> dict:
    """Every row's status, top class, top joint and alarm over a replay with a gap per stream."""
    slots = fleet.register([f"s{k}" for k in range(streams)])
    out: dict[str, list] = {k: [] for k in ("status", "cls", "joint", "alarm", "probs")}
    for t in range(ticks):
        send = np.arange(streams) != t % 23  # stream t % 23 skips this tick (when there is one)
        r = fleet.step(slots[send], np.full(send.sum(), t), np.full(send.sum(), 0.05 * (t + 1)),
                       x[37 * np.flatnonzero(send) + t])  # fmt: skip
        out["status"].append(r.status)
        out["cls"].append(r.probs.argmax(1))
        out["joint"].append(r.joint_scores.argmax(1))
        out["alarm"].append(np.stack([r.alarm, r.alarm_class, r.alarm_joint], axis=1))
        out["probs"].append(r.probs)
    return {k: np.concatenate(v) for k, v in out.items()}


def test_parts_and_threads_do_not_change_a_decision(deployed):
    """The tick split in parts of a few streams on two threads decides (status, class, joint,
    alarm) as one call on one thread; the probabilities agree to float32 rounding (onnxruntime
    rounds a batch of 2 and one of 7 differently)."""
    rec = load_recordings([deployed["heldout"]])
    one = _decisions(FleetRuntime(deployed["structural_onnx"], chunk=10_000), rec.x, 7, 80)
    parts = FleetRuntime(deployed["structural_onnx"], chunk=2, shards=2)
    split = _decisions(parts, rec.x, 7, 80)
    parts.close()
    assert (one["status"] == DECIDED).sum() > 300 and (one["alarm"][:, 0] > 0).any()
    for key in ("status", "cls", "joint", "alarm"):
        np.testing.assert_array_equal(one[key], split[key])
    np.testing.assert_allclose(one["probs"], split["probs"], atol=1e-6)


def test_models_without_an_incremental_form_fall_back_to_windows():
    assert supports_incremental(fresh_variant("anomaly_residual", 8))
    assert not supports_incremental(fresh_variant("anomaly_residual", 8, "backbone=thesis"))
    assert not supports_incremental(
        fresh_variant("anomaly_residual", 8, "model.backbone.convolutions=true")
    )


def test_each_bad_row_is_flagged_with_its_reason_and_the_rest_decided(deployed):
    rec = load_recordings([deployed["heldout"]])
    fleet = FleetRuntime(deployed["structural_onnx"], max_streams=8)
    slots = fleet.register([f"s{k}" for k in range(6)])
    for t in range(fleet.window):
        fleet.step(slots, np.full(6, t), np.full(6, 0.05 * (t + 1)), rec.x[t : t + 6])
    t = fleet.window
    x = rec.x[t : t + 6].copy()
    index, stamp = np.full(6, t), np.full(6, 0.05 * (t + 1))
    x[0, 8, 5] = np.inf
    x[1] = x[1][::-1]
    x[2, 0, 10] = 1.0  # a sensor channel on a joint node
    stamp[3] = 0.0
    index[4] += 3
    layout_ok = np.array([True, True, True, True, True, True])
    r = fleet.step(slots, index, stamp, x, layout_ok)
    assert list(r.status) == [INVALID] * 5 + [DECIDED]
    where = f"x[{schema.NODE_NAMES[8]}].{schema.FEATURE_NAMES[5]}"
    assert where in r.reasons[0] and "NaN or Inf" in r.reasons[0]
    indicators = "node-type indicators do not match the node order"
    assert r.reasons[1] == f"field 'x.is_joint/is_sensor': {indicators}"
    assert r.reasons[2] == "field 'x': joint nodes must zero the sensor channels"
    assert "time went backwards" in r.reasons[3]
    assert "gap in sample_index" in r.reasons[4] and "window restarted" in r.reasons[4]
    r = fleet.step(slots[:1], [t + 1], [0.05 * (t + 2)], x[5:6], np.array([False]))
    assert "node order differs" in r.reasons[0]
    r = fleet.step(slots[5:6], [t + 1], [np.nan], x[5:6])
    assert r.status[0] == INVALID and r.reasons[0] == "field 't': not finite"
    r = fleet.step(np.array([99]), [0], [0.05], x[5:6])
    assert r.status[0] == INVALID and "unknown stream" in r.reasons[0]
    r = fleet.step(slots[:1], [0], [0.05], np.zeros((1, 3, 3), np.float32))
    assert "shape" in r.reasons[0]
    # the stream limit: 8 slots
    assert (fleet.register([f"n{k}" for k in range(3)]) == [6, 7, -1]).all()


def test_a_burst_is_taken_in_order_up_to_the_limit(deployed):
    rec = load_recordings([deployed["heldout"]])
    one = FleetRuntime(deployed["structural_onnx"], max_burst=5)
    each = FleetRuntime(deployed["structural_onnx"])
    s1, s2 = one.register(["a"]), each.register(["a"])
    n = one.window + 7
    burst = one.step(np.repeat(s1, n), np.arange(n), 0.05 * (np.arange(n) + 1), rec.x[:n])
    assert list(burst.status[:5]) == [WARMING] * 5
    dropped = "burst: more than 5 samples from this stream in one tick; dropped"
    assert all(burst.reasons[k] == dropped for k in range(5, n))
    singles = [each.step(s2, [k], [0.05 * (k + 1)], rec.x[k : k + 1]) for k in range(5)]
    assert [s.status[0] for s in singles] == list(burst.status[:5])
    # the next sample after the dropped ones is a gap
    r = one.step(s1, [n], [0.05 * (n + 1)], rec.x[n : n + 1])
    assert "gap" in r.reasons[0]
    # a warmed-up stream's burst is buffered in order and decided once, on its last sample
    w = each.window
    for k in range(5, w + 5):
        each.step(s2, [k], [0.05 * (k + 1)], rec.x[k : k + 1])
    other = FleetRuntime(deployed["structural_onnx"])
    s3 = other.register(["a"])
    for k in range(w + 5):
        other.step(s3, [k], [0.05 * (k + 1)], rec.x[k : k + 1])
    k = np.arange(w + 5, w + 9)
    burst = each.step(np.repeat(s2, 4), k, 0.05 * (k + 1), rec.x[k])
    assert list(burst.status) == [BUFFERED] * 3 + [DECIDED]
    for j in k:  # the same samples one tick each
        single = other.step(s3, [j], [0.05 * (j + 1)], rec.x[j : j + 1])
    np.testing.assert_allclose(burst.probs[-1], single.probs[0], atol=1e-6)


def _probs(cls: int, p: float) -> np.ndarray:
    out = np.full((1, 7), (1 - p) / 6, np.float32)
    out[0, cls] = p
    return out


def _run(bank: AlarmBank, script: list[tuple[int, float, int]]) -> list[tuple[int, int, int]]:
    slot = np.zeros(1, np.int64)
    out = []
    for cls, p, joint in script:
        scores = np.full((1, 6), 0.1, np.float32)
        scores[0, joint] = 0.9
        state, alarm, j = bank.update(slot, _probs(cls, p), scores)
        out.append((int(state[0]), int(alarm[0]), int(j[0])))
    return out


def test_alarms_raise_hold_and_clear_with_hysteresis():
    policy = AlarmPolicy(raise_after=3, clear_after=4, min_confidence=0.8, clear_confidence=0.6)
    bank = AlarmBank(policy, 6, 1)
    jam = (3, 0.95, 2)
    healthy = (0, 0.9, 0)
    script = [healthy] * 2 + [jam] * 5 + [healthy] * 3 + [jam] + [healthy] * 4
    states = _run(bank, script)
    assert [s for s, _, _ in states] == (
        [NONE] * 2 + [NONE, NONE, RAISED, HELD, HELD] + [HELD] * 3 + [HELD] + [HELD] * 3
        + [CLEARED]
    )  # fmt: skip
    assert states[4][1:] == (3, 2)  # jam at elbow
    assert states[-1][1:] == (0, -1)


def test_alarms_suppress_flicker_and_low_confidence():
    bank = AlarmBank(AlarmPolicy(raise_after=3, clear_after=3, min_confidence=0.8), 6, 1)
    flicker = [(3, 0.95, 2), (0, 0.9, 0)] * 10
    low = [(3, 0.6, 2)] * 10  # confident enough to win, not to vote
    assert all(s == NONE for s, _, _ in _run(bank, flicker + low))


def test_alarm_joint_follows_the_smoothed_scores_and_class_switches_reraise():
    policy = AlarmPolicy(raise_after=2, clear_after=5, min_confidence=0.9, joint_smoothing=0.3)
    bank = AlarmBank(policy, 6, 1)
    states = _run(bank, [(1, 0.95, 4)] * 4 + [(1, 0.95, 1)] + [(2, 0.95, 1)] * 2)
    assert states[1] == (RAISED, 1, 4)
    assert states[4] == (HELD, 1, 4)  # one tick elsewhere does not move the joint
    assert states[6] == (RAISED, 2, 1)  # two agreeing ticks of another class re-raise


def test_alarm_policy_rejects_nonsense():
    message = "alarm raise_after and clear_after must be at least 1 tick"
    for bad in ({"raise_after": 0}, {"clear_after": 0}):
        with pytest.raises(ValueError) as info:
            AlarmPolicy(**bad)
        assert str(info.value) == message
    for name in ("min_confidence", "clear_confidence", "joint_smoothing"):
        for bad in (-0.01, 1.5):
            with pytest.raises(ValueError, match=f"alarm {name} must lie in \\[0, 1\\], got {bad}"):
                AlarmPolicy(**{name: bad})
    # the edges are settings a user may choose: one tick, certainty, anything
    AlarmPolicy(raise_after=1, clear_after=1, min_confidence=1.0, clear_confidence=0.0,
                joint_smoothing=1.0)  # fmt: skip
    AlarmPolicy(min_confidence=0.0, clear_confidence=1.0, joint_smoothing=0.0)


def test_a_tick_exactly_at_the_threshold_votes():
    """``min_confidence`` and ``clear_confidence`` are inclusive ("at least")."""
    policy = AlarmPolicy(raise_after=2, clear_after=2, min_confidence=0.75, clear_confidence=0.5)
    bank = AlarmBank(policy, 6, 1)
    states = _run(bank, [(3, 0.75, 2)] * 2 + [(0, 0.5, 0)] * 2)  # exact in float32
    assert [s for s, _, _ in states] == [NONE, RAISED, HELD, CLEARED]


def test_softmax_is_stable_for_large_and_far_apart_logits():
    from robohealth_mj.common.numeric import softmax

    z = np.array([[120.0, 100.0, 0.0], [0.0, -1.0, -2.0]], np.float32)
    p = softmax(z)
    assert np.isfinite(p).all()
    np.testing.assert_allclose(p.sum(axis=1), 1.0, rtol=1e-6)
    e = np.exp(np.array([0.0, -20.0, -120.0]))
    np.testing.assert_allclose(p[0], e / e.sum(), rtol=1e-5, atol=1e-30)  # float32 underflow
    e = np.exp(np.array([0.0, -1.0, -2.0]))
    np.testing.assert_allclose(p[1], e / e.sum(), rtol=1e-5)


def _diag(alarm: str = "none", cls: str | None = None, joint: str | None = None):
    return HealthDiagnosis(
        stamp=0.0, stream_id="s", sample_index=0, valid=True, fault_class="none",
        alarm=alarm, alarm_class=cls, alarm_joint=joint,
    )  # fmt: skip


def test_online_alarm_metrics_on_a_scripted_stream_with_known_onsets():
    healthy = FaultLabel()
    jam = FaultLabel("jam", "elbow", 0.6, True)
    drift = FaultLabel("sensor_drift", "wrist_1", 0.3, True)
    up = _diag("held", "jam", "elbow")
    script = (
        [(healthy, _diag())] * 10
        + [(healthy, _diag("raised", "jam", "wrist_1"))]  # a false alarm, settled healthy
        + [(healthy, _diag("held", "jam", "wrist_1"))] * 2
        + [(healthy, _diag("cleared"))]
        + [(jam, _diag())] * 4  # onset at tick 14: 4 ticks without
        + [(jam, _diag("raised", "jam", "wrist_1"))] * 2  # right class at +4
        + [(jam, up)] * 4  # right joint at +6
        + [(healthy, up)] * 3  # settling: not counted as false
        + [(healthy, _diag())] * 7
        + [(drift, _diag())] * 10  # never detected
    )
    ev = OnlineEvaluator(tick_s=0.05, settle_ticks=5)
    for truth, d in script:
        ev.update(truth, d)
    r = ev.result()
    assert r["episodes"] == 2
    a = r["alarms"]
    assert a["detected"] == 1 and a["detection_rate"] == 0.5
    jam_a = r["alarms_by_class"]["jam"]
    assert jam_a["class_latency_s_median"] == pytest.approx(0.20)
    assert jam_a["joint_latency_s_median"] == pytest.approx(0.30)
    assert r["alarms_by_class"]["sensor_drift"]["detected"] == 0
    assert r["alarms_by_severity"]["0.3"]["detection_rate"] == 0.0
    # settled healthy ticks: 14 before the jam, then 10 - 5 after it
    assert r["settled_healthy_ticks"] == 14 + 5
    assert r["false_alarm_rate"] == pytest.approx(3 / 19)
    assert r["false_alarms"] == 1
    assert r["false_alarms_per_hour"] == pytest.approx(1 / (19 * 0.05 / 3600))


def test_a_short_soak_flags_every_bad_row_and_keeps_the_healthy_streams(deployed):
    rec = load_recordings([deployed["heldout"]])
    streams = 140  # enough that the two shards engage (64 rows a shard at least)
    fleet = FleetRuntime(deployed["structural_onnx"], capacity=streams, max_streams=streams,
                         shards=2)  # fmt: skip
    calls = []
    infer = fleet.engine.infer
    fleet.engine.infer = lambda slots: calls.append(len(slots)) or infer(slots)
    report = soak(fleet, rec.x, streams, 120, bad_share=0.25).summary()
    assert all(report["injected"][k] > 0 for k in KINDS), report["injected"]
    assert sum(report["missed"].values()) == 0, report["missed"]
    assert report["healthy_undecided"] == 0
    assert fleet.capacity == streams  # state arrays allocated once
    assert max(calls) < streams - 20 and len(calls) > 120  # two model calls per full tick


def test_sharded_steps_decide_as_one_shard_does(deployed):
    rec = load_recordings([deployed["heldout"]])
    one = FleetRuntime(deployed["structural_onnx"])
    two = FleetRuntime(deployed["structural_onnx"], shards=2)
    a, b = _replay(one, rec.x, 130, 12), _replay(two, rec.x, 130, 12)
    assert (~np.isnan(a)).sum() == 5 * 130 * 7  # every stream decided on the last 5 ticks
    np.testing.assert_allclose(a, b, atol=1e-6)
    two.close()  # the threads stop; later steps run on the calling thread
    assert two._pool is None and two.shards == 1
    r = two.step(two.register([f"s{k}" for k in range(130)]), np.full(130, 12),
                 np.full(130, 0.65), rec.x[12:142])  # fmt: skip
    assert (r.status == DECIDED).all()
    assert two.describe() == {
        "model_id": one.model_id, "arm": "ur5e", "window": 8, "mode": "incremental", "threads": 1,
        "decide_every": 1, "joint_scores": "softmax", "observability": "all", "contact": None,
        "problem": None,
    }  # fmt: skip
    assert one.model_id.startswith("stgnn_fixed-structural-w8-")


def test_idle_streams_are_released_and_their_slots_reused(deployed):
    rec = load_recordings([deployed["heldout"]])
    fleet = FleetRuntime(deployed["structural_onnx"], idle_ticks=30)
    slots = fleet.register(["a", "b"])
    for t in range(10):
        fleet.step(slots, [t, t], [0.05 * (t + 1)] * 2, rec.x[t : t + 2])
    for t in range(10, 40):  # 'a' falls silent at tick 10
        fleet.step(slots[1:], [t], [0.05 * (t + 1)], rec.x[t : t + 1])
    assert fleet.streams == ["a", "b"]  # silent for 30 ticks: not yet idle
    for t in range(40, 60):
        r = fleet.step(slots[1:], [t], [0.05 * (t + 1)], rec.x[t : t + 1])
        assert r.status[0] == DECIDED
    assert fleet.streams == ["b"]  # released at the once-a-second sweep after 30 idle ticks
    (c,) = fleet.register(["c"])
    assert c == slots[0]  # the freed slot is reused, with a fresh window and sample index
    r = fleet.step([c], [0], [0.05], rec.x[:1])
    assert r.status[0] == WARMING and r.reasons[0].startswith("warming up")


def test_monitor_refuses_nonsense_alarm_and_evidence_settings(deployed, capsys):
    for bad, named in (
        ("alarm.min_confidence=2", "alarm: alarm min_confidence must lie in [0, 1], got 2"),
        ("evidence.clip=-1", "evidence: evidence clip and floor must be > 0, got -1"),
        ("evidence.half_life=3", "evidence.half_life: no such key"),
        ("contact.confirm=0", "contact: contact confirm must be at least 1 tick, got 0"),
    ):
        with pytest.raises(SystemExit) as info:
            monitor_main([f"model={deployed['structural_onnx']}", bad])
        assert info.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith("monitor: error: ") and named in err, err
        assert len(err.strip().splitlines()) == 1


def _table(printed: str) -> list[dict]:
    """The policy rows of tune_alarms' markdown table."""
    rows = []
    for line in printed.splitlines():
        cells = [c.strip() for c in line.strip("|").split("|")]
        if len(cells) == 14 and cells[3].isdigit():
            number = lambda c: None if c == "–" else float(c)  # noqa: E731
            rows.append({
                "horizon_s": float(cells[0]), "raise_after": int(cells[3]),
                "min_confidence": float(cells[5]), "detection_rate": number(cells[6]),
                "observable_detection_rate": number(cells[7]),
                "right_at_rise_rate": number(cells[8]), "false_alarm_rate": number(cells[9]),
                "false_alarms_per_hour": number(cells[10]),
                "class_latency_s_median": number(cells[11]), "meets": cells[13] == "yes",
            })  # fmt: skip
    return rows


def test_tune_alarms_sweeps_the_grid_and_chooses_the_fastest_policy_meeting_the_targets(
    deployed, record_cfg, tmp_path, capsys
):
    from robohealth_mj.deploy.alarm_sweep import GRID, TARGETS
    from robohealth_mj.recording.recorder import record_session
    from robohealth_mj.tune_alarms import main as tune_main

    healthy = tmp_path / "healthy"
    record_session(record_cfg("faults=none", "session.duration_s=60", "seed=11"), healthy)
    args = ["--model", str(deployed["structural_onnx"]), "--data", str(deployed["heldout"])]
    best = tune_main(args)
    rows = _table(capsys.readouterr().out)
    # horizon 0 is one setting (clip and floor are moot without memory)
    evidence = sum(h > 0 for h in GRID["horizon_s"]) * len(GRID["clip"]) * len(GRID["floor"])
    evidence += 0.0 in GRID["horizon_s"]
    alarms = len(GRID["raise_after"]) * len(GRID["min_confidence"]) * len(GRID["clear_after"])
    assert len(rows) == evidence * alarms
    # a stricter policy never detects more: more votes needed, or more confidence per vote
    no_memory = [r for r in rows if r["horizon_s"] == 0]
    by = {(r["raise_after"], r["min_confidence"]): r["detection_rate"] for r in no_memory}
    assert len(by) == len(GRID["raise_after"]) * len(GRID["min_confidence"])
    for (n, c), rate in by.items():
        for n2, c2 in by:
            if n2 >= n and c2 >= c:
                assert by[(n2, c2)] <= rate + 1e-9, ((n, c), (n2, c2))
    assert by[(3, 0.9)] > by[(14, 0.99)]
    good = [r for r in rows if r["meets"]]
    for r in good:
        observable = r["observable_detection_rate"]
        assert (observable if observable is not None else r["detection_rate"]) >= TARGETS[
            "detection_rate"
        ]
        assert r["right_at_rise_rate"] >= TARGETS["right_at_rise_rate"]
    if good:
        fastest = min(r["class_latency_s_median"] for r in good)
        assert best["class_latency_s_median"] == pytest.approx(fastest, abs=1e-3)
    else:  # nothing meets them all: the quiet policy detecting most, else the fewest alarms
        limits = ("false_alarm_rate", "false_alarms_per_hour")
        calm = [r for r in rows if all((r[k] or 0.0) <= TARGETS[k] for k in limits)]
        if calm:
            seen = lambda r: r["observable_detection_rate"] or r["detection_rate"]  # noqa: E731
            assert seen(best) == pytest.approx(max(seen(r) for r in calm), abs=1e-3)
        else:
            assert best["false_alarms_per_hour"] == min(r["false_alarms_per_hour"] for r in rows)
    # healthy running adds hours to the false-alarm rate, and the table says so
    again = tune_main([*args, "--healthy", str(healthy / "graphs.jsonl")])
    assert "(healthy); 0.02 h of settled healthy running" in capsys.readouterr().out
    minute = (1200 - 8 - 10) * 0.05 / 3600  # after the window fills and the clear delay passes
    assert again["healthy_hours"] == pytest.approx(best["healthy_hours"] + minute, abs=3e-4)


def test_choose_prefers_the_fastest_policy_that_meets_every_target():
    from robohealth_mj.deploy.alarm_sweep import choose, meets_targets

    def row(name, detection, per_hour, rate, latency, at_rise=0.99):
        return {"name": name, "detection_rate": detection, "false_alarms_per_hour": per_hour,
                "false_alarm_rate": rate, "class_latency_s_median": latency,
                "joint_latency_s_median": latency, "right_at_rise_rate": at_rise}  # fmt: skip

    rows = [
        row("slow", 0.99, 0.5, 0.001, 2.0),
        row("fast", 0.97, 1.0, 0.005, 0.6),
        row("noisy", 0.99, 3.0, 0.005, 0.2),  # too many false alarms per hour
        row("blind", 0.90, 0.0, 0.0, 0.1),  # detects too little
        row("jumpy", 0.99, 1.0, 0.02, 0.1),  # too many alarmed healthy ticks
        row("wrong", 0.99, 0.0, 0.0, 0.1, at_rise=0.9),  # rises with the wrong class or joint
    ]
    assert [meets_targets(r) for r in rows] == [True, True, False, False, False, False]
    assert choose(rows)["name"] == "fast"
    # none meets them all: the quiet policy that detects most (then is right at rise most)
    assert choose(rows[2:])["name"] == "wrong"
    assert choose(rows[2:5])["name"] == "blind"
    assert choose([rows[2], rows[4]])["name"] == "jumpy"  # nothing quiet: fewest alarms/h


def test_growing_the_fleet_keeps_every_stream_s_window_and_alarm(deployed, deciding_alarm):
    """Streams joining past the allocated capacity grow the state arrays mid-run: the streams
    already there must decide and alarm exactly as in a fleet that never grew."""
    rec = load_recordings([deployed["heldout"]])
    steady = FleetRuntime(deployed["structural_onnx"], alarm=deciding_alarm, capacity=64)
    growing = FleetRuntime(deployed["structural_onnx"], alarm=deciding_alarm, capacity=1)
    a, b = steady.register(["a"]), growing.register(["a"])
    results = {"steady": [], "growing": []}
    for t in range(400):
        if t in (120, 190):  # an alarm is up on 'a' at both (the held-out replay's two jams)
            joined = growing.register([f"n{t}_{k}" for k in range(3 * (t // 60))])
            assert (joined >= 0).all()
        for name, fleet, slot in (("steady", steady, a), ("growing", growing, b)):
            r = fleet.step(slot, [t], [0.05 * (t + 1)], rec.x[t : t + 1])
            results[name].append((r.status[0], r.alarm[0], r.alarm_class[0], r.alarm_joint[0],
                                  *r.probs[0].round(6)))  # fmt: skip
    assert growing.capacity == 16 and steady.capacity == 64  # 1 -> 2 -> 4, then -> 16
    assert results["steady"] == results["growing"]
    held = [row for row in results["steady"][120:131] + results["steady"][190:201] if row[2] > 0]
    assert len(held) >= 15  # the growth happened while alarms were up


def test_the_alarm_joint_is_an_ema_over_the_ticks_that_vote_for_its_class():
    """A script worked by hand: v(j) scores 0.9 at joint j and 0.1 elsewhere; weight 0.3."""
    policy = AlarmPolicy(raise_after=2, clear_after=3, min_confidence=0.8, joint_smoothing=0.3)
    bank = AlarmBank(policy, 6, 1)
    jam, friction, backlash, healthy, unsure = 3, 2, 1, (0, 0.9, 0), 0.5
    script = [
        (jam, 0.95, 4),  # a new run: the EMA starts at v(4)
        (jam, 0.95, 1),  # raised; EMA .7 v(4) + .3 v(1): joint 4 (.66 against .34)
        (jam, 0.95, 1),  # .492 against .508: joint 1
        (friction, 0.95, 0),  # another class's vote: ignored
        (jam, unsure, 0),  # an abstention: ignored
        (friction, 0.95, 0),  # a new run of friction (the abstention broke the last one)
        (friction, 0.95, 0),  # re-raised as friction: the EMA restarts at v(0)
        healthy, healthy, healthy,  # cleared on the third
        (jam, 0.95, 5),  # a new run: EMA v(5)
        (jam, 0.95, 2),  # raised: joint 5 (.66 against .34)
        healthy, healthy, healthy,
        (backlash, 0.95, 3), (backlash, 0.95, 3),  # raised: joint 3 (EMA v(3))
        (backlash, 0.95, 0),  # .66 against .34: joint 3
        (jam, 0.95, 5),  # another class while backlash is up: ignored
        (jam, unsure, 5),
        (jam, 0.95, 5),  # ignored again (one vote, no re-raise)
        (backlash, 0.95, 0),  # .492 against .508: joint 0
    ]  # fmt: skip
    got = _run(bank, script)
    expected = [
        (NONE, 0, -1), (RAISED, jam, 4), (HELD, jam, 1), (HELD, jam, 1), (HELD, jam, 1),
        (HELD, jam, 1), (RAISED, friction, 0), (HELD, friction, 0), (HELD, friction, 0),
        (CLEARED, 0, -1), (NONE, 0, -1), (RAISED, jam, 5), (HELD, jam, 5), (HELD, jam, 5),
        (CLEARED, 0, -1), (NONE, 0, -1), (RAISED, backlash, 3), (HELD, backlash, 3),
        (HELD, backlash, 3), (HELD, backlash, 3), (HELD, backlash, 3), (HELD, backlash, 0),
    ]  # fmt: skip
    assert got == expected
    np.testing.assert_allclose(bank.scores[0, [0, 3]], [0.508, 0.492], atol=1e-6)


def _with_metadata(src, out, **changes: str):
    import onnx

    proto = onnx.load(str(src))
    for prop in proto.metadata_props:
        if prop.key in changes:
            prop.value = changes[prop.key]
    onnx.save(proto, str(out))
    return out


def test_a_model_of_another_node_order_or_schema_is_refused_with_the_reason(deployed, tmp_path):
    import json

    onnx_path = deployed["structural_onnx"]
    reordered = json.dumps(list(schema.NODE_NAMES[::-1]))
    fleet = FleetRuntime(_with_metadata(onnx_path, tmp_path / "order.onnx", node_names=reordered))
    assert fleet.engine is None and fleet.problem.endswith(
        "is not J joints followed by their J sensors"
    )
    fleet = FleetRuntime(_with_metadata(onnx_path, tmp_path / "old.onnx", schema_version="1.0"))
    assert fleet.engine is None and fleet.problem.endswith(
        "'schema_version': 1.0 is not one this code reads (2.0, 3.0); export the model again"
    )


def test_the_default_fleet_takes_8192_streams():
    fleet = FleetRuntime(None)
    slots = fleet.register([f"arm{k}" for k in range(8193)])
    assert (slots[:8192] >= 0).all() and slots[8192] == -1 and len(set(slots[:8192])) == 8192


def test_stamps_and_indices_must_move_forward_and_hold_no_gap(deployed):
    rec = load_recordings([deployed["heldout"]])
    fleet = FleetRuntime(deployed["structural_onnx"])
    slots = fleet.register(["a", "b"])
    fleet.step(slots, [0, 0], [0.05, 0.05], rec.x[:2])
    # 'a' re-sends index 0 with a later stamp; 'b' jumps from its first index 0 to 5
    r = fleet.step(slots, [0, 5], [0.1, 0.3], rec.x[1:3])
    assert r.status[0] == INVALID and r.reasons[0].startswith("time went backwards: t=0.1 ")
    assert r.reasons[1] == ("gap in sample_index (0 -> 5) or over 0.25 s of time; window restarted")
    # layout flags may be any booleans, 0/1 included
    r = fleet.step(slots, [1, 6], [0.15, 0.35], rec.x[2:4], np.array([1, 1], np.int8))
    assert list(r.status) == [WARMING, WARMING]
    # a tick of the wrong shape keeps its rows' stamps and indices
    r = fleet.step(slots, [2, 7], [0.2, 0.4], np.zeros((2, 3, 3), np.float32))
    assert list(r.t) == [0.2, 0.4] and list(r.sample_index) == [2, 7]


def test_joint_scores_keep_the_faulted_joint_when_every_logit_is_large():
    """A confident softmax-trained model gives every joint a large logit; the sigmoid of each
    rounds to 1 in float32 and its argmax falls on the first joint. Softmax keeps the order."""
    from robohealth_mj.runtime.fleet import joint_scores_from_logits

    logits = np.array([[30.0, 40.0, 35.0, 20.0, 25.0, 38.0]], np.float32)
    softmax = joint_scores_from_logits(logits, "softmax")
    assert softmax.argmax() == 1 and softmax.sum() == pytest.approx(1.0)
    sigmoid = joint_scores_from_logits(logits, "sigmoid")
    assert (sigmoid == 1.0).all() and sigmoid.argmax() == 0  # why softmax models need softmax
    np.testing.assert_allclose(
        joint_scores_from_logits(np.array([[0.0, 2.0]], np.float32), "sigmoid"),
        [[0.5, 1 / (1 + np.exp(-2.0))]],
        rtol=1e-6,
    )


def test_the_export_records_how_joint_scores_were_trained(deployed):
    from robohealth_mj.deploy.export import read_metadata
    from robohealth_mj.learn.checkpoint import joint_score_kind

    assert joint_score_kind({"config": {"trainer": {"joint_softmax": False}}}) == "sigmoid"
    assert joint_score_kind({"config": {"trainer": {"joint_softmax": True}}}) == "softmax"
    assert joint_score_kind({"config": {}}) == "softmax"  # the trainer's default
    assert read_metadata(deployed["structural_onnx"])["joint_scores"] == "softmax"
    assert FleetRuntime(deployed["structural_onnx"]).describe()["joint_scores"] == "softmax"


def test_execution_providers_prefer_cuda_and_refuse_a_name_the_install_lacks():
    gpu = ["TensorrtExecutionProvider", "CUDAExecutionProvider", "CPUExecutionProvider"]
    cpu = ["AzureExecutionProvider", "CPUExecutionProvider"]
    assert execution_providers(None, gpu) == ["CUDAExecutionProvider", "CPUExecutionProvider"]
    assert execution_providers(None, cpu) == ["CPUExecutionProvider"]
    assert execution_providers(["CPUExecutionProvider"], gpu) == ["CPUExecutionProvider"]
    with pytest.raises(InputError, match="'CUDAExecutionProvider' is not in this onnxruntime"):
        execution_providers(["CUDAExecutionProvider", "CPUExecutionProvider"], cpu)


def test_the_fleet_reports_its_provider_and_refuses_an_unknown_one(deployed):
    fleet = FleetRuntime(deployed["structural_onnx"])
    assert fleet.engine is not None and fleet.providers[-1] == "CPUExecutionProvider"
    with pytest.raises(InputError, match="'NoSuchExecutionProvider'"):
        FleetRuntime(deployed["structural_onnx"], providers=["NoSuchExecutionProvider"])


def test_an_encoder_without_the_oldest_record_costs_one_snapshot_mlp_a_sample(deployed):
    """The point of ``first_record=false``: the fleet's per-sample graph runs the snapshot MLP
    once, not twice (bench's FLOP counter, on the same graph width and snapshot MLP)."""
    import base64

    import onnxruntime as ort

    from robohealth_mj.benchmarks.common import onnx_flops
    from robohealth_mj.runtime.metadata import read_metadata

    def encode_flops_per_node(graph: str) -> float:
        meta = read_metadata(deployed[f"{graph}_onnx"])
        raw = np.zeros((1, schema.N_NODES, schema.N_FEATURES), np.float32)
        z = np.zeros((1, int(meta["incremental_nodes"]), schema.N_FEATURES), np.float32)
        feeds = {"x_new": raw, "z_prev": z, "z_first": z, "has_prev": np.zeros(1, np.float32)}
        return onnx_flops(
            lambda m, o: ort.InferenceSession(m, o, providers=["CPUExecutionProvider"]),
            base64.b64decode(meta["incremental_encode"]), feeds,
        ) / int(meta["incremental_nodes"])  # fmt: skip

    # per graph node (the harness graph has 10, the structural 12); the harness's input mapping
    # adds 2.5 % of matrix products of its own
    both, one = encode_flops_per_node("structural"), encode_flops_per_node("harness")
    assert one > 0 and one == pytest.approx(both / 2, rel=0.05)


def test_bench_counts_a_graph_on_fewer_nodes_than_the_arm(deployed):
    """The unknown-placement harness reads the arm's 12 raw nodes into 10 of its own: bench's
    FLOP counter feeds each of its graphs the shapes that graph takes, and the fleet's
    incremental form costs less a tick than the whole window."""
    from robohealth_mj.benchmarks.fleet import model_flops

    harness = str(deployed["harness_onnx"])
    incremental, windowed = model_flops(harness), model_flops(harness, incremental=False)
    assert 0 < incremental < windowed


def test_bench_streams_names_an_unknown_provider_in_one_line(deployed, capsys):
    from robohealth_mj.bench import main as bench_main

    with pytest.raises(SystemExit) as info:
        model, data = str(deployed["structural_onnx"]), str(deployed["heldout"])
        bench_main(["streams", "--model", model, "--data", data, "--providers", "NoSuch"])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("bench: error: execution provider 'NoSuch' is not in this onnxruntime")
    assert len(err.splitlines()) == 1


def test_motion_observability_hides_friction_on_joints_still_through_the_window(deployed):
    """One joint turns at a single sample; windows holding that sample keep the model's calls,
    every other window (the arm still) has friction and backlash handed to none."""
    from robohealth_mj.data.observability import MOVING_RAD_S, hide_unobservable

    rec = load_recordings([deployed["heldout"]])
    ticks, spike = 90, 40
    x = rec.x[:ticks].copy()
    vel = schema.feature_index("vel")
    x[:, :, vel] = 0.0  # the arm still (the same input to both runtimes) ...
    x[spike, 2, vel] = 1.2 * MOVING_RAD_S  # ... but the elbow, at one sample
    plain = FleetRuntime(deployed["structural_onnx"])
    gated = FleetRuntime(deployed["structural_onnx"], observability="motion")
    assert gated.describe()["observability"] == "motion"
    a, b = plain.register(["s"]), gated.register(["s"])
    w, seen = plain.window, 0
    motion_only = [plain.classes.index(c) for c in ("backlash", "friction")]
    for t in range(ticks):
        ra = plain.step(a, [t], [0.05 * (t + 1)], x[t : t + 1])
        rb = gated.step(b, [t], [0.05 * (t + 1)], x[t : t + 1])
        if ra.status[0] != DECIDED:
            continue
        moved = np.zeros((1, 6), bool)
        moved[0, 2] = spike <= t <= spike + w - 1  # the spike lies in the window ending at t
        want = hide_unobservable(ra.probs, ra.joint_scores, moved, plain.classes)
        np.testing.assert_allclose(rb.probs, want, atol=1e-6)
        if not moved.any():
            assert (rb.probs[0, motion_only] == 0).all()
        else:
            seen += 1
            assert rb.probs[0, motion_only].sum() > 0 or ra.probs[0, motion_only].sum() == 0
    assert seen == w  # exactly the W windows that hold the spike


def test_the_monitor_refuses_an_unknown_observability(deployed, capsys):
    with pytest.raises(SystemExit) as info:
        monitor_main([f"model={deployed['structural_onnx']}", "observability=moving"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("monitor: error: observability must be one of"), err
    assert len(err.strip().splitlines()) == 1
