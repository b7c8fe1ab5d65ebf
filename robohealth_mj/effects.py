"""Fault effect sizes on every channel: ``python -m robohealth_mj.effects``.

The page (``--help`` prints it), the parser and what each subcommand prints live in
:mod:`robohealth_mj.recording.effects_cli`.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("effects"):  # a missing extra is one line, not a traceback
    from robohealth_mj.recording.effects_cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
