"""``python -m robohealth_mj.bag``: recordings as ROS 2 bags (rosbag2, MCAP storage).

The page (``--help`` prints it), the parser and what each subcommand prints live in
:mod:`robohealth_mj.bags.cli`.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("bag"):  # a missing extra is one line, not a traceback
    from robohealth_mj.bags.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    raise SystemExit(main())
