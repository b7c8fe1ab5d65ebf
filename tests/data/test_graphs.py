"""The graphs a model trains on: the structural schema graph, the unknown-placement harness and
its coupling, given as a matrix or read from a file."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.data.graphs import (
    DEFAULT_C0,
    coupling_correlation,
    harness_graph,
    load_coupling,
    structural_graph,
)

F = schema.N_FEATURES


def test_the_structural_graph_is_the_schema_s_and_leaves_snapshots_as_they_are():
    g = structural_graph()
    assert g.name == "structural" and g.node_names == schema.NODE_NAMES
    assert g.num_joints == 6 and g.coupling is None
    np.testing.assert_array_equal(g.adjacency, schema.adjacency())
    x = np.random.default_rng(1).normal(size=(3, 12, F)).astype(np.float32)
    assert g.transform(x) is x
    assert g.as_dict() == {
        "name": "structural", "node_names": list(schema.NODE_NAMES),
        "adjacency": schema.adjacency().tolist(), "num_joints": 6, "coupling": None,
        "sensing": "full", "channel_mask": None, "schema_nodes": 12,
        "classes": list(schema.FAULT_CLASSES), "baseline_shift": None,
        "joints": list(schema.JOINT_NAMES), "coupling_seed": None,
    }  # fmt: skip


def test_the_harness_mixes_in_float32_with_the_coupling_it_is_given():
    c = np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0], [1.0, 1.0], [0.2, 0.0], [0.0, 0.3]])
    g = harness_graph(coupling=c.tolist())
    assert g.name == "harness" and g.coupling.dtype == np.float32
    np.testing.assert_array_equal(g.coupling, c.astype(np.float32))
    assert g.node_names[6:] == ("harness_sensor_0", "harness_sensor_1")
    # the joints keep their kinematic chain; every joint links to every sensor (the placement
    # is not told to message passing); sensors do not link to each other
    expected = np.zeros((8, 8), np.float32)
    for i in range(5):
        expected[i, i + 1] = expected[i + 1, i] = 1.0
    expected[:6, 6:] = expected[6:, :6] = 1.0
    assert g.adjacency.dtype == np.float32
    np.testing.assert_array_equal(g.adjacency, expected)
    x = np.random.default_rng(2).normal(size=(4, 12, F)).astype(np.float32)
    h = g.transform(x)
    assert h.dtype == np.float32 and h.shape == (4, 8, F)
    expected = np.einsum("jm,tjc->tmc", c, x[:, 6:, schema.SENSOR_CHANNELS])
    np.testing.assert_allclose(h[:, 6:, schema.SENSOR_CHANNELS], expected, rtol=1e-5, atol=1e-6)
    assert g.as_dict()["coupling"] == c.astype(np.float32).tolist()
    np.testing.assert_array_equal(harness_graph().coupling, DEFAULT_C0)


@pytest.mark.parametrize("suffix", [".npy", ".json", ".csv"])
def test_a_coupling_file_is_read_in_each_format(tmp_path, suffix):
    path = tmp_path / f"c{suffix}"
    if suffix == ".npy":
        np.save(path, DEFAULT_C0.astype(np.float64))  # read back as float32 all the same
    elif suffix == ".json":
        path.write_text(json.dumps(DEFAULT_C0.tolist()))
    else:
        np.savetxt(path, DEFAULT_C0, delimiter=",")
    c = load_coupling(path)
    assert c.dtype == np.float32
    np.testing.assert_allclose(c, DEFAULT_C0, rtol=1e-6)
    g = harness_graph(coupling_file=str(path))
    np.testing.assert_allclose(g.coupling, DEFAULT_C0, rtol=1e-6)


def test_a_one_sensor_coupling_file_is_a_column(tmp_path):
    path = tmp_path / "c.csv"
    path.write_text("1\n0.5\n1\n1\n0.2\n0.3\n")  # six joints, one sensor
    c = load_coupling(path)
    assert c.shape == (6, 1) and c.dtype == np.float32
    assert harness_graph(coupling_file=str(path)).node_names[6:] == ("harness_sensor_0",)


@pytest.mark.parametrize(
    "matrix, message",
    [
        (np.ones((1, 4)), r"coupling must be \[J, M\] \(a row per joint\), got \(1, 4\)"),
        (np.ones((6, 0)), r"coupling must be \[J, M\] \(a row per joint\), got \(6, 0\)"),
        (np.ones(6), r"coupling must be \[J, M\] \(a row per joint\), got \(6,\)"),
        (-DEFAULT_C0, "must be >= 0"),
        (np.vstack([np.zeros((1, 4)), np.ones((5, 4))]), "every joint must reach a sensor"),
    ],
    ids=["rows", "no sensors", "1-d", "negative", "unreached joint"],
)
def test_a_bad_coupling_file_names_itself_and_the_problem(tmp_path, matrix, message):
    path = tmp_path / "c.npy"
    np.save(path, matrix)
    with pytest.raises(ValueError, match=message) as info:
        load_coupling(path)
    assert str(info.value).startswith(f"{path}: ")


def test_a_coupling_of_another_joint_count_is_refused_on_the_arm(tmp_path):
    path = tmp_path / "c.npy"
    np.save(path, np.ones((5, 4)))
    with pytest.raises(ValueError, match="the coupling has 5 rows, one per joint; the arm has 6"):
        harness_graph(coupling_file=str(path))


def test_coupling_correlation_needs_one_row_per_joint():
    with pytest.raises(ValueError):
        coupling_correlation(DEFAULT_C0[:5], DEFAULT_C0)


@pytest.mark.parametrize("sensors", [3, 4, 6, 8])
def test_a_random_placement_is_one_matrix_per_seed_with_every_joint_distinguishable(sensors):
    from robohealth_mj.data.graphs import placement_problem, random_coupling

    drawn = [random_coupling(seed, sensors) for seed in range(5)]
    for seed, c in enumerate(drawn):
        assert c.shape == (schema.N_JOINTS, sensors) and c.dtype == np.float32
        np.testing.assert_array_equal(c, random_coupling(seed, sensors))  # same seed, same C
        assert (c >= 0).all() and (c.sum(axis=1) > 0).all()  # every joint reaches a sensor
        assert (c.sum(axis=0) > 0).all()  # every sensor hears some joint
        rows = c / np.linalg.norm(c, axis=1, keepdims=True)
        assert len({tuple(np.round(r, 3)) for r in rows}) == schema.N_JOINTS  # rows distinct
        assert placement_problem(c) is None
    assert len({c.tobytes() for c in drawn}) == 5  # another seed, another placement


def test_placement_problems_are_named():
    from robohealth_mj.data.graphs import placement_problem, random_coupling

    assert placement_problem(DEFAULT_C0) is None
    twin = DEFAULT_C0.copy()
    twin[1] = 2.0 * twin[0]  # the same direction: the joints are indistinguishable
    assert "alike" in placement_problem(twin)
    deaf = np.hstack([DEFAULT_C0, np.zeros((schema.N_JOINTS, 1), np.float32)])
    assert "every sensor" in placement_problem(deaf)
    lost = DEFAULT_C0.copy()
    lost[2] = 0.0
    assert "every joint must reach a sensor" in placement_problem(lost)
    with pytest.raises(ValueError, match="2 to 12 sensors"):
        random_coupling(0, 13)


def test_the_harness_takes_a_seeded_placement_and_only_one_source_of_c0():
    from robohealth_mj.data.graphs import random_coupling

    g = harness_graph(coupling_seed=7, coupling_sensors=6)
    np.testing.assert_array_equal(g.coupling, random_coupling(7, 6))
    assert g.node_names[-1] == "harness_sensor_5" and g.adjacency.shape == (12, 12)
    with pytest.raises(ValueError, match="set one of coupling, coupling_file, coupling_seed"):
        harness_graph(coupling=DEFAULT_C0, coupling_seed=7)


def test_a_seeded_placement_is_chosen_from_the_command_line():
    from hydra.utils import instantiate

    from robohealth_mj.common.config import compose_config
    from robohealth_mj.data.graphs import random_coupling

    cfg = compose_config(
        "train", ["graph=harness", "graph.coupling_seed=3", "graph.coupling_sensors=8"]
    )
    g = instantiate(cfg.graph)
    np.testing.assert_array_equal(g.coupling, random_coupling(3, 8))
    assert len(g.node_names) == schema.N_JOINTS + 8
