"""``python -m robohealth_mj.dataset``: inspect, gate and merge recordings.

    python -m robohealth_mj.dataset summarize FILES... [--plot fig7.png] [--json out.json]
    python -m robohealth_mj.dataset merge FILES... --out graphs_training_merged.jsonl

FILES are ``graphs.jsonl`` files or session directories containing one. ``summarize`` exits 1 and
says why when any file fails the gate (a class missing, a degenerate joint-target distribution,
too few samples); any malformed line is an error naming file, line and field (exit 2).
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("dataset"):  # a missing extra is one line, not a traceback
    from robohealth_mj.data.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    raise SystemExit(main())
