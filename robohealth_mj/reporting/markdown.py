"""What every report table shares: a title and header, and the row of Table 6's layout."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.statistics import COLUMNS, fmt_stat


def heading(title: str, head: list[str]) -> list[str]:
    """A Markdown table's title and header lines."""
    return [f"### {title}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]


MAIN_HEAD = (
    "| variant | W | seeds | accuracy | fault-present | macro-F1 | localisation | "
    "probe acc. | probe loc. | |γ| | s / run |"
)


def main_row(r: dict[str, Any]) -> str:
    cells = [fmt_stat(r[f"{d}.{m}"]) for d, m in COLUMNS]
    wall = r["wall_seconds"]
    return (
        f"| {r['variant']} | {r['window']} | {len(r['seeds'])} | "
        + " | ".join(cells)
        + f" | {fmt_stat(r['gamma'])} | {'—' if not wall[2] else f'{wall[0]:.0f}'} |"
    )
