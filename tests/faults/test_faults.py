"""Fault modes act on the physics (or the sensor), the scheduler covers every scenario, and a
fault is undone exactly when it ends."""

from __future__ import annotations

import copy
import functools
import json

import numpy as np
import pytest
from omegaconf import OmegaConf

from robohealth_mj.common.config import compose_config
from robohealth_mj.faults.catalogue import MODES, FaultParameters, Scenario
from robohealth_mj.faults.mechanical import DriveFaults
from robohealth_mj.faults.scheduler import FaultScheduler, FixedFault
from robohealth_mj.recording.effect_sizes import _readings, by_hops, effect_by_sensor
from robohealth_mj.recording.recorder import build_simulator
from robohealth_mj.schema import JOINT_NAMES

SECONDS = 8.0


def _run(*overrides: str, seconds: float = SECONDS) -> tuple[dict[str, np.ndarray], list]:
    """Every per-tick array of a short run's chunks, concatenated, and the chunks' labels."""
    cfg = compose_config("record", ["seed=3", "session.progress=false", *overrides])
    sim = build_simulator(cfg)
    chunks = list(sim.run(round(seconds / sim.tick_s)))
    arrays = {
        name: np.concatenate([getattr(c, name) for c in chunks])
        for name, value in vars(chunks[0]).items()
        if isinstance(value, np.ndarray) and value.ndim
    }
    return arrays, [c.fault for c in chunks]


def _chunks(*overrides: str, seconds: float = SECONDS) -> dict[str, np.ndarray]:
    return _run(*overrides, seconds=seconds)[0]


def _simulate(*overrides: str):
    """Joint state ``[T, 6, 3]``, sensor readings ``[T, 6, 4]`` and labels of a short run."""
    a, labels = _run(*overrides)
    state = np.stack([a["pos"], a["vel"], a["effort"]], axis=-1)
    sensor = np.concatenate([a["vib"][:, :, None], a["acc"]], axis=-1)
    return state, sensor, labels


def _fixed(fault_class: str, joint: str, *extra: str) -> list[str]:
    return [
        "faults=fixed",
        f"faults.schedule.fault_class={fault_class}",
        f"faults.schedule.joint={joint}",
        *extra,
    ]


@pytest.fixture(scope="module")
def healthy():
    state, sensor, _ = _simulate("faults=none")
    return state, sensor


@pytest.mark.parametrize("fault_class", MODES)
def test_each_fault_changes_its_target_joint_beyond_the_noise(healthy, fault_class):
    joint = JOINT_NAMES.index("elbow")
    state, sensor, labels = _simulate(*_fixed(fault_class, "elbow", "faults.schedule.severity=0.9"))
    assert all(
        lab.active and lab.fault_class == fault_class and lab.joint == "elbow" for lab in labels
    )
    h_state, h_sensor = healthy
    # the target's features: its sensor's readings and its joint state, standardised by the
    # healthy run's spread; the noise floor alone would give ~0 (same seed, same noise draws)
    target = np.concatenate([sensor[:, joint], state[:, joint]], axis=-1)
    base = np.concatenate([h_sensor[:, joint], h_state[:, joint]], axis=-1)
    effect = np.sqrt(((target - base) ** 2).mean(axis=0)) / (base.std(axis=0) + 1e-9)
    assert effect.max() > 0.5, effect


@functools.lru_cache(maxsize=1)
def _healthy_readings(seconds: float) -> np.ndarray:
    return _readings(["seed=3", "faults=none"], seconds)["sensor"]


@pytest.mark.parametrize("fault_class", ["backlash", "jam", "struct_weaken"])
def test_physics_faults_propagate_and_fall_with_hop_distance(fault_class):
    """Measured, not authored: pure physics, one fault at the elbow (mid-chain)."""
    overrides = [
        "faults.fault_model=physics",
        f"faults.schedule.fault_class={fault_class}",
        "faults.schedule.joint=elbow",
        "faults.schedule.severity=0.9",
    ]
    healthy_run = _healthy_readings(20.0)
    faulted = _readings(["seed=3", "faults=fixed", *overrides], 20.0)["sensor"]
    hops = by_hops(effect_by_sensor(healthy_run, faulted), JOINT_NAMES.index("elbow"))
    assert hops[1] > 0.1 and hops[2] > 0.1  # other joints' sensors see it
    # the faulted joint's own sensor sees it most; beyond one hop the fall is not monotonic for
    # every mode (a jam at the elbow: 18.9 own, 7.3 one hop, 7.5 two hops on UR's UR5e inertials,
    # where the light wrist links shake the most)
    assert hops[0] > 1.5 * max(hops[1], hops[2])
    if fault_class != "jam":
        assert hops[1] > hops[2]


def test_physics_friction_raises_the_effort_of_the_target_drive():
    """In physics mode friction acts through the dynamics: the drive works harder."""
    moving = ["curriculum.families=[whole_arm]", "curriculum.speed_scales=[1.0]"]
    h_state, _, _ = _simulate("faults=none", *moving)
    state, _, _ = _simulate(*_fixed("friction", "elbow", "faults.fault_model=physics", *moving))
    j = JOINT_NAMES.index("elbow")
    direction = np.sign(h_state[:, j, 1])  # the same reference motion in both runs

    def along_motion(s: np.ndarray) -> float:  # the torque the drive spends along its motion
        return float((s[:, j, 2] * direction).mean())

    # the drive's own friction costs it torque along the motion (gravity, the larger part of the
    # elbow's torque, is the same in both runs and averages out of this)
    assert along_motion(state) > along_motion(h_state) + 2.0


def test_torque_residual_is_near_zero_healthy_and_rises_by_the_added_friction(model):
    """The drive torque minus the controller's model torque: what a UR's friction monitoring
    watches. Under a friction fault it must carry exactly the friction the model does not know."""
    moving = ["curriculum.families=[whole_arm]", "curriculum.speed_scales=[1.0]"]
    healthy = _chunks("faults=none", *moving)
    faulted = _chunks(*_fixed("friction", "elbow", "faults.schedule.severity=0.9"), *moving)
    j = JOINT_NAMES.index("elbow")
    p = _default_params()["physics"]["friction"]
    dof = int(model.joint("elbow_joint").dofadr[0])
    coulomb = model.dof_frictionloss[dof] * p["coulomb_gain"] * 0.9
    viscous = model.dof_damping[dof] * p["viscous_gain"] * 0.9
    v = healthy["vel"][:, j]
    after_ramp = np.arange(v.size) >= 20  # the fault develops over its first 0.5 s
    moving_ticks = after_ramp & (np.abs(v) > 0.05)
    added = coulomb * np.sign(v) + viscous * v  # what the extra friction costs the drive
    shift = faulted["effort_residual"][:, j] - healthy["effort_residual"][:, j]
    healthy_rms = np.sqrt((healthy["effort_residual"][moving_ticks, j] ** 2).mean())
    assert healthy_rms < 0.1 * np.abs(added[moving_ticks]).mean()
    slope = (shift[moving_ticks] @ added[moving_ticks]) / (
        added[moving_ticks] @ added[moving_ticks]
    )
    assert 0.8 < slope < 1.2, slope


def test_a_softer_drive_moves_the_piezo_energy_to_a_lower_band():
    """Lower the distal drive's stiffness 4x (its resonance halves); a jam's impacts excite it."""
    jam = _fixed("jam", "wrist_3", "faults.schedule.severity=0.5")

    def band_centroid(stiffness: float) -> float:
        run = _chunks(*jam, f"+sim.drive_overrides={{wrist_3:{{stiffness:{stiffness}}}}}")
        energy = (run["bands"][:, JOINT_NAMES.index("wrist_3")] ** 2).mean(axis=0)
        return float((energy / energy.sum()) @ np.arange(energy.size))

    nominal, softer = band_centroid(100.0), band_centroid(25.0)
    assert softer < 0.6 * nominal, (nominal, softer)


def test_tracking_error_shows_a_backlash_dead_band_under_load(healthy):
    """With a wider dead band the loaded link sits off its target by about the added gap."""
    run = _chunks(*_fixed("backlash", "elbow", "faults.schedule.severity=0.9"))
    h = _chunks("faults=none")
    j = JOINT_NAMES.index("elbow")
    gap = _default_params()["physics"]["backlash"]["gap_rad"] * 0.9
    offset = np.abs(run["pos_error"][40:, j]).mean()
    assert np.abs(h["pos_error"][40:, j]).mean() < 0.1 * gap
    assert 0.5 * gap < offset < 1.5 * gap, (offset, gap)


def test_analytic_mode_leaves_the_physics_healthy(healthy):
    state, sensor, _ = _simulate(*_fixed("jam", "elbow", "faults.fault_model=analytic"))
    h_state, h_sensor = healthy
    np.testing.assert_array_equal(state, h_state)  # same dynamics, same noise
    assert not np.array_equal(sensor, h_sensor)  # the painted signature


def test_sensor_drift_changes_only_its_own_sensor(healthy):
    state, sensor, _ = _simulate(*_fixed("sensor_drift", "wrist_1"))
    h_state, h_sensor = healthy
    j = JOINT_NAMES.index("wrist_1")
    others = [k for k in range(6) if k != j]
    np.testing.assert_array_equal(state, h_state)
    np.testing.assert_array_equal(sensor[:, others], h_sensor[:, others])
    drift = np.abs(sensor[:, j, 1:] - h_sensor[:, j, 1:]).mean(axis=-1)
    assert drift[-20:].mean() > 5 * drift[:20].mean()  # it accumulates


def test_a_pass_covers_all_108_scenarios_exactly_once():
    sched = FaultScheduler(tick_s=0.05, seed=9)
    assert sched.pass_ticks == 108 * 400
    for pass_index in (0, 1):
        seen = []
        for k in range(108):
            tick = (pass_index * 108 + k) * sched.scenario_ticks
            faulted = sched.interval_at(tick + 10)
            healthy = sched.interval_at(tick + sched.fault_ticks + 10)
            assert faulted.scenario is not None and healthy.scenario is None
            assert faulted.end_tick - faulted.start_tick == 240  # 12 s
            assert healthy.end_tick - healthy.start_tick == 160  # 8 s
            seen.append(faulted.scenario)
        assert len(set(seen)) == 108
        assert {s.severity for s in seen} == {0.3, 0.6, 0.9}
    first = [sched.scenario(k) for k in range(108)]
    second = [sched.scenario(108 + k) for k in range(108)]
    assert first != second  # reshuffled per pass
    assert first == [FaultScheduler(tick_s=0.05, seed=9).scenario(k) for k in range(108)]


def test_mechanical_faults_are_undone_exactly(model):
    m = copy.copy(model)
    params = FaultParameters(**_default_params()).physics
    drives = DriveFaults(m, params)
    before = {f: getattr(m, f).copy() for f in DriveFaults._FIELDS}
    for mode in ("backlash", "friction", "struct_weaken"):
        drives.apply(m, Scenario(mode, 2, 0.9))
        assert any(not np.array_equal(getattr(m, f), before[f]) for f in before), mode
        drives.apply(m, None)
        for f in before:
            assert np.array_equal(getattr(m, f), before[f]), (mode, f)


def test_a_fixed_fault_ends_and_the_drives_return_to_nominal(record_cfg):
    sim = build_simulator(
        record_cfg(
            "faults=fixed",
            "faults.schedule.fault_class=struct_weaken",
            "faults.schedule.onset_s=1.0",
            "faults.schedule.end_s=3.0",
        )
    )
    nominal = sim.model.tendon_stiffness.copy()
    assert not any(c.fault.active for c in sim.run(20))  # 0-1 s healthy
    assert all(c.fault.active for c in sim.run(20))  # 1-2 s: developed by now
    weakened = sim.model.tendon_stiffness.copy()
    assert weakened[2] == pytest.approx(nominal[2] * (1 - 0.85 * 0.9))
    assert all(c.fault.active for c in sim.run(20))  # 2-3 s: clears inside the interval
    np.testing.assert_array_equal(sim.model.tendon_stiffness, nominal)
    assert not any(c.fault.active for c in sim.run(20))
    np.testing.assert_array_equal(sim.model.tendon_stiffness, nominal)


def test_randomised_parameters_are_drawn_from_the_seed_and_recorded():
    a = FaultParameters(**_default_params(), randomise=True, spread=0.4, seed=1)
    b = FaultParameters(**_default_params(), randomise=True, spread=0.4, seed=1)
    c = FaultParameters(**_default_params(), randomise=True, spread=0.4, seed=2)
    nominal = FaultParameters(**_default_params())
    assert a.as_dict() == b.as_dict() != c.as_dict()
    gap = a.physics["backlash"]["gap_rad"] / nominal.physics["backlash"]["gap_rad"]
    assert 0.6 <= gap <= 1.4 and gap != 1.0
    assert a.as_dict()["randomised"] is True


def test_bad_fault_config_is_a_clear_error():
    with pytest.raises(ValueError, match="unknown fault class"):
        Scenario("rust", 0, 0.5)
    with pytest.raises(ValueError, match="severity"):
        Scenario("jam", 0, 1.5)
    with pytest.raises(ValueError, match="unknown joint"):
        FixedFault(0.05, "jam", "knee", 0.5)
    with pytest.raises(ValueError, match="whole number"):
        FaultScheduler(tick_s=0.05, fault_s=12.01)


def _default_params() -> dict:
    p = OmegaConf.to_container(compose_config("record").fault_params)
    return {"physics": p["physics"], "analytic": p["analytic"]}


def test_effects_tool_prints_a_row_per_fault_joint_and_severity(capsys, tmp_path):
    from robohealth_mj.effects import main as effects_main

    out = tmp_path / "rows.json"
    args = ["--seconds", "2", "--classes", "friction", "--joints", "elbow", "wrist_3"]
    effects_main([*args, "--severities", "0.9", "--json", str(out)])
    printed = [line for line in capsys.readouterr().out.splitlines() if line.startswith("friction")]
    assert len(printed) == 2
    rows = json.loads(out.read_text())
    assert [r["joint"] for r in rows] == ["elbow", "wrist_3"]
    assert all(r["channels"]["effort_residual"] > 3.0 for r in rows)  # the drive works harder


def test_effect_sizes_are_measured_on_a_seven_joint_arm_by_its_joint_names():
    """``effects --arm fr3``: the FR3's own joints, seven sensors, hops along its chain; its
    torque sensors read the link side, so a drive's friction barely moves their residual while
    the tracking error shows it; a joint the arm lacks is one line."""
    from robohealth_mj.common.errors import InputError
    from robohealth_mj.recording.effect_sizes import sweep

    (row,) = sweep(["friction"], ["fr3_joint4"], [0.9], ["physics"], 6.0, 0, arm="fr3")
    assert row["joint"] == "fr3_joint4" and len(row["effect_by_sensor"]) == 7
    assert set(row["effect_by_hops"]) == {0, 1, 2, 3}
    assert row["channels"]["pos_error"] > 5 * row["channels"]["effort_residual"]
    with pytest.raises(InputError, match="'elbow' is not a joint of this arm"):
        list(sweep(["jam"], ["elbow"], [0.9], ["physics"], 2.0, 0, arm="fr3"))
