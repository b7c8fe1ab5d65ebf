"""What an exported model says of itself: the metadata in its ONNX file, read with the ``onnx``
protobuf package alone (no torch), so the streaming runtime can check a model before running it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import onnx

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError


def read_metadata(path: Path | str) -> dict[str, Any]:
    """The metadata an exported model carries, with JSON fields decoded; an :class:`InputError`
    naming the file for anything that is not one of our exported models."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no model file")
    try:
        proto = onnx.load(str(path), load_external_data=False)
    except Exception as exc:  # protobuf's DecodeError and friends
        raise InputError(f"{path}: not an ONNX model ({type(exc).__name__})") from None
    raw = {p.key: p.value for p in proto.metadata_props}
    missing = [k for k in ("model_id", "schema_version", "node_names", "window") if k not in raw]
    if missing or not proto.graph.input:
        raise InputError(
            f"{path}: an ONNX model, but not one exported here (metadata key "
            f"'{(missing or ['x'])[0]}' missing)"
        )
    dims = [d.dim_value or d.dim_param for d in proto.graph.input[0].type.tensor_type.shape.dim]
    try:
        graph = schema.ArmGraph.of_nodes(json.loads(raw["node_names"]))
    except (ValueError, TypeError) as exc:
        raise InputError(f"{path}: metadata key 'node_names': {exc}") from None
    if raw["schema_version"] not in schema.READABLE_VERSIONS:
        raise InputError(
            f"{path}: metadata key 'schema_version': {raw['schema_version']} is not one this "
            f"code reads ({', '.join(schema.READABLE_VERSIONS)}); export the model again"
        )
    expected = [int(raw["window"]), graph.n_nodes, schema.N_FEATURES]
    if proto.graph.input[0].name != "x" or dims[1:] != expected:
        raise InputError(
            f"{path}: input '{proto.graph.input[0].name}' has shape {dims}, expected "
            f"[batch, {', '.join(map(str, expected))}] (x)"
        )
    decoded: dict[str, Any] = dict(raw)
    for key in ("node_names", "feature_names", "edges", "classes", "joints", "outputs", "arms",
                "transfer"):  # fmt: skip
        if key in raw:
            decoded[key] = json.loads(raw[key])
    if "window" in raw:
        decoded["window"] = int(raw["window"])
    decoded["arm_graph"] = graph  # the graph a raw window must be on
    return decoded
