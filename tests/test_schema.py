"""The GraphSample schema and the strict JSONL reader."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.arrays import common_graph, placed
from robohealth_mj.data.jsonl import format_line, node_features
from robohealth_mj.data.read import read_samples
from robohealth_mj.schema import FaultLabel, SchemaError, validate_sample


def _sample_obj(index: int = 0) -> dict:
    rng = np.random.default_rng(index)
    x = node_features(
        rng.normal(size=(6, len(schema.STATE_FEATURES))),
        rng.normal(size=(6, len(schema.SENSOR_FEATURES))),
    )
    line = format_line(
        "run-a",
        index,
        0.05 * (index + 1),
        x,
        FaultLabel(),
        {"index": 3, "family": "single_joint", "speed_scale": 1.0, "payload_scale": 1.0},
    )
    return json.loads(line)


def test_graph_has_the_canonical_nodes_and_bidirectional_edges():
    assert schema.NODE_NAMES[:6] == schema.JOINT_NAMES
    assert schema.NODE_NAMES[6:] == tuple(f"{j}_sensor" for j in schema.JOINT_NAMES)
    assert len(schema.FEATURE_NAMES) == schema.N_FEATURES == 15
    assert schema.FEATURE_NAMES[schema.SENSOR_CHANNELS] == schema.SENSOR_FEATURES
    edges = set(schema.EDGES)
    assert len(edges) == 2 * 5 + 2 * 6
    assert all((j, i) in edges for i, j in edges)
    a = schema.adjacency()
    np.testing.assert_array_equal(a, a.T)
    assert a[2, 3] == 1 and a[2, 8] == 1 and a[2, 4] == 0 and a[8, 9] == 0
    assert schema.edge_index().shape == (2, 22)


def test_a_formatted_line_validates_and_round_trips():
    obj = _sample_obj()
    sample = validate_sample(obj)
    assert sample.x.shape == (12, schema.N_FEATURES)
    np.testing.assert_array_equal(sample.x[:6, schema.SENSOR_CHANNELS], 0.0)
    np.testing.assert_allclose(
        sample.x[6:, schema.STATE_CHANNELS], sample.x[:6, schema.STATE_CHANNELS]
    )
    assert sample.fault.fault_class == "none" and not sample.fault.active


SEVEN = schema.ArmGraph(tuple(f"joint{k}" for k in range(1, 8)))


def _seven_joint_obj() -> dict:
    rng = np.random.default_rng(7)
    x = node_features(
        rng.normal(size=(7, len(schema.STATE_FEATURES))),
        rng.normal(size=(7, len(schema.SENSOR_FEATURES))),
    )
    fault = FaultLabel("jam", "joint7", 0.6, True)
    segment = {"index": 0, "family": "hold", "speed_scale": 1.0, "payload_scale": 1.0}
    return json.loads(format_line("run-7", 0, 0.05, x, fault, segment, SEVEN))


def test_the_graph_is_the_arms_any_joint_count_and_a_2_0_sample_is_the_ur_graph():
    """Schema 3.0: a seven-joint arm's sample validates on its own graph (14 nodes, 26 edges,
    its joints' names in the label); a 2.0 sample reads as the UR's six-joint graph and only
    that; a sample of another arm than the one expected is refused naming the nodes."""
    sample = validate_sample(_seven_joint_obj())
    assert sample.graph == SEVEN and sample.x.shape == (14, schema.N_FEATURES)
    assert len(SEVEN.edges) == 26 and sample.fault.joint == "joint7"
    old = {**_sample_obj(), "schema_version": "2.0"}
    assert validate_sample(old).graph == schema.UR_GRAPH
    seven_as_old = {**_seven_joint_obj(), "schema_version": "2.0"}
    with pytest.raises(SchemaError, match=r"field 'nodes': node order .* the 2.0 schema's"):
        validate_sample(seven_as_old)
    with pytest.raises(SchemaError, match=r"field 'nodes': node order .* differs from the arm's"):
        validate_sample(_sample_obj(), graph=SEVEN)
    wrong_joint = _seven_joint_obj()
    wrong_joint["fault"]["joint"] = "elbow"
    with pytest.raises(SchemaError, match=r"field 'fault.joint': unknown joint 'elbow'"):
        validate_sample(wrong_joint)
    not_an_arm = {**_seven_joint_obj(), "nodes": [f"n{k}" for k in range(14)]}
    with pytest.raises(SchemaError, match=r"field 'nodes': node order .* is not J joints"):
        validate_sample(not_an_arm)


def _set(path: str, value):
    def edit(obj):
        target = obj
        *parents, last = path.split(".")
        for key in parents:
            target = target[key]
        if value is _DELETE:
            del target[last]
        else:
            target[last] = value(target[last]) if callable(value) else value

    return edit


_DELETE = object()


def _nan_in_x(x):
    x[8][schema.feature_index("acc_x")] = float("nan")
    return x


def _joint_with_vibration(x):
    x[2][schema.feature_index("vib")] = 0.5
    return x


@pytest.mark.parametrize(
    "edit, field",
    [
        (_set("schema_version", "0.9"), "schema_version"),
        (_set("recording_run_id", _DELETE), "recording_run_id"),
        (_set("x", _nan_in_x), "x[elbow_sensor].acc_x"),
        (_set("nodes", lambda n: n[::-1]), "nodes"),
        (_set("edge_index", lambda e: [e[0][:-2], e[1][:-2]]), "edge_index"),
        (_set("x", _joint_with_vibration), "x[elbow].vib"),
        (_set("x", lambda x: x[:11]), "x"),
        (_set("fault.class", "melted"), "fault.class"),
        (_set("fault.severity", 1.5), "fault.severity"),
        (_set("fault.active", True), "fault.active"),
        (_set("segment.payload_scale", _DELETE), "segment.payload_scale"),
        (_set("sample_index", "7"), "sample_index"),
    ],
)
def test_each_schema_violation_names_its_field(edit, field):
    obj = copy.deepcopy(_sample_obj())
    edit(obj)
    with pytest.raises(SchemaError, match=re.escape(f"f.jsonl:4: field '{field}'")):
        validate_sample(obj, source="f.jsonl", line=4)


def _write(path: Path, lines: list[str]) -> Path:
    path.write_text("".join(lines))
    return path


def test_reader_reports_a_truncated_last_line(tmp_path):
    lines = [json.dumps(_sample_obj(i)) + "\n" for i in range(3)]
    path = _write(tmp_path / "g.jsonl", [*lines[:2], lines[2][:200]])
    with pytest.raises(SchemaError, match=r"g.jsonl:3: field '<line>': truncated"):
        list(read_samples(path))


def test_reader_reports_invalid_json_and_non_increasing_indices(tmp_path):
    good = [json.dumps(_sample_obj(i)) + "\n" for i in range(3)]
    path = _write(tmp_path / "bad.jsonl", [good[0], "{not json\n", good[2]])
    with pytest.raises(SchemaError, match=r"bad.jsonl:2: field '<json>'"):
        list(read_samples(path))
    path = _write(tmp_path / "order.jsonl", [good[1], good[0]])
    with pytest.raises(SchemaError, match=r"order.jsonl:2: field 'sample_index'"):
        list(read_samples(path))


def test_arms_of_one_joint_count_named_apart_are_read_by_place_along_the_chain():
    """A Franka's and a Kinova's seven joints carry other names: recordings of both load on the
    positional graph (``chain_1`` … ``chain_7``), whose model reads any seven-joint arm and no
    six-joint one; a model of one arm's names reads that arm only; arms of two joint counts
    are one line naming both counts."""
    fr3 = tuple(f"fr3_joint{k}" for k in range(1, 8))
    gen3 = tuple(f"joint_{k}" for k in range(1, 8))
    chain = common_graph({fr3, gen3})
    assert chain == schema.ArmGraph.by_position(7) and chain.positional
    assert chain.joints[0] == "chain_1" and chain.edges == schema.ArmGraph(fr3).edges
    assert chain.reads(schema.ArmGraph(gen3)) and chain.reads(SEVEN)
    assert not chain.reads(schema.UR_GRAPH) and not schema.ArmGraph(fr3).reads(SEVEN)
    assert not schema.ArmGraph(fr3).positional
    assert common_graph({fr3}) == schema.ArmGraph(fr3) and common_graph(set()) == schema.UR_GRAPH
    with pytest.raises(InputError, match=r"one joint count expected .* arms of 6 and 7 joints"):
        common_graph({fr3, schema.JOINT_NAMES})


def test_a_six_joint_arm_sits_on_seven_places_without_the_upper_arm_roll():
    """Training for transfer across joint counts: a UR's six joints take places 1, 2 and 4–7 of
    a seven-joint chain (no third joint: the upper-arm roll), its sensor packages follow its
    joints, the absent joint's nodes read zero but for the node-type flags, and a fault on the
    elbow is a fault on place 4. Without ``pad`` the two counts are one line (above)."""
    seven = schema.ArmGraph.by_position(7)
    assert schema.UR_GRAPH.places_on(seven) == [0, 1, 3, 4, 5, 6]
    assert schema.ArmGraph(("a", "b", "c", "d", "e")).places_on(seven) == [0, 1, 4, 5, 6]
    assert common_graph({schema.JOINT_NAMES, tuple(f"j{k}" for k in range(7))}, pad=True) == seven
    rng = np.random.default_rng(0)
    x = rng.normal(size=(3, 12, schema.N_FEATURES)).astype(np.float32)
    x[:, :, :2] = schema.UR_GRAPH.type_flags()
    part = {"joints": np.array(schema.JOINT_NAMES), "x": x, "fault_joint": np.array([-1, 2, 5])}
    out = placed(part, seven)
    assert out["x"].shape == (3, 14, schema.N_FEATURES)
    np.testing.assert_array_equal(out["x"][:, [0, 1, 3, 4, 5, 6]], x[:, :6])
    np.testing.assert_array_equal(out["x"][:, [7, 8, 10, 11, 12, 13]], x[:, 6:])
    np.testing.assert_array_equal(out["x"][:, [2, 9], 2:], 0.0)
    np.testing.assert_array_equal(out["x"][0, :, :2], seven.type_flags())
    np.testing.assert_array_equal(out["fault_joint"], [-1, 3, 6])
    assert list(out["joints"]) == list(seven.joints)
