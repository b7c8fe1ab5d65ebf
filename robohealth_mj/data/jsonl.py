"""GraphSample JSONL: fast writing for the recorder, strict reading for everyone else.

A reader never drops or repairs a line: any problem raises SchemaError naming file, line and field.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from functools import cache
from pathlib import Path

import numpy as np

from robohealth_mj.schema import (
    N_FEATURES,
    SCHEMA_VERSION,
    SENSOR_CHANNELS,
    STATE_CHANNELS,
    UR_GRAPH,
    ArmGraph,
    FaultLabel,
    GraphSample,
    SchemaError,
    validate_sample,
)


@cache
def _graph_json(graph: ArmGraph) -> tuple[str, str, str]:
    """The node list, the edge list and one %-template for the whole feature matrix of a
    graph's lines (the template: 4x faster than formatting value by value)."""
    nodes = json.dumps(list(graph.nodes))
    edges = json.dumps([[i for i, _ in graph.edges], [j for _, j in graph.edges]])
    template = ",".join(["[" + ",".join(["%.6g"] * N_FEATURES) + "]"] * graph.n_nodes)
    return nodes, edges, template


def node_features(state: np.ndarray, sensor: np.ndarray) -> np.ndarray:
    """Assemble ``[..., 2J, F]`` node features from per-joint readings.

    ``state [..., J, len(STATE_FEATURES)]`` goes to each joint node and to its sensor node;
    ``sensor [..., J, len(SENSOR_FEATURES)]`` to the sensor nodes only.
    """
    lead, j = state.shape[:-2], state.shape[-2]
    x = np.zeros((*lead, 2 * j, N_FEATURES))
    x[..., :j, 0] = 1.0
    x[..., j:, 1] = 1.0
    x[..., :j, STATE_CHANNELS] = state
    x[..., j:, STATE_CHANNELS] = state
    x[..., j:, SENSOR_CHANNELS] = sensor
    return x


def format_line(
    run_id: str,
    sample_index: int,
    t: float,
    x: np.ndarray,
    fault: FaultLabel,
    segment: dict,
    graph: ArmGraph = UR_GRAPH,
) -> str:
    """One GraphSample of ``graph`` as a JSON line (6 significant digits: well below the noise
    floor)."""
    nodes, edges, template = _graph_json(graph)
    rows = template % tuple(x.ravel().tolist())
    joint = "null" if fault.joint is None else json.dumps(fault.joint)
    fault_json = (
        f'{{"class":{json.dumps(fault.fault_class)},"joint":{joint},'
        f'"severity":{fault.severity:.6g},"active":{"true" if fault.active else "false"}}}'
    )
    return (
        f'{{"schema_version":"{SCHEMA_VERSION}","recording_run_id":{json.dumps(run_id)},'
        f'"sample_index":{sample_index},"t":{t:.6f},"nodes":{nodes},'
        f'"edge_index":{edges},"x":[{rows}],"fault":{fault_json},'
        f'"segment":{json.dumps(segment, separators=(",", ":"))}}}\n'
    )


def read_jsonl_samples(path: Path | str) -> Iterator[GraphSample]:
    """Yield validated samples of a GraphSample JSONL file; sample_index must increase within
    each recording run, and every line is of the first line's arm graph. (Any kind of
    recording: :func:`robohealth_mj.data.read.read_samples`.)"""
    path = Path(path)
    graph: ArmGraph | None = None
    last_index: dict[str, int] = {}
    with path.open("r", encoding="utf-8") as handle:
        for line_no, line in enumerate(handle, start=1):
            if not line.endswith("\n"):
                raise SchemaError(
                    "truncated last line (no newline; the writer was cut off?)",
                    source=str(path),
                    line=line_no,
                    field="<line>",
                )
            if not line.strip():
                raise SchemaError("blank line", source=str(path), line=line_no, field="<line>")
            try:
                obj = json.loads(line)
            except json.JSONDecodeError as exc:
                raise SchemaError(
                    f"invalid JSON ({exc.msg} at column {exc.colno})",
                    source=str(path),
                    line=line_no,
                    field="<json>",
                ) from None
            sample = validate_sample(obj, source=str(path), line=line_no, graph=graph)
            graph = sample.graph
            previous = last_index.get(sample.recording_run_id)
            if previous is not None and sample.sample_index <= previous:
                raise SchemaError(
                    f"{sample.sample_index} does not increase (previous {previous})",
                    source=str(path),
                    line=line_no,
                    field="sample_index",
                )
            last_index[sample.recording_run_id] = sample.sample_index
            yield sample
