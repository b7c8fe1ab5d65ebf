"""``python -m robohealth_mj.report DIR``: a campaign directory -> tables and figures (thesis §3).

Reads every run's ``train_summary.json`` and ``eval_*.json`` below DIR, groups them by
(graph, variant, window) and reports mean ± std over seeds: held-out (Table 6 layout), payload
probe, harness localisation and C-C0 correlation, |gamma|. Writes ``DIR/report/results.md``,
``results.csv`` and figures (or into ``--out``), and prints the tables.

With ``--archive ARCHIVE`` the finished runs' records (no checkpoints) are first copied from DIR
into ARCHIVE, a directory kept in git, and the report is built from ARCHIVE: every run archived
so far, from any machine, not only those still on this one.

    python -m robohealth_mj.report outputs/thesis_physics \
        --archive studies/thesis_physics/results/runs --out studies/thesis_physics/results

With ``--lives FILE`` (a ``lives.json`` of ``studies/wear/campaign.py``) it draws each
held-out life instead: the wearing joint's true severity, the health index with its band and the
RUL estimates against the true RUL (``--out``, default the file's directory).

    python -m robohealth_mj.report --lives outputs/lives/gbdt_last_s42/lives.json \
        --out studies/wear/results
"""

from __future__ import annotations

import argparse
from pathlib import Path

from robohealth_mj.common.errors import InputError, one_line_errors

with one_line_errors("report"):  # a missing extra is one line, not a traceback
    from robohealth_mj.reporting.archive import archive_runs
    from robohealth_mj.reporting.build import build_report
    from robohealth_mj.reporting.lives import plot_lives, read_lives

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
    parser.add_argument(
        "--archive",
        type=Path,
        help="copy the finished runs' records here first, then report on everything archived",
    )
    parser.add_argument("--out", type=Path, help="where the report goes (default: ROOT/report)")
    parser.add_argument("--lives", type=Path, help="draw the held-out lives of this lives.json")
    args = parser.parse_args(argv)
    with one_line_errors("report"):
        if args.lives:
            figs = plot_lives(read_lives(args.lives), args.out or args.lives.parent)
            print(f"{len(figs)} figures: {figs[0]} (+ one per held-out life)")
            return
        _report(Path(args.root), args.archive, args.out)


def _report(root: Path, archive: Path | None, out: Path | None) -> None:
    if not root.is_dir():
        raise InputError(f"{root}: no such campaign directory")
    if archive:
        copied = archive_runs(root, archive)
        print(f"archived {len(copied)} finished run(s) from {root} into {archive}")
        root = archive
    out = out or root / "report"
    text, figs = build_report(root, out)
    print(text)
    print(f"report: {out / 'results.md'} (+ results.csv, {len(figs)} figures)")
