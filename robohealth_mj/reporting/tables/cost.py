"""Wall time per run and per campaign block."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def cost_markdown(rows: list[dict[str, Any]], root: Path) -> str:
    """Wall time per run (mean over seeds, where measured) and per block (``blocks.tsv``, which
    ``studies/thesis_physics/run.sh`` appends to)."""
    out = ["### Cost: wall time per run and per block", ""]
    blocks = root / "blocks.tsv"
    if blocks.is_file():
        out += ["| block | wall s | parallel runs | host |", "|---|---|---|---|"]
        for line in blocks.read_text().splitlines():
            parts = line.split("\t")
            if len(parts) == 4:
                out.append("| " + " | ".join(parts) + " |")
        out.append("")
    timed = [r for r in rows if r["wall_seconds"][2]]
    if timed:
        out += ["| setting | variant | W | runs | s / run |", "|---|---|---|---|---|"]
        for r in timed:
            mean, std, n = r["wall_seconds"]
            cells = (r["setting"], r["variant"], r["window"], n, f"{mean:.0f} ± {std:.0f}")
            out.append("| " + " | ".join(map(str, cells)) + " |")
        total = sum(r["wall_seconds"][0] * r["wall_seconds"][2] for r in timed)
        out += [
            "",
            f"{sum(r['wall_seconds'][2] for r in timed)} runs, "
            f"{total / 3600:.2f} h of run time in all.",
            "",
        ]
    return "\n".join(out)
