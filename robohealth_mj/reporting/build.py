"""A campaign report: every table and figure of a directory of finished runs, written together."""

from __future__ import annotations

from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_text
from robohealth_mj.common.errors import InputError
from robohealth_mj.reporting.figures import figures
from robohealth_mj.reporting.runs import collect
from robohealth_mj.reporting.statistics import aggregate
from robohealth_mj.reporting.tables.cost import cost_markdown
from robohealth_mj.reporting.tables.csv_rows import write_csv
from robohealth_mj.reporting.tables.overview import markdown
from robohealth_mj.reporting.tables.q1 import decomposition_markdown
from robohealth_mj.reporting.tables.q2 import coupling_markdown
from robohealth_mj.reporting.tables.severity import severity_markdown
from robohealth_mj.reporting.tables.visibility import visibility_markdown

__all__ = ["build_report"]


def build_report(root: Path, out: Path | None = None) -> tuple[str, list[Path]]:
    """Tables and figures of every finished run under ``root``, written to ``out`` (default
    ``root/report``)."""
    runs = collect(root)
    if not runs:
        raise InputError(f"no finished runs (train_summary.json + eval_heldout.json) under {root}")
    rows = aggregate(runs)
    out = out or root / "report"
    out.mkdir(parents=True, exist_ok=True)
    sections = [
        markdown(rows),
        decomposition_markdown(runs),
        coupling_markdown(runs),
        severity_markdown(runs),
        visibility_markdown(runs),
        cost_markdown(rows, root),
    ]
    text = "\n".join(s for s in sections if s)
    atomic_write_text(
        out / "results.md",
        f"# Results: {root}\n\n{len(runs)} runs; mean ± std over seeds.\n\n{text}",
    )
    atomic_write_text(out / "results.csv", write_csv(rows))
    return text, figures(runs, rows, out)
