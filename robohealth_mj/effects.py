"""Fault effect sizes on every channel: ``python -m robohealth_mj.effects``.

Effect = RMS(faulted - healthy) / the healthy channel's std, on the faulted joint's own nodes, for
each fault x joint x severity (same seed, trajectory and noise draws in both runs). ``1-hop`` is
the mean effect over the sensor channels of the neighbouring joints' sensors.

    python -m robohealth_mj.effects [--joints shoulder_pan elbow wrist_3]
        [--severities 0.3 0.6 0.9] [--seconds 30] [--models physics] [--json rows.json]
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("effects"):  # a missing extra is one line, not a traceback
    from robohealth_mj.recording.effects_cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
