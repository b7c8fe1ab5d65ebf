"""The z-scoring refitted at commissioning: an arm's healthy running reads as the training arms'
healthy running did, place by place, and a fault still departs from it."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.deploy.renormalise import healthy_moments, match_healthy


def _z(x: np.ndarray, mean: np.ndarray, std: np.ndarray) -> np.ndarray:
    return (x - mean) / std


@pytest.fixture
def arms() -> dict[str, np.ndarray]:
    """Healthy node features ``[T, 3, 2]`` of the training arms and of an arm whose second node
    runs at three times the spread and 5 above, and whose first node's second channel is a
    type flag (constant on both)."""
    rng = np.random.default_rng(0)
    ref = rng.normal(1.0, 0.5, size=(4000, 3, 2))
    ref[:, 0, 1] = 1.0
    arm = rng.normal(1.0, 0.5, size=(4000, 3, 2))
    arm[:, 1] = 3.0 * arm[:, 1] + 5.0
    arm[:, 0, 1] = 1.0
    return {"ref": ref, "arm": arm}


def test_moments_map_the_arms_healthy_running_onto_the_training_arms(arms):
    """Under the training normalisation (fitted on faulted running too, so healthy running is
    not at 0) the refitted one puts the arm's healthy mean and spread where the training arms'
    were, on every live channel."""
    mean, std = np.full((3, 2), 0.7), np.full((3, 2), 0.9)
    mean[0, 1], std[0, 1] = 0.0, 1.0
    new_mean, new_std = match_healthy(
        mean, std, healthy_moments(arms["ref"]), healthy_moments(arms["arm"]), "moments"
    )
    z_ref, z_arm = _z(arms["ref"], mean, std), _z(arms["arm"], new_mean, new_std)
    np.testing.assert_allclose(z_arm.mean(0), z_ref.mean(0), atol=1e-4)
    np.testing.assert_allclose(z_arm.std(0), z_ref.std(0), rtol=1e-4)
    # the type flag keeps its training normalisation
    assert new_mean[0, 1] == mean[0, 1] and new_std[0, 1] == std[0, 1]
    # untouched where the arm is like its training arms, three times the spread where not
    np.testing.assert_allclose(new_std[1], 3.0 * std[1], rtol=0.05)
    np.testing.assert_allclose(new_std[2], std[2], rtol=0.05)


def test_a_fault_departs_in_units_of_the_arms_own_healthy_spread(arms):
    """A step of two of this arm's healthy spreads on its wide node reads as two training
    spreads, as the same step would on a training arm: the fault is neither drowned nor
    magnified by the arm's scale."""
    mean, std = np.zeros((3, 2)), np.ones((3, 2))
    ref_m, arm_m = healthy_moments(arms["ref"]), healthy_moments(arms["arm"])
    new_mean, new_std = match_healthy(mean, std, ref_m, arm_m, "moments")
    step_arm = 2.0 * arm_m[1][1, 0]
    moved = _z(arm_m[0][1, 0] + step_arm, new_mean[1, 0], new_std[1, 0])
    at_rest = _z(arm_m[0][1, 0], new_mean[1, 0], new_std[1, 0])
    assert moved - at_rest == pytest.approx(2.0 * ref_m[1][1, 0], rel=1e-6)


def test_shift_moves_the_offset_and_keeps_the_spread(arms):
    mean, std = np.zeros((3, 2)), np.ones((3, 2))
    new_mean, new_std = match_healthy(
        mean, std, healthy_moments(arms["ref"]), healthy_moments(arms["arm"]), "shift"
    )
    np.testing.assert_array_equal(new_std, std)
    z_ref, z_arm = _z(arms["ref"], mean, std), _z(arms["arm"], new_mean, new_std)
    np.testing.assert_allclose(z_arm.mean(0), z_ref.mean(0), atol=1e-4)


def test_none_keeps_the_training_normalisation_and_a_typo_is_refused(arms):
    mean, std = np.zeros((3, 2)), np.ones((3, 2))
    moments = healthy_moments(arms["ref"]), healthy_moments(arms["arm"])
    kept = match_healthy(mean, std, *moments, "none")
    assert kept[0] is mean and kept[1] is std
    with pytest.raises(
        ValueError, match="match: one of none, sensors, shift, moments, got 'moment'"
    ):
        match_healthy(mean, std, *moments, "moment")


def test_sensors_moves_the_packages_offsets_and_leaves_the_joint_states():
    """A package reading gravity of the other sign (a maker's axis pointing down) is moved onto
    the training arms' reading; the same arm's other poses and loads, in its joint states, stay
    as they are: the model still sees the torques they bring."""
    rng = np.random.default_rng(1)
    ref = rng.normal(0.0, 1.0, size=(3000, 2, schema.N_FEATURES))
    arm = ref + 4.0  # every channel 4 off
    acc_z = schema.feature_index("acc_z")
    ref[:, 1, acc_z] += 9.8
    arm[:, 1, acc_z] -= 9.8
    mean, std = np.zeros((2, schema.N_FEATURES)), np.ones((2, schema.N_FEATURES))
    new_mean, new_std = match_healthy(
        mean, std, healthy_moments(ref), healthy_moments(arm), "sensors"
    )
    np.testing.assert_array_equal(new_std, std)
    state, sensors = slice(0, schema.SENSOR_CHANNELS.start), schema.SENSOR_CHANNELS
    np.testing.assert_array_equal(new_mean[:, state], mean[:, state])
    z_ref, z_arm = ref.mean(0), arm.mean(0) - new_mean
    np.testing.assert_allclose(z_arm[:, sensors], z_ref[:, sensors], atol=1e-9)
    assert z_arm[1, acc_z] == pytest.approx(z_ref[1, acc_z])
