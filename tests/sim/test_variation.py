"""Arms that are not the nominal one: the per-session draw of the arm's own parameters."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.config import compose_config
from robohealth_mj.recording.recorder import build_simulator
from robohealth_mj.sim.model import build_model
from robohealth_mj.sim.variation import ArmVariation

SPREAD = ArmVariation(friction=0.3, damping=0.3, stiffness=0.1, armature=0.1, mass=0.15)


def test_the_drawn_arm_is_the_seeds_and_within_its_spreads():
    nominal = build_model()
    a, drawn_a = SPREAD.draw(nominal, 7)
    b, drawn_b = SPREAD.draw(nominal, 7)
    c, drawn_c = SPREAD.draw(nominal, 8)
    assert drawn_a == drawn_b and drawn_a != drawn_c
    for field in ("dof_frictionloss", "dof_damping", "dof_armature", "tendon_stiffness",
                  "body_mass", "body_inertia"):  # fmt: skip
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert not np.array_equal(a.dof_frictionloss, c.dof_frictionloss)
    for name, spread in (("friction", 0.3), ("damping", 0.3), ("mass", 0.15)):
        f = np.array(list(drawn_a[name].values()))
        assert ((1 - spread <= f) & (f <= 1 + spread)).all() and f.std() > 0
    wrist = nominal.body("wrist_1_link").id
    ratio = a.body_mass[wrist] / nominal.body_mass[wrist]
    assert ratio == pytest.approx(drawn_a["mass"]["wrist_1_link"], abs=1e-5)
    assert set(drawn_a["mass"]) == set(load_arm("ur5e").link_bodies)
    again = ArmVariation(**{**SPREAD.spreads(), "seed": 7}).draw(nominal, 99)[1]
    assert again == drawn_a  # the arm's own seed: the same arm in another session
    assert nominal.dof_frictionloss[0] == 3.0  # the nominal model is left as it was
    same, nothing = ArmVariation().draw(nominal, 7)
    assert same is nominal and nothing == {}
    with pytest.raises(ValueError, match=r"arm.mass: a spread in \[0, 1\)"):
        ArmVariation(mass=1.2)


def test_the_physics_runs_the_drawn_arm_and_the_controller_keeps_the_datasheet():
    sim = build_simulator(compose_config("record", ["arm=varied", "seed=3"]))
    nominal = build_model()
    motor = sim.index.motor_dof
    drawn = np.array(list(sim.arm["friction"].values()))
    np.testing.assert_allclose(
        sim.model.dof_frictionloss[motor], nominal.dof_frictionloss[motor] * drawn, rtol=1e-5
    )
    np.testing.assert_allclose(sim.controller.coulomb, nominal.dof_frictionloss[motor])
    np.testing.assert_array_equal(sim.controller.model.body_mass[:-1], nominal.body_mass[:-1])
    assert build_simulator(compose_config("record", ["seed=3"])).arm == {}


def test_each_sensor_package_reads_with_its_drawn_sensitivity_and_noise():
    """The drawn transducers: a package of gain g reads g x the acceleration (MEMS mean and piezo
    level alike), and its noise floor scales with its factor."""
    sim = build_simulator(compose_config("record", ["arm=varied", "seed=3"]))
    gain = np.array(list(sim.arm["sensor_gain"].values()))
    np.testing.assert_allclose(sim.sensors.gain, gain)
    assert ((gain >= 0.9) & (gain <= 1.1)).all() and gain.std() > 0
    package = build_simulator(compose_config("record", ["seed=3"])).sensors
    t = np.arange(0, 0.2, 0.001)
    acc = np.zeros((len(t), 6, 3))
    acc[:, :, 0] = np.sin(2 * np.pi * 120 * t)[:, None]  # in the piezo's band
    plain_mean, plain = package.process(acc, 50)
    package.reset()
    package.gain = np.array([1.0, 2.0, 1.0, 1.0, 0.5, 1.0])
    mean, scaled = package.process(acc, 50)
    np.testing.assert_allclose(mean, plain_mean * package.gain[None, :, None], atol=1e-12)
    np.testing.assert_allclose(scaled.vib, plain.vib * package.gain[None, :], rtol=1e-9)
    package.noise_scale = np.array([1.0, 1.0, 3.0, 1.0, 1.0, 1.0])
    zero = np.zeros((20000, 6, 3))
    _, _, _, noisy = package.add_noise(np.random.default_rng(0), zero[:, :, 0], zero[:, :, 0],
                                       zero[:, :, 0], zero)  # fmt: skip
    std = noisy.std(axis=(0, 2))
    assert std[2] == pytest.approx(3 * std[0], rel=0.05)
