"""ROS 2 bags (rosbag2, MCAP storage) in and out, with standard message types only.

``is_bag`` lives here, free of ``rosbags``, so that the file-kind dispatch
(:mod:`robohealth_mj.data.read`) can ask it without importing the bag reader.
"""

from __future__ import annotations

from pathlib import Path


def is_bag(path: Path | str) -> bool:
    """A rosbag2 directory (``metadata.yaml`` beside its storage files)."""
    p = Path(path)
    return p.is_dir() and (p / "metadata.yaml").is_file()
