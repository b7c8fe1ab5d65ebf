"""Table 6: every model at each window of the reference setting."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.markdown import MAIN_HEAD, main_row
from robohealth_mj.reporting.runs import REFERENCE


def table6(rows: list[dict[str, Any]]) -> str:
    """Table 6's layout, once per window of the reference setting (structural graph, every
    channel, the schema's sensors)."""
    out = []
    ref = [r for r in rows if r["setting"] == REFERENCE]
    for window in sorted({r["window"] for r in ref}):
        sub = [r for r in ref if r["window"] == window]
        if len(sub) < 2:
            continue  # one model at this window: a window-ablation point, in Table 7
        out += [f"### Table 6: every model at W = {window} (held-out session; payload probe)", ""]
        out += [MAIN_HEAD, "|---|---|---|---|---|---|---|---|---|---|---|"]
        out += [main_row(r) for r in sub]
        out.append("")
    return "\n".join(out)
