"""Memory in the diagnosis: evidence accumulated over windows, and the alarms reading it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robohealth_mj.runtime.alarms import CLEARED, HELD, NONE, RAISED, AlarmBank, AlarmPolicy
from robohealth_mj.runtime.evidence import EvidenceBank, EvidencePolicy

C = 7  # none + six faults
FAINT = 4  # struct_weaken


def window(top: int, p_top: float, p_none: float | None = None) -> np.ndarray:
    """A window's probabilities ``[1, C]``: ``p_top`` on ``top``, ``p_none`` on none (if
    ``top`` is a fault), the rest shared evenly."""
    p = np.zeros(C)
    p[top] = p_top
    if top != 0 and p_none is not None:
        p[0] = p_none
    rest = [k for k in range(C) if p[k] == 0]
    p[rest] = (1.0 - p.sum()) / len(rest)
    return p[None].astype(np.float32)


def reference(stream: np.ndarray, policy: EvidencePolicy) -> np.ndarray:
    """The accumulated probabilities of a whole stream ``[T, C]``, recomputed from the module
    docstring's formula with Python floats, one tick after another."""
    lam = math.exp(-policy.tick_s / policy.horizon_s)
    evidence = [0.0] * C
    out = []
    for p in stream.astype(np.float64):
        logp = [math.log(max(v, 1e-12)) for v in p]
        top = max(logp)
        total = [lam * e + max(v - top, -policy.clip) for e, v in zip(evidence, logp, strict=True)]
        lead = max(total)
        evidence = [max(v - lead, -policy.floor) for v in total]
        z = [math.exp(v) for v in evidence]
        out.append([v / sum(z) for v in z])
    return np.array(out)


def test_without_memory_the_alarms_read_the_window_itself():
    bank = EvidenceBank(EvidencePolicy(horizon_s=0.0), C, 2)
    p = np.vstack([window(3, 0.6, 0.3), window(0, 0.9)])
    assert bank.update(np.array([0, 1]), p) is p


def test_a_constant_faint_offset_is_detected_after_the_predicted_ticks_and_not_before():
    """Healthy windows rule the fault out to the floor; then every window leans slightly
    towards it (0.5 against 0.4 for none). The fault overtakes none by log(0.5/0.4) a tick, so
    the accumulated probability reaches ``min_confidence`` after exactly the ticks that take,
    and the alarm rises ``raise_after - 1`` ticks later."""
    policy = EvidencePolicy(horizon_s=math.inf, clip=4.0, floor=8.0)
    alarm = AlarmPolicy(raise_after=4, clear_after=10, min_confidence=0.97)
    evidence, alarms = EvidenceBank(policy, C, 1), AlarmBank(alarm, 6, 1)
    slot, scores = np.zeros(1, np.int64), np.eye(6, dtype=np.float32)[[2]]
    healthy, faint = window(0, 0.9), window(FAINT, 0.5, 0.4)
    for _ in range(20):
        evidence.update(slot, healthy)
    # predicted: the others sit at the floor; none must fall log(share) below the fault, where
    # share = (1 - min_conf) / min_conf less the floor's mass of the five other faults
    share = (1 - alarm.min_confidence) / alarm.min_confidence - 5 * math.exp(-policy.floor)
    per_tick = math.log(0.5 / 0.4)
    votes_from = math.ceil((policy.floor - math.log(share)) / per_tick)
    states = []
    for _ in range(votes_from + 10):
        acc = evidence.update(slot, faint)
        state, cls, joint = alarms.update(slot, acc, scores)
        states.append((int(state[0]), int(cls[0]), int(joint[0])))
    rise = votes_from + alarm.raise_after - 1  # 1-based tick of the faint stretch
    assert [s for s, _, _ in states[: rise - 1]] == [NONE] * (rise - 1)
    assert states[rise - 1] == (RAISED, FAINT, 2)
    assert all(s == HELD for s, _, _ in states[rise:])
    # the window alone never votes: 0.5 is far below the confidence an alarm needs
    plain = AlarmBank(alarm, 6, 1)
    assert all(plain.update(slot, faint, scores)[0][0] == NONE for _ in range(200))


def test_neutral_windows_let_the_evidence_decay_with_the_horizon():
    policy = EvidencePolicy(horizon_s=2.0, clip=4.0, floor=8.0)
    bank = EvidenceBank(policy, C, 1)
    slot = np.zeros(1, np.int64)
    for _ in range(10):
        bank.update(slot, window(2, 0.9, 0.05))
    before = bank.evidence[0].copy()
    assert before[2] == 0.0 and before[0] < -2.0
    uniform = np.full((1, C), 1.0 / C, np.float32)
    for _ in range(15):
        bank.update(slot, uniform)
    np.testing.assert_allclose(bank.evidence[0], before * policy.decay**15, rtol=1e-6)


def test_state_carried_tick_by_tick_equals_the_whole_stream_recomputed():
    """Three streams interleaved in a random order through one bank: each stream's accumulated
    probabilities equal the reference recomputation of that stream alone."""
    rng = np.random.default_rng(3)
    policy = EvidencePolicy(horizon_s=1.5, clip=2.0, floor=6.0)
    streams = [rng.dirichlet(np.full(C, 0.6), size=80).astype(np.float32) for _ in range(3)]
    bank = EvidenceBank(policy, C, 3)
    got = [np.zeros((80, C)) for _ in range(3)]
    order = rng.permutation(np.repeat(np.arange(3), 80))
    position = [0, 0, 0]
    for s in order.tolist():
        k = position[s]
        got[s][k] = bank.update(np.array([s]), streams[s][k : k + 1])[0]
        position[s] += 1
    for s in range(3):
        np.testing.assert_allclose(got[s], reference(streams[s], policy), rtol=2e-5, atol=1e-7)


def test_the_alarm_on_a_scripted_faint_fault_raises_holds_and_clears():
    """Healthy, a faint fault the window never votes for, a rest where the windows say nothing
    either way (the evidence is kept: the alarm holds), then healthy again until it clears."""
    policy = EvidencePolicy(horizon_s=30.0, clip=2.0, floor=6.0)
    alarm = AlarmPolicy(raise_after=3, clear_after=5, min_confidence=0.95)
    evidence, alarms = EvidenceBank(policy, C, 1), AlarmBank(alarm, 6, 1)
    slot, scores = np.zeros(1, np.int64), np.eye(6, dtype=np.float32)[[5]]
    uniform = np.full((1, C), 1.0 / C, np.float32)
    script = (
        [window(0, 0.9)] * 30 + [window(FAINT, 0.55, 0.35)] * 120 + [uniform] * 40
        + [window(0, 0.95)] * 60
    )  # fmt: skip
    states = []
    for p in script:
        state, cls, joint = alarms.update(slot, evidence.update(slot, p), scores)
        states.append((int(state[0]), int(cls[0]), int(joint[0])))
    kinds = [s for s, _, _ in states]
    assert kinds[:30] == [NONE] * 30
    rise = kinds.index(RAISED)
    assert 30 < rise < 150 and states[rise][1:] == (FAINT, 5)
    assert kinds[rise + 1 : 190] == [HELD] * (190 - rise - 1)  # held through the rest
    clear = kinds.index(CLEARED)
    assert 190 < clear < 190 + 20 and kinds[clear + 1 :] == [NONE] * (len(kinds) - clear - 1)


def test_evidence_policy_rejects_nonsense():
    for bad, message in (
        ({"horizon_s": -1.0}, "horizon_s must be >= 0"),
        ({"tick_s": 0.0}, "tick_s > 0"),
        ({"clip": 0.0}, "clip and floor must be > 0"),
        ({"floor": -1.0}, "clip and floor must be > 0"),
    ):
        with pytest.raises(ValueError, match=message):
            EvidencePolicy(**bad)
    assert EvidencePolicy(horizon_s=math.inf).decay == 1.0
    assert not EvidencePolicy().memory


def test_a_gap_restarts_the_evidence_with_the_window(deployed):
    """After a gap, a stream's accumulated probabilities are those of a stream that started
    there: nothing from before the gap survives."""
    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime

    rec = load_recordings([deployed["heldout"]])
    policy = EvidencePolicy(horizon_s=5.0, clip=4.0, floor=8.0)
    faulted = np.flatnonzero(rec.active)[0]
    before, after = range(faulted, faulted + 40), range(faulted + 60, faulted + 100)

    def run(ticks) -> np.ndarray:
        fleet = FleetRuntime(deployed["structural_onnx"], evidence=policy)
        slot = fleet.register(["arm"])
        out = []
        for k in ticks:
            r = fleet.step(slot, rec.sample_index[k : k + 1], [0.05 * k], rec.x[k : k + 1])
            out.append(r.accumulated[0] if r.status[0] == DECIDED else None)
        return out

    with_gap = run([*before, *after])[len(before) :]
    fresh = run(after)
    decided = [k for k, v in enumerate(fresh) if v is not None]
    assert len(decided) > 20
    for k in decided:
        np.testing.assert_array_equal(with_gap[k], fresh[k])
    without_gap = run(range(faulted + 20, faulted + 100))[40:]
    assert any(
        not np.array_equal(a, b) for a, b in zip(without_gap, fresh, strict=True) if b is not None
    )


def test_the_fleet_s_alarms_read_the_accumulated_probabilities(deployed, deciding_alarm):
    """The alarms a memory-carrying fleet raises are those an alarm bank raises on its
    accumulated probabilities, not on the window's."""
    from robohealth_mj.data.arrays import load_recordings
    from robohealth_mj.runtime.fleet import DECIDED, FleetRuntime

    rec = load_recordings([deployed["heldout"]])
    policy = EvidencePolicy(horizon_s=5.0, clip=1.0, floor=8.0)
    fleet = FleetRuntime(deployed["structural_onnx"], evidence=policy, alarm=deciding_alarm)
    slot = fleet.register(["arm"])
    banks = {
        "accumulated": AlarmBank(deciding_alarm, 6, 1),
        "window": AlarmBank(deciding_alarm, 6, 1),
    }
    got, replayed = [], {"accumulated": [], "window": []}
    for k in range(len(rec)):
        r = fleet.step(slot, rec.sample_index[k : k + 1], [0.05 * k], rec.x[k : k + 1])
        if r.status[0] != DECIDED:
            continue
        got.append((int(r.alarm[0]), int(r.alarm_class[0]), int(r.alarm_joint[0])))
        for key, probs in (("accumulated", r.accumulated), ("window", r.probs)):
            state, cls, joint = banks[key].update(np.zeros(1, np.int64), probs, r.joint_scores)
            replayed[key].append((int(state[0]), int(cls[0]), int(joint[0])))
    assert sum(s == RAISED for s, _, _ in got) >= 5
    assert got == replayed["accumulated"] and got != replayed["window"]
