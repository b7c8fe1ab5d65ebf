"""A GraphSample and its validation: a line of a recording, a message off the bus, checked field
by field against the graph (:mod:`robohealth_mj.schema.graph`) so that a sample of another graph
is refused naming its file, line and field, never reinterpreted."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robohealth_mj.schema.graph import (
    FAULT_CLASSES,
    FEATURE_NAMES,
    N_FEATURES,
    READABLE_VERSIONS,
    SENSOR_CHANNELS,
    SENSOR_FEATURES,
    UR_GRAPH,
    ArmGraph,
)


class SchemaError(ValueError):
    """A sample that does not match the schema; the message names file, line and field."""

    def __init__(
        self,
        message: str,
        *,
        source: str = "<sample>",
        line: int | None = None,
        field: str | None = None,
    ) -> None:
        where = source if line is None else f"{source}:{line}"
        prefix = f"{where}: field '{field}': " if field else f"{where}: "
        super().__init__(prefix + message)
        self.source, self.line, self.field = source, line, field


@dataclass(frozen=True)
class FaultLabel:
    """Ground truth carried by every sample; ``joint`` is None when no fault is active."""

    fault_class: str = "none"
    joint: str | None = None
    severity: float = 0.0
    active: bool = False


@dataclass(frozen=True)
class GraphSample:
    """One 20 Hz snapshot of the arm as a graph of its J joints and J sensor packages."""

    recording_run_id: str
    sample_index: int
    t: float
    x: np.ndarray  # [N, N_FEATURES], N = 2 J
    fault: FaultLabel
    segment: dict[str, Any]
    # A live sample's header stamp, exactly: ``t`` is it in float seconds, which at epoch times is
    # up to 128 ns off, so a diagnosis stamped from ``t`` would not match the sample it diagnoses.
    stamp_ns: int | None = None
    graph: ArmGraph = UR_GRAPH  # the arm's graph: x's rows, fault.joint's names


# The segment of a sample with no ground truth (a robot's own log or bag): nothing is known of it.
UNLABELLED_SEGMENT = {"index": 0, "family": "log", "speed_scale": 1.0, "payload_scale": 1.0}

_REQUIRED = {
    "schema_version": str,
    "recording_run_id": str,
    "sample_index": int,
    "t": (int, float),
    "nodes": list,
    "edge_index": list,
    "x": list,
    "fault": dict,
    "segment": dict,
}
_SEGMENT_REQUIRED = {
    "index": int,
    "family": str,
    "speed_scale": (int, float),
    "payload_scale": (int, float),
}


def _require(obj: dict, key: str, kind: Any, err: Any, prefix: str = "") -> Any:
    if key not in obj:
        raise err("missing", field=prefix + key)
    value = obj[key]
    if (isinstance(value, bool) and kind is not bool) or not isinstance(value, kind):
        raise err(
            f"expected {getattr(kind, '__name__', kind)}, got {type(value).__name__}",
            field=prefix + key,
        )
    return value


def validate_sample(
    obj: Any,
    *,
    source: str = "<sample>",
    line: int | None = None,
    graph: ArmGraph | None = None,
) -> GraphSample:
    """Check one decoded JSON object against the schema and return it as a GraphSample: on
    ``graph`` when given (a recording's manifest says which), else on the graph its node list
    names (a 2.0 sample: the UR graph only).

    Raises SchemaError naming ``source``, ``line`` and the offending field; nothing is repaired.
    """

    def err(message: str, field: str | None = None) -> SchemaError:
        return SchemaError(message, source=source, line=line, field=field)

    if not isinstance(obj, dict):
        raise err(f"expected a JSON object, got {type(obj).__name__}")
    # The version first: a recording of another schema fails on that, not on a field it lacks.
    version = _require(obj, "schema_version", str, err)
    if version not in READABLE_VERSIONS:
        raise err(
            f"version {version!r} is not one of the supported {list(READABLE_VERSIONS)} "
            "(re-record it)",
            field="schema_version",
        )
    for key, kind in _REQUIRED.items():
        _require(obj, key, kind, err)
    if obj["sample_index"] < 0:
        raise err("must be >= 0", field="sample_index")
    if not math.isfinite(obj["t"]):
        raise err("not finite", field="t")
    graph = _graph(obj, version, graph, err)
    edges = obj["edge_index"]
    if (
        len(edges) != 2
        or any(not isinstance(r, list) for r in edges)
        or list(zip(*edges, strict=False)) != list(graph.edges)
    ):
        raise err("topology differs from the arm's structural graph", field="edge_index")
    x = _features(obj["x"], graph, err)
    fault = _fault(obj["fault"], graph, err)
    segment = obj["segment"]
    for key, kind in _SEGMENT_REQUIRED.items():
        _require(segment, key, kind, err, prefix="segment.")
    return GraphSample(
        obj["recording_run_id"], obj["sample_index"], float(obj["t"]), x, fault, segment,
        graph=graph,
    )  # fmt: skip


def _graph(obj: dict, version: str, expected: ArmGraph | None, err: Any) -> ArmGraph:
    """The sample's graph from its node list: the UR graph for 2.0, any arm's for 3.0; the
    expected one's where the caller knows it (a recording's manifest)."""
    nodes = tuple(obj["nodes"])
    if version == "2.0" and nodes != UR_GRAPH.nodes:
        raise err(
            f"node order {list(nodes)} differs from the 2.0 schema's {list(UR_GRAPH.nodes)}",
            field="nodes",
        )
    if expected is not None:
        if nodes != expected.nodes:
            raise err(
                f"node order {list(nodes)} differs from the arm's {list(expected.nodes)}",
                field="nodes",
            )
        return expected
    try:
        return ArmGraph.of_nodes(nodes)
    except (ValueError, TypeError) as exc:
        raise err(str(exc), field="nodes") from None


def _features(rows: list, graph: ArmGraph, err: Any) -> np.ndarray:
    n = graph.n_nodes
    if len(rows) != n or any(not isinstance(r, list) or len(r) != N_FEATURES for r in rows):
        raise err(f"expected {n} rows of {N_FEATURES} features", field="x")
    try:
        x = np.array(rows, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise err(f"non-numeric feature ({exc})", field="x") from None
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        node, feat = bad[0]
        raise err("NaN or Inf", field=f"x[{graph.nodes[node]}].{FEATURE_NAMES[feat]}")
    if not np.array_equal(x[:, :2], graph.type_flags()):
        raise err("node-type indicators do not match the node order", field="x.is_joint/is_sensor")
    stray = np.argwhere(x[: graph.n_joints, SENSOR_CHANNELS] != 0.0)
    if stray.size:
        node, feat = stray[0]
        name = f"x[{graph.nodes[node]}].{SENSOR_FEATURES[feat]}"
        raise err("joint nodes must zero the sensor channels", field=name)
    return x.astype(np.float32)


def _fault(fault: dict, graph: ArmGraph, err: Any) -> FaultLabel:
    cls = _require(fault, "class", str, err, prefix="fault.")
    if cls not in FAULT_CLASSES:
        raise err(f"unknown class {cls!r}; known: {list(FAULT_CLASSES)}", field="fault.class")
    if "joint" not in fault:
        raise err("missing", field="fault.joint")
    joint = fault["joint"]
    if joint is not None and joint not in graph.joints:
        raise err(f"unknown joint {joint!r}", field="fault.joint")
    severity = _require(fault, "severity", (int, float), err, prefix="fault.")
    if not (0.0 <= severity <= 1.0):
        raise err(f"{severity} outside [0, 1]", field="fault.severity")
    active = _require(fault, "active", bool, err, prefix="fault.")
    if active and (cls == "none" or joint is None):
        raise err(
            "an active fault needs a class other than 'none' and a joint", field="fault.active"
        )
    return FaultLabel(cls, joint, float(severity), active)
