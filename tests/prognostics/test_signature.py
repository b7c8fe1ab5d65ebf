"""The four mechanical modes told apart and read from the recorded channels alone, on small
recordings whose physics the test writes: friction a torque against the motion, backlash a dead
zone in the lag, a softer drive a lag in proportion to the torque, a catching gear torque
impulses; a healthy joint's readings rise with its speed."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.channels import CHANNELS, channel_readings
from robohealth_mj.prognostics.health import MECHANICAL_CLASSES
from robohealth_mj.prognostics.index_model import ChannelFits, FittedIndex, IndexModel, fit_index
from robohealth_mj.prognostics.signature import Signatures, adapt, fit_signatures
from robohealth_mj.schema import FAULT_CLASSES, FEATURE_NAMES

J = 2
F = {name: i for i, name in enumerate(FEATURE_NAMES)}


def _ticks(
    n: int,
    rng,
    speed: float,
    mode: str | None = None,
    joint: int = 0,
    s: float = 0.0,
    episode: bool = False,
):
    """Snapshots ``[n, 2J, F]`` of two joints turning back and forth at ``speed``; the healthy
    tracking error and torque residual grow with the speed. In a short labelled ``episode`` a
    backlash also rings the sensor's high band (an onset transient whole days do not show)."""
    x = np.zeros((n, 2 * J, len(FEATURE_NAMES)), np.float32)
    t = np.arange(n)
    vel = speed * np.sign(np.sin(t / 5.0) + 1e-9)
    effort = 5.0 * np.sin(t / 7.0) + 2.0
    for j in range(J):
        residual = 0.1 * speed * np.sign(vel) + rng.normal(0, 0.05, n)
        pos_error = 1e-4 * speed * np.sign(vel) + rng.normal(0, 2e-5, n)
        if j == joint and mode == "friction":  # a torque against the motion, and a lag
            residual += 1.0 * s * np.sign(vel)
            pos_error -= 3e-4 * s * np.sign(vel)
        if j == joint and mode == "backlash":
            pos_error += 4e-3 * s * np.sign(effort)
            x[:, J + j, F["vib_200_450"]] += 0.01 * s * episode
        if j == joint and mode == "struct_weaken":
            pos_error += 4e-4 * s * effort
        if j == joint and mode == "jam":
            hits = rng.random(n) < 0.2 * s
            residual += hits * 8.0 * s * rng.choice([-1.0, 1.0], n)  # impulses either way
        x[:, j, F["vel"]], x[:, j, F["effort"]] = vel, effort
        x[:, j, F["effort_residual"]], x[:, j, F["pos_error"]] = residual, pos_error
        x[:, J + j, F["vib"]] = 0.01 + rng.normal(0, 1e-3, n)
        x[:, J + j, F["vib_200_450"]] += 0.001 + rng.normal(0, 1e-4, n)
    return x


def _recording(path, rng) -> None:
    """A labelled recording: every mode on every joint at 0.3, 0.6 and 0.9, at three speeds,
    between healthy stretches."""
    parts, labels = [], []
    for speed in (0.3, 0.6, 1.0):
        for mode in MECHANICAL_CLASSES:
            for joint in range(J):
                for s in (0.3, 0.6, 0.9):
                    parts.append(_ticks(300, rng, speed, mode, joint, s, episode=True))
                    labels.append((FAULT_CLASSES.index(mode), joint, s))
                    parts.append(_ticks(300, rng, speed * rng.uniform(0.8, 1.2)))
                    labels.append((0, -1, 0.0))
    label = [np.concatenate([np.full(len(p), lab[k]) for p, lab in zip(parts, labels, strict=True)])
             for k in range(3)]  # fmt: skip
    np.savez(path, x=np.concatenate(parts), fault_class=label[0], fault_joint=label[1],
             severity=label[2])  # fmt: skip


def _day(rng, mode: str | None, joint: int, s: float, speed: float):
    """A day's readings ``[C, J]``, its truth ``[J]`` and mode index."""
    r = channel_readings(_ticks(1500, rng, speed, mode, joint, s), J)
    truth = np.zeros(J)
    truth[joint] = s if mode else 0.0
    return r, truth, MECHANICAL_CLASSES.index(mode) if mode else -1


@pytest.fixture(scope="module")
def signatures(tmp_path_factory) -> Signatures:
    rng = np.random.default_rng(7)
    path = tmp_path_factory.mktemp("signature") / "graphs.jsonl.cache.npz"
    _recording(path, rng)
    days = [_day(rng, mode, j, s, speed) for mode in (*MECHANICAL_CLASSES, None)
            for j in range(J) for s in (0.2, 0.5, 0.8) for speed in (0.4, 0.9)]  # fmt: skip
    return adapt(fit_signatures([path], J), days)


@pytest.mark.parametrize("mode", MECHANICAL_CLASSES)
def test_each_mode_is_named_and_read_from_the_channels_alone(signatures, mode):
    rng = np.random.default_rng(11)
    for joint, s, speed in ((0, 0.45, 0.5), (1, 0.7, 0.8)):
        r, _, m = _day(rng, mode, joint, s, speed)
        called, severity, _ = signatures.call(r)
        assert MECHANICAL_CLASSES[called[joint]] == mode
        assert severity[joint] == pytest.approx(s, abs=0.08)
        assert severity[1 - joint] == 0.0  # the other joint is healthy
        assert signatures.read(r, np.full(J, m))[joint] == pytest.approx(s, abs=0.08)


def test_a_channel_whole_days_do_not_bear_out_is_not_read(signatures):
    backlash = MECHANICAL_CLASSES.index("backlash")
    high, lag = CHANNELS.index("vibration_high"), CHANNELS.index("lag")
    assert not signatures.use[backlash, high] and signatures.use[backlash, lag]
    assert signatures.use[MECHANICAL_CLASSES.index("jam"), CHANNELS.index("residual_rms")]


def test_a_healthy_joint_reads_no_wear_at_any_speed_though_its_readings_rise_with_it(signatures):
    rng = np.random.default_rng(3)
    slow, fast = (channel_readings(_ticks(1500, rng, v), J) for v in (0.3, 1.0))
    lag = CHANNELS.index("lag_against_motion")
    assert fast[lag, 0] > 2 * slow[lag, 0]  # the healthy level follows the speed
    short = [channel_readings(_ticks(150, rng, v), J) for v in rng.uniform(0.3, 1.0, 10)]
    for r in (slow, fast, *short):
        assert (signatures.call(r)[1] == 0.0).all()
    no_detect = dataclasses.replace(signatures, detect=0.0)  # noise alone then reads as wear
    assert max(no_detect.call(r)[1].max() for r in short) > 0.0


def _by_hand(margin: float, joints: int = 1) -> Signatures:
    """Healthy level 0 and spread 1 on every joint: backlash lags, a softer drive lags nearly as
    much per unit severity (and opens a little gap), friction alone raises the friction
    channel, a jam (weakly) the vibration."""
    c, m = len(CHANNELS), len(MECHANICAL_CLASSES)
    response = np.zeros((m, c, joints, 4))
    lag, gap, friction = (CHANNELS.index(k) for k in ("lag", "gap", "friction"))
    response[MECHANICAL_CLASSES.index("backlash"), lag, :, 0] = 100.0
    response[MECHANICAL_CLASSES.index("struct_weaken"), lag, :, 0] = 90.0
    response[MECHANICAL_CLASSES.index("struct_weaken"), gap, :, 0] = 5.0
    response[MECHANICAL_CLASSES.index("friction"), friction, :, 0] = 100.0
    response[MECHANICAL_CLASSES.index("jam"), CHANNELS.index("vibration"), :, 0] = 10.0
    use = np.ones((m, c), bool)
    use[:, CHANNELS.index("speed")] = False
    return Signatures(np.zeros((c, joints, 3)), np.ones((c, joints)), response, use, 16.0, margin)


def test_a_call_is_sure_only_where_no_other_mode_explains_the_readings_nearly_as_well():
    signatures = _by_hand(margin=0.7)
    friction_day, lag_day = np.zeros((len(CHANNELS), 1)), np.zeros((len(CHANNELS), 1))
    friction_day[CHANNELS.index("friction")] = 40.0
    lag_day[CHANNELS.index("lag")] = 40.0
    mode, severity, sure = signatures.call(friction_day)
    assert MECHANICAL_CLASSES[mode[0]] == "friction" and severity[0] == 0.4 and sure[0]
    mode, severity, sure = signatures.call(lag_day)
    assert MECHANICAL_CLASSES[mode[0]] == "backlash" and severity[0] == 0.4 and not sure[0]
    assert _by_hand(margin=0.0).call(lag_day)[2][0]  # with no margin any detected call is sure
    assert not signatures.call(np.zeros((len(CHANNELS), 1)))[2][0]  # nothing to call


def test_a_mode_that_barely_moves_the_channels_is_not_read_from_them():
    """A jam that moves the vibration 10 spreads at full severity: a day 5 spreads up reads
    0.5, but one spread of noise would move that by 0.1, so the call is not sure."""
    day = np.zeros((len(CHANNELS), 1))
    day[CHANNELS.index("vibration")] = 5.0
    mode, severity, sure = _by_hand(margin=0.7).call(day)
    assert MECHANICAL_CLASSES[mode[0]] == "jam" and severity[0] == 0.5 and not sure[0]
    size = _by_hand(margin=0.7).size(0.5, np.array([0.3]))[:, 0]
    assert size[MECHANICAL_CLASSES.index("jam")] == pytest.approx(5.0)
    assert size[MECHANICAL_CLASSES.index("friction")] == pytest.approx(50.0)


def test_a_mode_felt_on_two_joints_is_called_sure_only_where_it_shows_most():
    """A catching gear's impulses reach the neighbouring joints, weaker: the source keeps the
    call, the neighbour falls back to the window model's reading."""
    day = np.zeros((len(CHANNELS), 2))
    day[CHANNELS.index("friction")] = (40.0, 15.0)
    mode, severity, sure = _by_hand(margin=0.7, joints=2).call(day)
    assert (mode == MECHANICAL_CLASSES.index("friction")).all()
    assert severity.tolist() == [0.4, 0.15] and sure.tolist() == [True, False]


def test_a_joint_that_never_turned_is_not_read(signatures):
    rng = np.random.default_rng(5)
    x = _ticks(500, rng, 0.5)
    x[:, 1, F["vel"]] = 0.0
    r = channel_readings(x, J)
    assert np.isnan(signatures.call(r)[1][1]) and np.isfinite(signatures.call(r)[1][0])


def test_a_signature_index_takes_the_sure_calls_and_is_saved_as_the_monitor_reads_it(tmp_path):
    """Where the channels' call is sure the index reads its severity; where it is not, the
    channel form the window model names (here backlash's lag over its scale)."""
    c = len(CHANNELS)
    scales = np.array([[100.0], [200.0]])  # friction's and backlash's reading per unit severity

    def day(severity: float, channel: str) -> dict:
        readings = np.zeros((c, 1))
        readings[CHANNELS.index(channel)] = 100.0 * severity
        modes = np.zeros((4, 1))
        modes[MECHANICAL_CLASSES.index("backlash")] = 0.5  # the window model names backlash
        return {"truth": [severity], "raw": [0.5], "raw_moving": [0.5],
                "raw_modes": modes.tolist(), "channel": readings.tolist()}  # fmt: skip

    fits = ChannelFits(scales, _by_hand(margin=0.7))
    fitted = fit_index(IndexModel("signature", "none"), [day(0.2, "friction")], fits)
    assert fitted.calibrate(day(0.4, "friction"))[0] == pytest.approx(0.4)  # sure: friction
    assert fitted.calibrate(day(0.4, "lag"))[0] == pytest.approx(0.2)  # not sure: 40 / 200
    path = tmp_path / "index.json"
    path.write_text(json.dumps(fitted.to_json()))
    loaded = FittedIndex.load(path)
    for probe in (day(0.4, "friction"), day(0.4, "lag"), day(0.05, "friction")):
        assert loaded.calibrate(probe) == pytest.approx(fitted.calibrate(probe))
    assert loaded.channels.signatures.detect == 16.0 and loaded.channels.signatures.margin == 0.7
    with pytest.raises(InputError, match="needs the channels' signatures"):
        fit_index(IndexModel("signature_named", "pooled"), [day(0.2, "lag")])
    path.write_text(json.dumps({**fitted.to_json(), "channel_scales": None}))
    with pytest.raises(InputError, match="raw=signature without channel_scales"):
        FittedIndex.load(path)
    path.write_text(json.dumps({**fitted.to_json(), "signatures": None}))
    with pytest.raises(InputError, match="raw=signature without signatures"):
        FittedIndex.load(path)
    broken = fitted.to_json()
    broken["signatures"]["channels"] = ["friction", "lag"]
    path.write_text(json.dumps(broken))
    with pytest.raises(InputError, match=r"index.json: signatures: a signature of channels"):
        FittedIndex.load(path)
