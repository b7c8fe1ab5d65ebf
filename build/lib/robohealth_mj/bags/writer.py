"""Writing rosbag2 (MCAP storage) with ``rosbags``: recordings, and the monitor's diagnoses.

The bag is a directory (``metadata.yaml`` + one ``.mcap``), as ``ros2 bag record`` makes it, so
``ros2 bag info`` and Foxglove open it without plugins. Message definitions are embedded (ROS 2
Humble types), messages are stamped with simulation time and logged at that time, and the
session manifest goes into the bag's custom metadata (``robohealth_mj.manifest``).
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from robohealth_mj.bags.messages import MessageFactory, stamp_ns, typestore
from robohealth_mj.bags.topics import DIAGNOSTICS, BagTopics
from robohealth_mj.schema import SCHEMA_VERSION, GraphSample


class BagWriter:
    """Context manager: ``write_sample`` per GraphSample, ``write_diagnosis`` per diagnosis.
    Written into ``<out>.partial`` and renamed on a clean close, so a bag at ``out`` is whole."""

    def __init__(self, out: Path | str, topics: BagTopics | None = None) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        self.out = Path(out)
        if self.out.exists():
            raise FileExistsError(f"{self.out} exists; choose another bag directory")
        self.partial = self.out.with_name(self.out.name + ".partial")
        shutil.rmtree(self.partial, ignore_errors=True)
        self.topics = topics or BagTopics.load()
        self.store = typestore()
        self.messages = MessageFactory(self.store)
        self.writer = Writer(self.partial, version=8, storage_plugin=StoragePlugin.MCAP)
        self.connections: dict[str, Any] = {}

    def __enter__(self) -> BagWriter:
        self.writer.open()
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is not None:
            self.writer.close()
            shutil.rmtree(self.partial, ignore_errors=True)
            return
        self.writer.set_custom_data("robohealth_mj.schema_version", SCHEMA_VERSION)
        self.writer.close()
        self.partial.rename(self.out)

    def set_manifest(self, manifest: dict) -> None:
        self.writer.set_custom_data("robohealth_mj.manifest", json.dumps(manifest, sort_keys=True))

    def _write(self, topic: str, msg: Any, t: float) -> None:
        conn = self.connections.get(topic)
        if conn is None:
            conn = self.writer.add_connection(topic, msg.__msgtype__, typestore=self.store)
            self.connections[topic] = conn
        self.writer.write(conn, stamp_ns(t), self.store.serialize_cdr(msg, msg.__msgtype__))

    def write_sample(self, sample: GraphSample) -> None:
        for topic, msg in self.messages.sample_messages(sample, self.topics):
            self._write(topic, msg, sample.t)

    def write_diagnosis(self, d: Any, classes: list[str], joints: list[str]) -> None:
        """A ``HealthDiagnosis`` on ``health_diagnosis``: level from the alarm (OK: none, WARN: a
        fault decided without an alarm, or an invalid sample, ERROR: an alarm up)."""
        msg = self.messages.health_diagnosis(d, classes, joints)
        assert msg.__msgtype__ == DIAGNOSTICS
        self._write(self.topics.health_diagnosis, msg, d.stamp)


def write_bag(
    samples: Iterable[GraphSample],
    out: Path | str,
    manifest: dict | None = None,
    topics: BagTopics | None = None,
) -> int:
    """Write every sample to a new bag at ``out``; returns how many."""
    count = 0
    with BagWriter(out, topics) as bag:
        if manifest is not None:
            bag.set_manifest(manifest)
        for sample in samples:
            bag.write_sample(sample)
            count += 1
    return count
