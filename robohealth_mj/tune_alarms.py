"""``python -m robohealth_mj.tune_alarms --model M --data SESSION``: choose alarm settings on a
selection recording (record one with a seed of its own; never tune on the held-out session).

The model's decisions are computed once (``--healthy``: also on a healthy-only session, so that
false alarms per hour rest on hours, not minutes), then every policy of the grid replays over
them; the
table (markdown) lists each policy's detection rate, false alarms and latency, and the last line
names the chosen policy (see :func:`~robohealth_mj.deploy.alarm_sweep.choose`). Put it in
``conf/monitor.yaml``'s ``evidence`` and ``alarm`` blocks. The grid covers memory (``evidence``:
how window probabilities accumulate) and the alarm's debouncing together, since each changes
what the other should be.
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("tune_alarms"):  # a missing extra is one line, not a traceback
    from robohealth_mj.deploy.tune_cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
