"""``python -m robohealth_mj.report DIR``: a campaign directory -> tables and figures (thesis §3).

Reads every run's ``train_summary.json`` and ``eval_*.json`` below DIR, groups them by
(graph, variant, window) and reports mean ± std over seeds: held-out (Table 6 layout), payload
probe, harness localisation and C-C0 correlation, |gamma|. Writes ``DIR/report/results.md``,
``results.csv`` and figures, and prints the tables.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from robohealth_mj.reporting import build_report

__all__ = ["build_report", "main"]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.report",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "root",
        nargs="?",
        default="outputs/campaign",
        help="campaign directory (default: outputs/campaign)",
    )
    args = parser.parse_args(argv)
    root = Path(args.root)
    text, figs = build_report(root)
    print(text)
    print(f"report: {root / 'report' / 'results.md'} (+ results.csv, {len(figs)} figures)")


if __name__ == "__main__":
    main()
