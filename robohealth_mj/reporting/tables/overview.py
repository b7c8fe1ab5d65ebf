"""Tables 6, 7 and 8, then every other structural setting in Table 6's layout."""

from __future__ import annotations

from typing import Any

from robohealth_mj.reporting.markdown import MAIN_HEAD, main_row
from robohealth_mj.reporting.runs import REFERENCE
from robohealth_mj.reporting.tables.table6 import table6
from robohealth_mj.reporting.tables.table7 import table7
from robohealth_mj.reporting.tables.table8 import table8


def markdown(rows: list[dict[str, Any]]) -> str:
    """Tables 6, 7 and 8, then every other setting in Table 6's layout."""
    parts = [t for t in (table6(rows), table7(rows), table8(rows)) if t]
    others = [r for r in rows if r["setting"] != REFERENCE and r["graph"] == "structural"]
    for setting in dict.fromkeys(r["setting"] for r in others):
        parts += [f"### {setting}", "", MAIN_HEAD, "|---|---|---|---|---|---|---|---|---|---|---|"]
        parts += [main_row(r) for r in others if r["setting"] == setting] + [""]
    return "\n".join(parts)
