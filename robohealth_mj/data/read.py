"""Samples from a recording of any kind: the one place that dispatches on file kind.

It sits above every reader (GraphSample JSONL in :mod:`robohealth_mj.data.jsonl`, rosbag2 in
:mod:`robohealth_mj.bags.reader`, controller logs in :mod:`robohealth_mj.logs`), so none imports
another; the bag reader (and ``rosbags``) is imported only when a bag is read, a log's column map
is the shipped one whose columns it has.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from robohealth_mj.bags import is_bag
from robohealth_mj.data.jsonl import read_jsonl_samples
from robohealth_mj.logs import is_log, log_samples, log_sensing
from robohealth_mj.schema import GraphSample

__all__ = [
    "RecordingFile", "is_bag", "is_log", "open_recording", "read_samples", "recording_arm",
    "recording_sensing",
]  # fmt: skip


def _manifest(path: Path) -> dict:
    """The manifest beside a recording (``{}`` where there is none or it does not read)."""
    manifest = (path if path.is_dir() else path.parent) / "manifest.json"
    try:
        data = json.loads(manifest.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


@dataclass(frozen=True)
class RecordingFile:
    """A recording looked at once: its kind (``log``, ``bag`` or ``jsonl``), the sensing profile
    it carries and the arm it names, so a reader of it dispatches and reads its manifest once."""

    path: Path
    kind: str
    sensing: str  # a log: the channels its columns give; a bag without sensor topics: stock;
    # a recording: its manifest's (an ingested log's says which); a simulated one: full
    arm: str | None  # the manifest's arm (every recording simulated since arms became data)


def open_recording(path: Path | str) -> RecordingFile:
    """What ``path`` is, read once; a path that is none of them is the user's to fix."""
    path = Path(path)
    if is_log(path):
        return RecordingFile(path, "log", log_sensing(path), None)
    if is_bag(path):
        from robohealth_mj.bags.reader import bag_sensing

        return RecordingFile(path, "bag", bag_sensing(path), None)
    if path.is_dir() and (path / "graphs.jsonl").is_file():  # a session directory
        path = path / "graphs.jsonl"
    if not path.is_file():
        raise FileNotFoundError(
            f"{path}: no recording there (a graphs.jsonl, a bag directory or a controller log, "
            ".csv or .parquet)"
        )
    manifest = _manifest(path)
    ratings = manifest.get("arm_ratings")
    arm = ratings.get("arm") if isinstance(ratings, dict) else None
    return RecordingFile(path, "jsonl", str(manifest.get("sensing", "full")), arm and str(arm))


def recording_sensing(path: Path | str) -> str:
    """The sensing profile a recording carries (:class:`RecordingFile`; a simulated one's,
    ``full``, where nothing is there to say)."""
    return _looked_at(path).sensing


def recording_arm(path: Path | str) -> str | None:
    """The arm a recording names; ``None`` where nothing says (a log, a bag, an older one)."""
    return _looked_at(path).arm


def _looked_at(path: Path | str) -> RecordingFile:
    try:
        return open_recording(path)
    except FileNotFoundError:
        return RecordingFile(Path(path), "jsonl", "full", None)


def read_samples(path: Path | str) -> Iterator[GraphSample]:
    """Validated samples of a GraphSample JSONL file, a rosbag2 directory or a controller log
    (``.csv``, ``.parquet``)."""
    if is_log(path):
        return log_samples(path)
    if is_bag(path):
        from robohealth_mj.bags.reader import read_bag_samples

        return read_bag_samples(Path(path))
    return read_jsonl_samples(path)
