"""Reading GraphSamples back from a rosbag2 (MCAP) bag, assembled by time stamp.

Stamped messages are keyed by ``header.stamp``, header-less ones (the vibration arrays) by their
log time. Every ``joint_states`` stamp must have exactly one message on each of the other sample
topics; anything else is an error naming the bag, the topic and the stamp: a topic absent from the
bag, a message missing at a stamp, a message whose stamp has no ``joint_states`` (late or stray),
a second message at one stamp, or one that does not deserialise or lacks a field.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.bags.messages import sample_from_messages, typestore
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.schema import (
    FAULT_CLASSES,
    FEATURE_NAMES,
    JOINT_NAMES,
    NODE_NAMES,
    GraphSample,
    SchemaError,
)


class BagError(SchemaError):
    """A bag that cannot be read as recordings; the message names bag, topic and stamp."""


def _stamp(msg: Any) -> int | None:
    header = getattr(msg, "header", None)
    if header is None:
        return None
    return int(header.stamp.sec) * 10**9 + int(header.stamp.nanosec)


def _open(path: Path):
    from rosbags.rosbag2 import Reader

    try:
        reader = Reader(path)
        reader.open()
    except Exception as exc:  # rosbags raises its own types for every malformed bag
        raise BagError(
            f"not a readable rosbag2 bag ({type(exc).__name__}: {exc})", source=str(path)
        ) from None
    return reader


def bag_sensing(path: Path | str, topics: BagTopics | None = None) -> str:
    """``stock`` for a bag with no sensor package topics (a robot's own), else ``full``."""
    topics = topics or BagTopics.load()
    reader = _open(Path(path))
    try:
        present = {c.topic for c in reader.connections}
    finally:
        reader.close()
    sensors = {topics.imu.format(joint=j) for j in JOINT_NAMES}
    return "full" if sensors & present else "stock"


def bag_manifest(path: Path | str) -> dict | None:
    """The session manifest a bag carries in its custom metadata, if any."""
    import yaml

    meta = Path(path) / "metadata.yaml"
    try:
        info = yaml.safe_load(meta.read_text())["rosbag2_bagfile_information"]
        raw = (info.get("custom_data") or {}).get("robohealth_mj.manifest")
        return None if raw is None else json.loads(raw)
    except (OSError, KeyError, TypeError, ValueError, yaml.YAMLError) as exc:
        raise BagError(
            f"unreadable metadata ({type(exc).__name__}: {exc})", source=str(meta)
        ) from None


def read_bag_samples(path: Path | str, topics: BagTopics | None = None) -> Iterator[GraphSample]:
    """The bag's GraphSamples in stamp order."""
    path = Path(path)
    topics = topics or BagTopics.load()
    wanted = topics.sample_topics()
    store = typestore()
    reader = _open(path)
    try:
        present = {c.topic: c.msgtype for c in reader.connections}
        optional = optional_topics(topics, present)
        wanted = {t: m for t, m in wanted.items() if t in present or t not in optional}
        for topic, msgtype in wanted.items():
            if topic not in present:
                raise BagError(f"topic '{topic}' ({msgtype}) is missing", source=str(path))
            if present[topic] != msgtype:
                raise BagError(
                    f"topic '{topic}' has type {present[topic]}, expected {msgtype}",
                    source=str(path),
                )
        connections = [c for c in reader.connections if c.topic in wanted]
        by_stamp: dict[int, dict[str, Any]] = {}
        for conn, logged, raw in reader.messages(connections=connections):
            try:
                msg = store.deserialize_cdr(raw, conn.msgtype)
            except Exception as exc:
                raise BagError(
                    f"topic '{conn.topic}' at stamp {logged / 1e9:.6f} s: malformed message "
                    f"({type(exc).__name__}: {exc})",
                    source=str(path),
                ) from None
            stamp = _stamp(msg)
            stamp = logged if stamp is None else stamp
            slot = by_stamp.setdefault(stamp, {})
            if conn.topic in slot:
                raise BagError(
                    f"topic '{conn.topic}': a second message at stamp {stamp / 1e9:.6f} s",
                    source=str(path),
                )
            slot[conn.topic] = msg
    finally:
        reader.close()
    yield from _assemble(path, topics, wanted, by_stamp)


def optional_topics(topics: BagTopics, present) -> set[str]:
    """What a bag may lack: the ground truth (a robot's own bag has none: its samples are
    numbered by stamp and read as healthy) and the sensor package, all of it or none (a stock
    arm has none: those channels stay zero)."""
    sensors = {topics.imu.format(joint=j) for j in JOINT_NAMES}
    sensors |= {topics.vibration.format(joint=j) for j in JOINT_NAMES}
    return {topics.fault_state} | (sensors if not sensors & set(present) else set())


def _assemble(path, topics: BagTopics, wanted, by_stamp) -> Iterator[GraphSample]:
    imu = [topics.imu.format(joint=j) for j in JOINT_NAMES]
    vib = [topics.vibration.format(joint=j) for j in JOINT_NAMES]
    sensors = imu[0] in wanted
    truth = topics.fault_state in wanted
    stamps = sorted(by_stamp)
    period = float(np.median(np.diff(stamps))) if len(stamps) > 1 else 1.0
    stray = [t for t in sorted(by_stamp) if topics.joint_states not in by_stamp[t]]
    if stray:  # before "missing": a late message is missing at one stamp and stray at another
        other = sorted(by_stamp[stray[0]])[0]
        raise BagError(
            f"topic '{other}' at stamp {stray[0] / 1e9:.6f} s: no '{topics.joint_states}' "
            "message at that stamp (late, early or stray)",
            source=str(path),
        )
    for stamp in stamps:
        msgs = by_stamp[stamp]
        at = f"at stamp {stamp / 1e9:.6f} s"
        for topic in wanted:
            if topic not in msgs:
                raise BagError(f"topic '{topic}' {at}: message missing", source=str(path))

        def where(key, message: str, stamp_text: str = at) -> BagError:
            topic = (
                getattr(topics, key)
                if isinstance(key, str)
                else topics.vibration.format(joint=JOINT_NAMES[key[1]])
            )
            return BagError(f"topic '{topic}' {stamp_text}: {message}", source=str(path))

        try:
            sample = sample_from_messages(
                stamp / 1e9,
                msgs[topics.joint_states],
                msgs[topics.joint_errors],
                [msgs[t] for t in imu] if sensors else None,
                [msgs[t] for t in vib] if sensors else None,
                msgs[topics.fault_state] if truth else None,
                where,
            )
            if not truth:  # numbered by stamp: a gap in the stamps is a gap in the numbering
                index = round((stamp - stamps[0]) / period)
                sample = replace(sample, recording_run_id=path.name, sample_index=index)
        except (AttributeError, TypeError, ValueError) as exc:
            if isinstance(exc, SchemaError):
                raise
            raise BagError(f"{at}: malformed message ({exc})", source=str(path)) from None
        _check(sample, path, at, topics)
        yield sample


def _check(sample: GraphSample, path: Path, at: str, topics: BagTopics) -> None:
    bad = np.argwhere(~np.isfinite(sample.x))
    if bad.size:
        node, feat = bad[0]
        raise BagError(
            f"{at}: NaN or Inf in x[{NODE_NAMES[node]}].{FEATURE_NAMES[feat]}", source=str(path)
        )
    f = sample.fault
    if f.fault_class not in FAULT_CLASSES or (f.joint is not None and f.joint not in JOINT_NAMES):
        raise BagError(
            f"topic '{topics.fault_state}' {at}: unknown fault {f.fault_class!r} @ {f.joint!r}",
            source=str(path),
        )
