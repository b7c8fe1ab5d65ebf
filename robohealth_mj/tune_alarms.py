"""``python -m robohealth_mj.tune_alarms --model M --data SESSION``: choose alarm settings on a

The page (``--help`` prints it), the parser and what each subcommand prints live in
:mod:`robohealth_mj.deploy.tune_cli`.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("tune_alarms"):  # a missing extra is one line, not a traceback
    from robohealth_mj.deploy.tune_cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
