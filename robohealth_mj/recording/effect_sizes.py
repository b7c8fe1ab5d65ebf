"""Measured fault effect sizes: how far a fault moves each channel, at its joint and by hops.

The same session (seed, trajectory, noise draws) is simulated healthy and with one fault held on;
the effect on a channel is the RMS of the faulted-minus-healthy difference divided by the healthy
channel's standard deviation: the change a detector watching that channel would see against its
healthy baseline. Nothing here is authored: propagation is whatever the physics does.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from functools import lru_cache

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.config import arm_override, compose_config
from robohealth_mj.common.errors import InputError
from robohealth_mj.recording.recorder import build_simulator, chunk_features

SIGNALS = schema.FEATURE_NAMES[schema.STATE_CHANNELS.start :]
SENSOR_SIGNALS = schema.FEATURE_NAMES[schema.SENSOR_CHANNELS]


def _readings(overrides: Sequence[str], seconds: float) -> dict[str, np.ndarray]:
    """Node features ``x [T, 2J, F]`` of a simulated run (any arm: ``arm=`` among the
    overrides), plus the per-joint views the older callers use: ``sensor [T, J, S]`` (sensor
    nodes) and ``effort [T, J]``, and the arm's ``joints``."""
    cfg = compose_config("record", ["session.progress=false", *overrides])
    sim = build_simulator(cfg)
    x = np.concatenate([chunk_features(c) for c in sim.run(round(seconds / sim.tick_s))])
    j = sim.graph.n_joints
    return {
        "x": x,
        "sensor": x[:, j:, schema.SENSOR_CHANNELS],
        "effort": x[:, :j, schema.feature_index("effort")],
        "joints": sim.graph.joints,
    }


def standardised_effect(healthy: np.ndarray, faulted: np.ndarray) -> np.ndarray:
    """RMS(faulted - healthy) / std(healthy) over time (axis 0), per remaining index."""
    scale = healthy.std(axis=0) + 1e-9
    return np.sqrt(((faulted - healthy) ** 2).mean(axis=0)) / scale


def effect_by_sensor(healthy: np.ndarray, faulted: np.ndarray) -> np.ndarray:
    """Standardised effect per sensor ``[J]``, mean over its channels ``[T, J, S]``."""
    return standardised_effect(healthy, faulted).mean(axis=-1)


def by_hops(effect: np.ndarray, joint: int) -> dict[int, float]:
    hops = np.abs(np.arange(len(effect)) - joint)
    return {int(h): float(effect[hops == h].mean()) for h in sorted(set(hops.tolist()))}


def channel_effects(healthy_x: np.ndarray, faulted_x: np.ndarray, joint: int) -> dict[str, float]:
    """Effect on every signal channel of the faulted joint's own nodes: joint-state channels on
    the joint node, sensor channels on its sensor node."""
    effect = standardised_effect(healthy_x, faulted_x)  # [2J, F]
    out = {}
    for name in SIGNALS:
        c = schema.feature_index(name)
        node = len(effect) // 2 + joint if name in SENSOR_SIGNALS else joint
        out[name] = float(effect[node, c])
    return out


@lru_cache(maxsize=4)
def _healthy(seed: int, seconds: float, extra: tuple[str, ...]) -> dict[str, np.ndarray]:
    return _readings([f"seed={seed}", *extra, "faults=none"], seconds)


def measure(
    fault_class: str,
    joint: str,
    severity: float,
    fault_model: str,
    seconds: float,
    seed: int = 0,
    extra: Sequence[str] = (),
) -> dict:
    """One row: per-channel effect at the faulted joint, sensor effect by hops, effort shift."""
    healthy = _healthy(seed, seconds, tuple(extra))
    if joint not in healthy["joints"]:
        raise InputError(f"--joints: {joint!r} is not a joint of this arm ({healthy['joints']})")
    faulted = _readings(
        [
            f"seed={seed}",
            *extra,
            "faults=fixed",
            f"faults.fault_model={fault_model}",
            f"faults.schedule.fault_class={fault_class}",
            f"faults.schedule.joint={joint}",
            f"faults.schedule.severity={severity}",
        ],
        seconds,
    )
    j = healthy["joints"].index(joint)
    sensors = effect_by_sensor(healthy["sensor"], faulted["sensor"])
    effort_shift = float(
        np.abs(faulted["effort"][:, j]).mean() - np.abs(healthy["effort"][:, j]).mean()
    )
    return {
        "fault": fault_class,
        "joint": joint,
        "severity": severity,
        "fault_model": fault_model,
        "channels": {
            k: round(v, 3) for k, v in channel_effects(healthy["x"], faulted["x"], j).items()
        },
        "effect_by_sensor": sensors.round(4).tolist(),
        "effect_by_hops": by_hops(sensors, j),
        "target_effort_shift_nm": round(effort_shift, 4),
    }


def sweep(
    classes: Iterable[str],
    joints: Iterable[str],
    severities: Iterable[float],
    models: Iterable[str],
    seconds: float,
    seed: int,
    arm: str | None = None,
) -> Iterable[dict]:
    """Rows for every fault x joint x severity x fault model, in that nesting order, on ``arm``
    (a shipped arm's name or a URDF; default the UR5e)."""
    extra = tuple(arm_override(f"arm={arm}")) if arm else ()
    for fault_class in classes:
        for joint in joints:
            for severity in severities:
                for model in models:
                    yield measure(fault_class, joint, severity, model, seconds, seed, extra)


# Columns of the printed table: the faulted joint's channels, grouped as the README shows them.
COLUMNS = {
    "pos_err": ("pos_error",),
    "residual": ("effort_residual",),
    "effort": ("effort",),
    "vib": ("vib",),
    "bands": ("vib_20_80", "vib_80_200", "vib_200_450"),
    "kurt": ("vib_kurtosis",),
    "acc": ("acc_x", "acc_y", "acc_z"),
}


def table_row(row: dict) -> list[float]:
    """The max effect within each column group, then the 1-hop sensor effect."""
    values = [max(row["channels"][c] for c in group) for group in COLUMNS.values()]
    return [*values, row["effect_by_hops"].get(1, float("nan"))]
