"""The GraphSample schema: the one owner of node order, feature names, edges and version.

Every producer (the recorder) and consumer (datasets, training, evaluation, the runtime) validates
against this package, so a file recorded with another graph definition is refused, never
reinterpreted: the graph in :mod:`~robohealth_mj.schema.graph`, a sample and its validation in
:mod:`~robohealth_mj.schema.sample`.
"""

from robohealth_mj.schema.graph import (
    EDGES,
    FAULT_CLASSES,
    FEATURE_NAMES,
    JOINT_NAMES,
    N_FEATURES,
    N_JOINTS,
    N_NODES,
    NODE_NAMES,
    READABLE_VERSIONS,
    SCHEMA_VERSION,
    SENSOR_CHANNELS,
    SENSOR_FEATURES,
    SENSOR_NAMES,
    STATE_CHANNELS,
    STATE_FEATURES,
    UR_GRAPH,
    WINDOW_STATISTICS,
    ArmGraph,
    adjacency,
    edge_index,
    feature_index,
    hop_distance,
)
from robohealth_mj.schema.sample import (
    UNLABELLED_SEGMENT,
    FaultLabel,
    GraphSample,
    SchemaError,
    validate_sample,
)

__all__ = [
    "EDGES",
    "FAULT_CLASSES",
    "FEATURE_NAMES",
    "JOINT_NAMES",
    "NODE_NAMES",
    "N_FEATURES",
    "N_JOINTS",
    "N_NODES",
    "READABLE_VERSIONS",
    "SCHEMA_VERSION",
    "SENSOR_CHANNELS",
    "SENSOR_FEATURES",
    "SENSOR_NAMES",
    "STATE_CHANNELS",
    "STATE_FEATURES",
    "UNLABELLED_SEGMENT",
    "UR_GRAPH",
    "WINDOW_STATISTICS",
    "ArmGraph",
    "FaultLabel",
    "GraphSample",
    "SchemaError",
    "adjacency",
    "edge_index",
    "feature_index",
    "hop_distance",
    "validate_sample",
]
