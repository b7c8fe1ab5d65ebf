"""``python -m robohealth_mj.report DIR``: a campaign directory -> tables and figures (thesis §3).

The page (``--help`` prints it), the parser and what each subcommand prints live in
:mod:`robohealth_mj.reporting.cli`.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("report"):  # a missing extra is one line, not a traceback
    from robohealth_mj.reporting.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
