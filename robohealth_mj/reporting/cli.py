"""The command line of ``python -m robohealth_mj.report`` (its page: the entry point's
docstring): the parser and what each subcommand prints."""

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
