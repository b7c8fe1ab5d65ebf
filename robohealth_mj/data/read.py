"""Samples from a recording of any kind: the one place that dispatches on file kind.

It sits above every reader (GraphSample JSONL in :mod:`robohealth_mj.data.jsonl`, rosbag2 in
:mod:`robohealth_mj.bags.reader`, controller logs in :mod:`robohealth_mj.logs`), so none imports
another; the bag reader (and ``rosbags``) is imported only when a bag is read, a log's column map
is the shipped one whose columns it has.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

from robohealth_mj.bags import is_bag
from robohealth_mj.data.jsonl import read_jsonl_samples
from robohealth_mj.logs import is_log, log_samples, log_sensing
from robohealth_mj.schema import GraphSample

__all__ = ["is_bag", "is_log", "read_samples", "recording_arm", "recording_sensing"]


def _manifest(path: Path) -> dict:
    """The manifest beside a recording (``{}`` where there is none or it does not read)."""
    manifest = (path if path.is_dir() else path.parent) / "manifest.json"
    try:
        data = json.loads(manifest.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def recording_sensing(path: Path | str) -> str:
    """The sensing profile a recording carries: a controller log the joint channels its columns
    give (``stock``, or ``stock_reduced`` without the target position), a bag without the sensor
    topics ``stock``; a recording its manifest's ``sensing`` (an ingested log's says which); a
    simulated one every channel (``full``)."""
    path = Path(path)
    if is_log(path):
        return log_sensing(path)
    if is_bag(path):
        from robohealth_mj.bags.reader import bag_sensing

        return bag_sensing(path)
    return str(_manifest(path).get("sensing", "full"))


def recording_arm(path: Path | str) -> str | None:
    """The arm a recording comes from, where its manifest says (``arm_ratings``: every recording
    simulated since arms became data); ``None`` where nothing says (a log, a bag, an older one)."""
    path = Path(path)
    if is_log(path) or is_bag(path):
        return None
    ratings = _manifest(path).get("arm_ratings")
    arm = ratings.get("arm") if isinstance(ratings, dict) else None
    return str(arm) if arm else None


def read_samples(path: Path | str) -> Iterator[GraphSample]:
    """Validated samples of a GraphSample JSONL file, a rosbag2 directory or a controller log
    (``.csv``, ``.parquet``)."""
    if is_log(path):
        return log_samples(path)
    if is_bag(path):
        from robohealth_mj.bags.reader import read_bag_samples

        return read_bag_samples(Path(path))
    return read_jsonl_samples(path)
