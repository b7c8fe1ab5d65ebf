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
from robohealth_mj.prognostics.signature import (
    OUTLIER,
    Signatures,
    _growing_fit,
    adapt,
    fit_signatures,
)
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
    steep: bool = False,
):
    """Snapshots ``[n, 2J, F]`` of two joints turning back and forth at ``speed``; the healthy
    tracking error and torque residual grow with the speed. In a short labelled ``episode`` a
    backlash also rings the sensor's high band (an onset transient whole days do not show). A
    ``steep`` softer drive loses stiffness as the built one does (x (1 - 0.85 s)): its lag grows
    as s / (1 - 0.85 s)."""
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
            pos_error += 4e-4 * (s / (1.0 - 0.85 * s) if steep else s) * effort
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
def world(tmp_path_factory) -> tuple[Signatures, list]:
    """Signatures fitted on a labelled recording's episodes, and whole days to adapt them to."""
    rng = np.random.default_rng(7)
    path = tmp_path_factory.mktemp("signature") / "graphs.jsonl.cache.npz"
    _recording(path, rng)
    days = [_day(rng, mode, j, s, speed) for mode in (*MECHANICAL_CLASSES, None)
            for j in range(J) for s in (0.2, 0.5, 0.8) for speed in (0.4, 0.9)]  # fmt: skip
    return fit_signatures([path], J), days


@pytest.fixture(scope="module")
def signatures(world) -> Signatures:
    return adapt(*world)


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
    by_hand = _by_hand(margin=20.0)  # a jam moves the vibration 10 spreads per unit severity
    noise = np.zeros((len(CHANNELS), 1))
    noise[CHANNELS.index("vibration")] = 3.0  # three spreads of healthy noise on that channel
    assert by_hand.call(noise)[1][0] == 0.0
    no_detect = dataclasses.replace(by_hand, detect=0.0)  # noise alone then reads as wear
    assert no_detect.call(noise)[1][0] == pytest.approx(0.3)


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


def test_a_call_is_sure_only_where_no_other_mode_fits_the_readings_nearly_as_well():
    signatures = _by_hand(margin=20.0)
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
    mode, severity, sure = _by_hand(margin=20.0).call(day)
    assert MECHANICAL_CLASSES[mode[0]] == "jam" and severity[0] == 0.5 and not sure[0]
    size = _by_hand(margin=20.0).size(0.5, np.array([0.3]))[:, 0]
    assert size[MECHANICAL_CLASSES.index("jam")] == pytest.approx(5.0)
    assert size[MECHANICAL_CLASSES.index("friction")] == pytest.approx(50.0)


def test_a_mode_felt_on_two_joints_is_called_sure_only_where_it_shows_most():
    """A catching gear's impulses reach the neighbouring joints, weaker: the source keeps the
    call, the neighbour falls back to the window model's reading."""
    day = np.zeros((len(CHANNELS), 2))
    day[CHANNELS.index("friction")] = (40.0, 15.0)
    mode, severity, sure = _by_hand(margin=20.0, joints=2).call(day)
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

    fits = ChannelFits(scales, _by_hand(margin=20.0))
    fitted = fit_index(IndexModel("signature", "none"), [day(0.2, "friction")], fits)
    assert fitted.calibrate(day(0.4, "friction"))[0] == pytest.approx(0.4)  # sure: friction
    assert fitted.calibrate(day(0.4, "lag"))[0] == pytest.approx(0.2)  # not sure: 40 / 200
    path = tmp_path / "index.json"
    path.write_text(json.dumps(fitted.to_json()))
    loaded = FittedIndex.load(path)
    for probe in (day(0.4, "friction"), day(0.4, "lag"), day(0.05, "friction")):
        assert loaded.calibrate(probe) == pytest.approx(fitted.calibrate(probe))
    assert loaded.channels.signatures.detect == 16.0 and loaded.channels.signatures.margin == 20.0
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


def test_a_channel_that_strays_from_day_to_day_stops_outvoting_one_that_tracks_the_wear():
    """Backlash moves the lag and the dead zone 100 spreads per unit severity, but the dead
    zone's day-to-day fit swings (error 1.0) where the lag tracks (0.05): a day at 0.5 whose
    dead zone read nothing is read from its lag, not split between the two."""
    c = len(CHANNELS)
    error = np.zeros((len(MECHANICAL_CLASSES), c))
    backlash = MECHANICAL_CLASSES.index("backlash")
    lag, gap = CHANNELS.index("lag"), CHANNELS.index("gap")
    error[backlash, lag], error[backlash, gap] = 0.05, 1.0
    exact = _by_hand(margin=20.0)
    response = exact.response.copy()
    response[backlash, gap, :, 0] = 100.0
    exact = dataclasses.replace(exact, response=response)
    scattered = dataclasses.replace(exact, error=error)
    day = np.zeros((c, 1))
    day[lag] = 50.0
    mode = np.array([backlash])
    assert exact.read(day, mode)[0] == pytest.approx(0.25, abs=0.01)
    assert scattered.read(day, mode)[0] == pytest.approx(0.5, abs=0.02)
    again = Signatures.from_json(json.loads(json.dumps(scattered.to_json())), "signatures.json")
    assert again.read(day, mode) == scattered.read(day, mode)


def test_one_channel_that_strays_far_from_its_response_cannot_drag_the_read():
    """A softer drive moves the lag, the compliance and the dead zone 100 spreads per unit
    severity. A day at 0.4 whose lag and compliance read 40 but whose dead zone reads 150 (that
    joint's days stray from the episodes' shape there) reads 0.4 from the two that agree; with
    no limit on one channel's misfit the stray one drags it to 0.77. A saved signature keeps
    its limit; one saved before the limit existed reads without it."""
    c = len(CHANNELS)
    spring = MECHANICAL_CLASSES.index("struct_weaken")
    lag, compliance, gap = (CHANNELS.index(k) for k in ("lag", "compliance", "gap"))
    response = np.zeros((len(MECHANICAL_CLASSES), c, 1, 4))
    response[spring, [lag, compliance, gap], :, 0] = 100.0
    limited = dataclasses.replace(_by_hand(margin=20.0), response=response, outlier=25.0)
    day = np.zeros((c, 1))
    day[lag], day[compliance], day[gap] = 40.0, 40.0, 150.0
    mode = np.array([spring])
    assert limited.read(day, mode)[0] == pytest.approx(0.4, abs=0.01)
    unlimited = dataclasses.replace(limited, outlier=np.inf)
    assert unlimited.read(day, mode)[0] == pytest.approx(0.77, abs=0.01)
    saved = json.loads(json.dumps(limited.to_json()))
    assert Signatures.from_json(saved, "signatures.json").read(day, mode) == limited.read(day, mode)
    del saved["outlier"]
    older = Signatures.from_json(saved, "signatures.json")
    assert older.read(day, mode) == unlimited.read(day, mode)
    with pytest.raises(InputError, match=r"signatures.json: outlier must be a positive misfit"):
        Signatures.from_json({**saved, "outlier": -1.0}, "signatures.json")


def test_the_days_set_how_far_each_channel_strays(world):
    """A lag that swings by a random factor from day to day is given a larger share of error
    than the same lag read faithfully; a channel a mode never reads is given none."""
    episodic, days = world
    rng = np.random.default_rng(13)
    lag, backlash = CHANNELS.index("lag"), MECHANICAL_CLASSES.index("backlash")
    swung = []
    for r, truth, mode in days:
        r = r.copy()
        if mode == backlash:
            r[lag] *= rng.uniform(0.4, 1.6)
        swung.append((r, truth, mode))
    faithful, swinging = adapt(episodic, days).error, adapt(episodic, swung).error
    assert faithful[backlash, lag] < 0.1 and swinging[backlash, lag] > 0.2
    assert (faithful[~adapt(episodic, days).use] == 0).all()
    assert adapt(episodic, days).outlier == OUTLIER  # what a day's severity read is limited by


def _loaded_days(spring: bool, loads=(30.0, 24.0, 36.0, 30.0, 24.0)) -> np.ndarray:
    """``[K, C, 1]`` days of a joint that carries the arm's weight, its lag growing by 2 spreads
    a day: a gap's whatever the load, a spring's in proportion to it (at load 30 the same)."""
    days = np.zeros((len(loads), len(CHANNELS), 1))
    for k, load in enumerate(loads):
        lag = 50.0 + 2.0 * k
        days[k, CHANNELS.index("lag")] = lag * load / 30.0 if spring else lag
        days[k, CHANNELS.index("load")] = load
    return days


def test_the_days_loads_tell_a_gap_from_a_softer_spring_where_a_day_cannot():
    """Within a day both sag by one offset; a gap's lag holds as the payload changes from day
    to day, a spring's follows it. Too few days, or a load that never changed: no verdict."""
    signatures = _by_hand(margin=20.0)
    backlash, spring = (MECHANICAL_CLASSES.index(m) for m in ("backlash", "struct_weaken"))
    assert signatures.settle(_loaded_days(spring=False)).tolist() == [backlash]
    assert signatures.settle(_loaded_days(spring=True)).tolist() == [spring]
    steady = (30.0, 30.3, 29.7, 30.0, 30.2)  # a load that barely changed: no verdict
    assert signatures.settle(_loaded_days(False, steady)).tolist() == [-1]
    assert signatures.settle(_loaded_days(True)[:-1]).tolist() == [-1]


def test_a_call_between_a_gap_and_a_spring_is_settled_by_the_last_days_loads():
    signatures = _by_hand(margin=20.0)
    days = _loaded_days(spring=True)
    mode, _, sure = signatures.call(days[-1])
    assert MECHANICAL_CLASSES[mode[0]] == "backlash" and not sure[0]  # a day alone: a tie
    mode, severity, sure = signatures.call(days[-1], days)
    assert MECHANICAL_CLASSES[mode[0]] == "struct_weaken" and sure[0]
    assert severity[0] == signatures.read(days[-1], mode)[0]
    friction_day = np.zeros((len(CHANNELS), 1))
    friction_day[CHANNELS.index("friction")] = 40.0
    assert MECHANICAL_CLASSES[signatures.call(friction_day, days)[0][0]] == "friction"


def test_a_response_steep_at_the_end_still_reads_light_wear_as_light():
    """A softer drive's lag grows as s / (1 - 0.85 s): fitted at 0.3, 0.6 and 0.9 a plain
    quadratic bends below zero at light wear, and a day worn 0.1 could only read 0.3."""
    sev = np.repeat([0.3, 0.6, 0.9], 4)
    speed = np.tile([0.3, 0.5, 0.7, 0.9], 3)
    design = np.stack([sev, sev * speed, sev**2, sev**2 * speed], axis=1)
    excess = 100.0 * sev / (1.0 - 0.85 * sev)
    plain = np.linalg.lstsq(design, excess, rcond=None)[0]
    signatures = _by_hand(margin=20.0)
    spring, lag = MECHANICAL_CLASSES.index("struct_weaken"), CHANNELS.index("lag")
    day = np.zeros((len(CHANNELS), 1))
    day[lag] = 100.0 * 0.1 / (1.0 - 0.085)
    day[CHANNELS.index("speed")] = 0.6
    reads = []
    for terms in (plain, _growing_fit(design, excess, speed)):
        response = signatures.response.copy()
        response[spring] = 0.0
        response[spring, lag, 0] = terms
        reads.append(dataclasses.replace(signatures, response=response).read(day, [spring])[0])
    assert reads[0] >= 0.2 and reads[1] == pytest.approx(0.1, abs=0.06)


def test_a_mode_cannot_buy_a_loose_fit_by_predicting_a_large_uncertain_excess():
    """A softer drive that also moves the residual's spread, with five times its own size of
    scatter there: predicting 40 spreads it cannot vouch for must cost it, or any stray excess
    on that channel (3 spreads here) would read as its evidence rather than as noise."""
    signatures = _by_hand(margin=20.0)
    spring, rms = MECHANICAL_CLASSES.index("struct_weaken"), CHANNELS.index("residual_rms")
    response = signatures.response.copy()
    response[spring, rms, :, 0] = 100.0
    error = np.zeros(signatures.use.shape)
    error[spring, rms] = 5.0
    day = np.zeros((len(CHANNELS), 1))
    day[CHANNELS.index("lag")], day[rms] = 40.0, 3.0
    loose = dataclasses.replace(signatures, response=response, error=error)
    assert MECHANICAL_CLASSES[loose.call(day)[0][0]] == "backlash"


def test_a_steep_softer_drive_fitted_at_three_severities_reads_light_wear_lightly(tmp_path):
    """Fitted on episodes at 0.3, 0.6 and 0.9 only, a softer drive whose lag steepens toward
    full wear must still grow from no wear: a day worn 0.12 reads near 0.12, not 0.3."""
    rng = np.random.default_rng(23)
    parts, labels = [], []
    for speed in (0.3, 0.6, 1.0):
        for s in (0.3, 0.6, 0.9):
            parts.append(_ticks(300, rng, speed, "struct_weaken", 0, s, steep=True))
            labels.append((FAULT_CLASSES.index("struct_weaken"), 0, s))
            for mode in ("backlash", "friction", "jam"):  # every mode fitted, as the corpus has
                parts.append(_ticks(300, rng, speed, mode, 0, s))
                labels.append((FAULT_CLASSES.index(mode), 0, s))
            parts.append(_ticks(300, rng, speed * rng.uniform(0.8, 1.2)))
            labels.append((0, -1, 0.0))
    label = [np.concatenate([np.full(len(p), lab[k]) for p, lab in zip(parts, labels, strict=True)])
             for k in range(3)]  # fmt: skip
    path = tmp_path / "graphs.jsonl.cache.npz"
    np.savez(path, x=np.concatenate(parts), fault_class=label[0], fault_joint=label[1],
             severity=label[2])  # fmt: skip
    fitted = dataclasses.replace(fit_signatures([path], J), detect=16.0)
    spring = MECHANICAL_CLASSES.index("struct_weaken")
    day = channel_readings(_ticks(1500, rng, 0.6, "struct_weaken", 0, 0.12, steep=True), J)
    assert fitted.read(day, np.full(J, spring))[0] == pytest.approx(0.12, abs=0.05)
