"""``python -m robohealth_mj.dataset``: inspect, gate and merge recordings.

The page (``--help`` prints it), the parser and what each subcommand prints live in
:mod:`robohealth_mj.data.cli`.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("dataset"):  # a missing extra is one line, not a traceback
    from robohealth_mj.data.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    raise SystemExit(main())
