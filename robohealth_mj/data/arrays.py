"""Recordings as arrays, with a binary cache so a corpus is parsed from JSONL only once.

The cache (``<file>.cache.npz``) is keyed by the source's size, modification time and the schema
version; any mismatch re-parses (and re-validates) the JSONL. Written atomically.
"""

from __future__ import annotations

import glob
import hashlib
import io
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_bytes
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.read import is_bag, read_samples, recording_arm
from robohealth_mj.data.relative import REFERENCE_ARM, to_relative
from robohealth_mj.schema import FAULT_CLASSES, SCHEMA_VERSION, UR_GRAPH, ArmGraph

CACHE_SUFFIX = ".cache.npz"


@dataclass
class Recording:
    """All samples of one or more files, in file order. ``run`` indexes ``run_ids`` and
    ``arms`` (each run's arm; empty: the reference arm's). ``x`` holds relative channels
    (:mod:`robohealth_mj.data.relative`): for the UR5e, the readings as recorded."""

    x: np.ndarray  # [T, N, F] float32
    run: np.ndarray  # [T] int32
    run_ids: list[str]
    sample_index: np.ndarray  # [T] int64
    fault_class: np.ndarray  # [T] int64, index into FAULT_CLASSES
    fault_joint: np.ndarray  # [T] int64, index into graph.joints, -1 when healthy
    severity: np.ndarray  # [T] float32
    active: np.ndarray  # [T] bool
    payload_scale: np.ndarray  # [T] float32
    sources: list[str]
    arms: list[str] = field(default_factory=list)  # [len(run_ids)] the arm of each run
    graph: ArmGraph = UR_GRAPH  # the arm graph of every sample (N = 2 J nodes)

    def __len__(self) -> int:
        return len(self.x)

    def fingerprint(self) -> str:
        """Identifies the data a model saw: run ids and their sample counts, plus a content hash."""
        h = hashlib.sha256()
        for rid, count in zip(
            self.run_ids, np.bincount(self.run, minlength=len(self.run_ids)), strict=True
        ):
            h.update(f"{rid}:{count};".encode())
        h.update(np.ascontiguousarray(self.x[:: max(1, len(self.x) // 997)]).tobytes())
        return h.hexdigest()[:16]


def _key(path: Path) -> str:
    if path.is_dir():  # a bag: its storage files say whether it changed
        st = max((f.stat() for f in path.iterdir() if f.is_file()), key=lambda s: s.st_mtime_ns)
        return json.dumps(
            {"size": st.st_size, "mtime_ns": st.st_mtime_ns, "schema": SCHEMA_VERSION}
        )
    st = path.stat()
    return json.dumps({"size": st.st_size, "mtime_ns": st.st_mtime_ns, "schema": SCHEMA_VERSION})


def _parse(path: Path) -> dict[str, np.ndarray]:
    xs, runs, idx, cls, joint, sev, act, payload = [], [], [], [], [], [], [], []
    run_ids: dict[str, int] = {}
    graph: ArmGraph | None = None
    for s in read_samples(path):
        if graph is not None and s.graph != graph:
            raise InputError(f"{path}: samples of two arm graphs ({graph.n_joints} and "
                             f"{s.graph.n_joints} joints) in one file")  # fmt: skip
        graph = s.graph
        xs.append(s.x)
        runs.append(run_ids.setdefault(s.recording_run_id, len(run_ids)))
        idx.append(s.sample_index)
        cls.append(FAULT_CLASSES.index(s.fault.fault_class))
        joint.append(graph.joints.index(s.fault.joint) if s.fault.active else -1)
        sev.append(s.fault.severity if s.fault.active else 0.0)
        act.append(s.fault.active)
        payload.append(float(s.segment["payload_scale"]))
    if not xs or graph is None:
        raise InputError(f"{path}: no samples (an empty recording)")
    return {
        "joints": np.array(graph.joints),
        "x": np.stack(xs).astype(np.float32),
        "run": np.array(runs, np.int32),
        "run_ids": np.array(list(run_ids)),
        "sample_index": np.array(idx, np.int64),
        "fault_class": np.array(cls, np.int64),
        "fault_joint": np.array(joint, np.int64),
        "severity": np.array(sev, np.float32),
        "active": np.array(act, bool),
        "payload_scale": np.array(payload, np.float32),
    }


def _load_one(path: Path) -> dict[str, np.ndarray]:
    cache = path.with_name(path.name + CACHE_SUFFIX)
    key = _key(path)
    if cache.is_file():
        try:
            with np.load(cache, allow_pickle=False) as data:
                if str(data["key"]) == key:
                    return {k: data[k] for k in data.files if k != "key"}
        except (OSError, ValueError, KeyError):
            pass  # unreadable cache: rebuild it below
    arrays = _parse(path)
    buffer = io.BytesIO()
    np.savez(buffer, key=np.array(key), **arrays)
    atomic_write_bytes(cache, buffer.getvalue())
    return arrays


def file_arm(path: Path | str, arm: str | None = None) -> str:
    """The arm whose ratings a file's channels are read against: the one its manifest names;
    else ``arm`` (what the user says a log or bag comes from); else the reference arm."""
    named = recording_arm(path)
    if named is not None and arm is not None and named != arm:
        raise InputError(f"{path}: a recording of a {named}, not of a {arm} (arm={arm})")
    return named or arm or REFERENCE_ARM


def single_arm(paths: list[Path | str], arm: str | None = None, what: str = "data") -> str:
    """The one arm ``paths`` all come from (see :func:`file_arm`); a one-line error when they
    mix arms (what one exported model or one commissioning reads is one arm's)."""
    arms = sorted({file_arm(p, arm) for p in paths})
    if len(arms) > 1:
        raise InputError(f"{what}: recordings of one arm expected; got {', '.join(arms)}")
    return arms[0]


def common_graph(graphs: set[tuple[str, ...]], pad: bool = False) -> ArmGraph:
    """The one graph recordings of these arms' joint lists are read on: their own when they
    share it, a positional one when their arms have as many joints named apart (the seven-joint
    makers: a model fitted on several reads each by place along the chain). Arms of several
    joint counts: with ``pad`` (training for transfer) the longest chain's positional graph, the
    shorter arms' joints placed on it (:meth:`ArmGraph.places_on`); else one line."""
    if not graphs:
        return UR_GRAPH
    if len(graphs) == 1:
        return ArmGraph(next(iter(graphs)))
    counts = sorted({len(g) for g in graphs})
    if len(counts) == 1 or pad:
        return ArmGraph.by_position(counts[-1])
    shown = "; ".join(", ".join(g) for g in sorted(graphs))
    raise InputError(
        f"recordings of one joint count expected (one model reads one; transfer=true trains "
        f"across counts); got arms of {' and '.join(map(str, counts))} joints: {shown}"
    )


def placed(part: dict[str, np.ndarray], graph: ArmGraph) -> dict[str, np.ndarray]:
    """One file's arrays on a longer chain's graph: its joints and their sensor packages at
    their places (:meth:`ArmGraph.places_on`), the absent joints' nodes all zero but for the
    node-type flags, fault joints renumbered. An absent joint has no reading and no fault: a
    graph model's messages pass it by its embedding alone, a booster reads it constant."""
    own = ArmGraph(tuple(str(j) for j in part["joints"]))
    if own.n_joints == graph.n_joints:
        return part
    at = np.array(own.places_on(graph))
    x = np.zeros((len(part["x"]), graph.n_nodes, part["x"].shape[2]), np.float32)
    x[:, :, :2] = graph.type_flags()
    x[:, at] = part["x"][:, : own.n_joints]
    x[:, graph.n_joints + at] = part["x"][:, own.n_joints :]
    joint = np.where(part["fault_joint"] >= 0, at[np.maximum(part["fault_joint"], 0)], -1)
    return {**part, "x": x, "fault_joint": joint, "joints": np.array(graph.joints)}


def load_recordings(
    paths: list[Path | str], arm: str | None = None, pad: bool = False
) -> Recording:
    """Load (from cache when fresh) and concatenate recordings; run ids stay distinct; each
    file's torques and speeds relative to its arm's ratings (``arm``: the arm of files that
    name none; default the reference arm). Arms of several joint counts only with ``pad``: on
    the longest chain by place (:func:`common_graph`, :func:`placed`)."""
    parts, arms = [], []
    for p in paths:
        part, name = _load_one(Path(p)), file_arm(p, arm)
        if name != REFERENCE_ARM:
            part = {**part, "x": to_relative(part["x"], name)}
        parts.append(part)
        arms += [name] * len(part["run_ids"])
    parts = [{"joints": np.array(UR_GRAPH.joints), **p} for p in parts]  # a 2.0 file: the UR's
    graph = common_graph({tuple(str(j) for j in p["joints"]) for p in parts}, pad)
    parts = [placed(p, graph) for p in parts]
    run_ids: list[str] = []
    runs = []
    for part in parts:
        names = [str(r) for r in part["run_ids"]]
        duplicate = set(names) & set(run_ids)
        if duplicate:
            raise InputError(f"recording_run_id {sorted(duplicate)} appears in more than one file")
        runs.append(part["run"] + len(run_ids))
        run_ids += names
    cat = {
        k: np.concatenate([p[k] for p in parts])
        for k in (
            "x",
            "sample_index",
            "fault_class",
            "fault_joint",
            "severity",
            "active",
            "payload_scale",
        )
    }
    return Recording(
        run=np.concatenate(runs),
        run_ids=run_ids,
        sources=[str(p) for p in paths],
        arms=arms,
        graph=graph,
        **cat,
    )


def resolve_recordings(paths: list[str] | str) -> list[Path]:
    """Files, session directories (their ``graphs.jsonl``) or rosbag2 directories; a corpus
    dir's ``train_*`` too."""
    out = []
    for raw in [paths] if isinstance(paths, str) else paths:
        p = Path(raw)
        if p.is_dir() and (p / "graphs.jsonl").is_file():
            out.append(p / "graphs.jsonl")
        elif is_bag(p) or p.is_file():
            out.append(p)
        else:
            raise FileNotFoundError(f"no recording at {raw}")
    return out


def expand_paths(patterns: list[str] | str) -> list[Path]:
    """Paths, session dirs and glob patterns -> recording files (sorted, each once)."""
    patterns = [patterns] if isinstance(patterns, str) else list(patterns)
    found: list[str] = []
    for pattern in patterns:
        matches = sorted(glob.glob(pattern)) if any(c in pattern for c in "*?[") else [pattern]
        if not matches:
            raise FileNotFoundError(f"no recordings match {pattern!r}")
        found += matches
    return list(dict.fromkeys(resolve_recordings(found)))
