"""Samples from a recording of any kind: the one place that dispatches on file kind.

It sits above both readers (GraphSample JSONL in :mod:`robohealth_mj.data.jsonl`, rosbag2 in
:mod:`robohealth_mj.bags.reader`), so neither imports the other; the bag reader (and ``rosbags``)
is imported only when a bag is read.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from robohealth_mj.bags import is_bag
from robohealth_mj.data.jsonl import read_jsonl_samples
from robohealth_mj.schema import GraphSample

__all__ = ["is_bag", "read_samples"]


def read_samples(path: Path | str) -> Iterator[GraphSample]:
    """Validated samples of a GraphSample JSONL file or a rosbag2 directory."""
    if is_bag(path):
        from robohealth_mj.bags.reader import read_bag_samples

        return read_bag_samples(Path(path))
    return read_jsonl_samples(path)
