"""A GraphSample and its validation: a line of a recording, a message off the bus, checked field
by field against the graph (:mod:`robohealth_mj.schema.graph`) so that a sample of another graph
is refused naming its file, line and field, never reinterpreted."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robohealth_mj.schema.graph import (
    EDGES,
    FAULT_CLASSES,
    FEATURE_NAMES,
    JOINT_NAMES,
    N_FEATURES,
    N_JOINTS,
    N_NODES,
    NODE_NAMES,
    SCHEMA_VERSION,
    SENSOR_CHANNELS,
    SENSOR_FEATURES,
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
    """One 20 Hz snapshot of the arm as a 12-node graph."""

    recording_run_id: str
    sample_index: int
    t: float
    x: np.ndarray  # [N_NODES, N_FEATURES]
    fault: FaultLabel
    segment: dict[str, Any]
    # A live sample's header stamp, exactly: ``t`` is it in float seconds, which at epoch times is
    # up to 128 ns off, so a diagnosis stamped from ``t`` would not match the sample it diagnoses.
    stamp_ns: int | None = None


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


def validate_sample(obj: Any, *, source: str = "<sample>", line: int | None = None) -> GraphSample:
    """Check one decoded JSON object against the schema and return it as a GraphSample.

    Raises SchemaError naming ``source``, ``line`` and the offending field; nothing is repaired.
    """

    def err(message: str, field: str | None = None) -> SchemaError:
        return SchemaError(message, source=source, line=line, field=field)

    if not isinstance(obj, dict):
        raise err(f"expected a JSON object, got {type(obj).__name__}")
    # The version first: a recording of another schema fails on that, not on a field it lacks.
    version = _require(obj, "schema_version", str, err)
    if version != SCHEMA_VERSION:
        raise err(
            f"version {version!r} is not the supported {SCHEMA_VERSION!r} (re-record it)",
            field="schema_version",
        )
    for key, kind in _REQUIRED.items():
        _require(obj, key, kind, err)
    if obj["sample_index"] < 0:
        raise err("must be >= 0", field="sample_index")
    if not math.isfinite(obj["t"]):
        raise err("not finite", field="t")
    if tuple(obj["nodes"]) != NODE_NAMES:
        raise err(
            f"node order {obj['nodes']} differs from the schema's {list(NODE_NAMES)}", field="nodes"
        )
    edges = obj["edge_index"]
    if (
        len(edges) != 2
        or any(not isinstance(r, list) for r in edges)
        or list(zip(*edges, strict=False)) != list(EDGES)
    ):
        raise err("topology differs from the schema's structural graph", field="edge_index")
    x = _features(obj["x"], err)
    fault = _fault(obj["fault"], err)
    segment = obj["segment"]
    for key, kind in _SEGMENT_REQUIRED.items():
        _require(segment, key, kind, err, prefix="segment.")
    return GraphSample(
        obj["recording_run_id"], obj["sample_index"], float(obj["t"]), x, fault, segment
    )


def _features(rows: list, err: Any) -> np.ndarray:
    if len(rows) != N_NODES or any(not isinstance(r, list) or len(r) != N_FEATURES for r in rows):
        raise err(f"expected {N_NODES} rows of {N_FEATURES} features", field="x")
    try:
        x = np.array(rows, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise err(f"non-numeric feature ({exc})", field="x") from None
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        node, feat = bad[0]
        raise err("NaN or Inf", field=f"x[{NODE_NAMES[node]}].{FEATURE_NAMES[feat]}")
    expected_type = np.zeros((N_NODES, 2))
    expected_type[:N_JOINTS, 0] = 1.0
    expected_type[N_JOINTS:, 1] = 1.0
    if not np.array_equal(x[:, :2], expected_type):
        raise err("node-type indicators do not match the node order", field="x.is_joint/is_sensor")
    stray = np.argwhere(x[:N_JOINTS, SENSOR_CHANNELS] != 0.0)
    if stray.size:
        node, feat = stray[0]
        name = f"x[{NODE_NAMES[node]}].{SENSOR_FEATURES[feat]}"
        raise err("joint nodes must zero the sensor channels", field=name)
    return x.astype(np.float32)


def _fault(fault: dict, err: Any) -> FaultLabel:
    cls = _require(fault, "class", str, err, prefix="fault.")
    if cls not in FAULT_CLASSES:
        raise err(f"unknown class {cls!r}; known: {list(FAULT_CLASSES)}", field="fault.class")
    if "joint" not in fault:
        raise err("missing", field="fault.joint")
    joint = fault["joint"]
    if joint is not None and joint not in JOINT_NAMES:
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
