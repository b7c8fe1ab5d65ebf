"""``python -m robohealth_mj.bag``: recordings as ROS 2 bags (rosbag2, MCAP storage).

    python -m robohealth_mj.bag write SESSION [--out DIR]     # graphs.jsonl or a session dir
    python -m robohealth_mj.bag info BAG
    python -m robohealth_mj.bag plot BAG --out timeline.png   # truth and diagnosis, one timeline

``write`` converts a recording to a bag directory that ``ros2 bag info`` and Foxglove open
without plugins (standard messages only; topics in ``conf/bag.yaml``; the session manifest in the
bag's metadata). Every command that reads recordings (``dataset``, ``train``, ``evaluate``,
``monitor source=replay``) also takes such a bag directory.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("bag"):  # a missing extra is one line, not a traceback
    from robohealth_mj.bags.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    raise SystemExit(main())
