"""Friction and backlash read from their own channels, in severity units, tick by tick."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.channels import (
    CHANNELS,
    ChannelSums,
    channel_readings,
    fit_scales,
)
from robohealth_mj.prognostics.index_model import ChannelFits, FittedIndex, IndexModel, fit_index
from robohealth_mj.schema import FAULT_CLASSES, FEATURE_NAMES

J = 2  # joints; nodes: 2 joints then 2 sensor packages


def _ticks(n: int, friction: float = 0.0, gap: float = 0.0, still_joint: int | None = None):
    """Snapshots ``[n, 2J, F]``: each joint turning back and forth; a friction torque against
    the motion shows in the residual, a backlash gap as a lag of its size."""
    x = np.zeros((n, 2 * J, len(FEATURE_NAMES)), np.float32)
    vel = 0.5 * np.sign(np.sin(np.arange(n) / 5.0) + 1e-9)
    for j in range(J):
        x[:, j, FEATURE_NAMES.index("vel")] = 0.0 if j == still_joint else vel
        x[:, j, FEATURE_NAMES.index("effort_residual")] = friction * np.sign(vel)
        x[:, j, FEATURE_NAMES.index("pos_error")] = gap * np.sign(vel)
    return x


def test_a_friction_torque_and_a_gap_read_as_themselves_on_the_turning_joint():
    r = channel_readings(_ticks(200, friction=1.5, gap=0.004, still_joint=1), J)
    assert r[0, 0] == pytest.approx(1.5) and r[1, 0] == pytest.approx(0.004)
    assert np.isnan(r[:6, 1]).all() and np.isnan(r[-1, 1])  # a still joint: no motion channel
    sums = ChannelSums(J)
    for tick in _ticks(200, friction=1.5, gap=0.004):  # the monitor adds one sample at a time
        sums.add(tick)
    batch = channel_readings(_ticks(200, 1.5, 0.004), J)
    assert sums.readings() == pytest.approx(batch, nan_ok=True)


def test_a_few_torque_impulses_lift_the_peak_channel_where_the_spread_barely_moves():
    """A catching gear at low severity: six knocks in a minute of ticks."""
    rng = np.random.default_rng(3)
    healthy = _ticks(1200)
    healthy[:, :J, FEATURE_NAMES.index("effort_residual")] = rng.normal(0.0, 0.2, (1200, J))
    knocked = healthy.copy()
    knocked[rng.choice(1200, 6, replace=False), 0, FEATURE_NAMES.index("effort_residual")] += 1.5
    before, after = channel_readings(healthy, J), channel_readings(knocked, J)
    with np.errstate(invalid="ignore"):  # channels this sample does not carry read NaN
        rise = after[:, 0] / before[:, 0] - 1.0
    assert (
        rise[CHANNELS.index("residual_rms")] < 0.2 and rise[CHANNELS.index("residual_peak")] > 1.0
    )
    assert after[:, 1] == pytest.approx(before[:, 1], nan_ok=True)  # the other joint: untouched


def test_the_scales_are_the_reading_per_unit_severity_of_labelled_episodes(tmp_path):
    parts, labels = [], []
    for sev in (0.3, 0.6, 0.9):  # friction at joint 1 reading 10 N m per unit severity
        parts.append(_ticks(100, friction=10.0 * sev))
        labels.append((FAULT_CLASSES.index("friction"), 1, sev))
        parts.append(_ticks(50))
        labels.append((0, -1, 0.0))
    x = np.concatenate(parts)
    cls = np.concatenate([[c] * len(p) for p, (c, _, _) in zip(parts, labels, strict=True)])
    joint = np.concatenate([[j] * len(p) for p, (_, j, _) in zip(parts, labels, strict=True)])
    sev = np.concatenate([[s] * len(p) for p, (_, _, s) in zip(parts, labels, strict=True)])
    path = tmp_path / "graphs.jsonl.cache.npz"
    np.savez(path, x=x, fault_class=cls, fault_joint=joint, severity=sev)
    scales = fit_scales([path], J)
    assert scales[0, 1] == pytest.approx(10.0) and np.isnan(scales[0, 0])


def test_a_channel_index_reads_the_named_mode_in_severity_units_and_needs_its_scales(tmp_path):
    """A severity head saturated at 0.3 cannot tell 0.2 from 0.7; the friction channel can."""
    scales = np.array([[10.0, 10.0], [0.01, 0.01]])
    modes = np.zeros((4, J))
    modes[1, 0] = 0.3  # the model names friction (mode 1) on joint 0, always reading 0.3

    def day(severity: float) -> dict:
        channel = [[10.0 * severity, 0.1], [0.0, 0.0]]
        return {"truth": [severity, 0.0], "raw": [0.3, 0.0], "raw_moving": [0.3, 0.0],
                "raw_modes": modes.tolist(), "channel": channel}  # fmt: skip

    days = [day(s) for s in np.linspace(0.0, 0.8, 40)]
    fitted = fit_index(IndexModel("channel", "pooled"), days, ChannelFits(scales))
    head_only = fit_index(IndexModel("moving", "pooled"), days)
    assert fitted.calibrate(day(0.2))[0] == pytest.approx(0.2, abs=0.03)
    assert fitted.calibrate(day(0.7))[0] == pytest.approx(0.7, abs=0.03)
    assert head_only.calibrate(day(0.2))[0] == head_only.calibrate(day(0.7))[0]
    path = tmp_path / "index.json"
    path.write_text(json.dumps(fitted.to_json()))
    assert FittedIndex.load(path).calibrate(day(0.5)) == pytest.approx(fitted.calibrate(day(0.5)))
    path.write_text(json.dumps({**fitted.to_json(), "channel_scales": None}))
    with pytest.raises(InputError, match="without channel_scales"):
        FittedIndex.load(path)
