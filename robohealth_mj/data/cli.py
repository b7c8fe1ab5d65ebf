"""``python -m robohealth_mj.dataset``: inspect, gate and merge recordings.

    python -m robohealth_mj.dataset summarize FILES... [--plot fig7.png] [--json out.json]
    python -m robohealth_mj.dataset merge FILES... --out graphs_training_merged.jsonl

FILES are ``graphs.jsonl`` files or session directories containing one. ``summarize`` exits 1 and
says why when any file fails the gate (a class missing, a degenerate joint-target distribution,
too few samples); any malformed line is an error naming file, line and field (exit 2).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.errors import exit_status


def resolve(paths: list[str]) -> list[Path]:
    from robohealth_mj.data.arrays import resolve_recordings

    return resolve_recordings(paths)


def _summarize(args: argparse.Namespace) -> int:
    from robohealth_mj.data.summary import format_summary, gate, summarize_file

    failed, rows = 0, []
    for path in resolve(args.files):
        summary = summarize_file(path)
        failed += bool(gate(summary, args.min_samples, args.min_joint_share))
        rows.append(summary.as_dict())
        print(format_summary(summary), flush=True)
        if args.plot:
            from robohealth_mj.data.figure import plot_signatures

            out = Path(args.plot)
            if len(args.files) > 1:
                out = out.with_name(f"{out.stem}_{path.parent.name}{out.suffix}")
            print(f"  figure: {plot_signatures(path, out)}")
    if args.json:
        atomic_write_json(args.json, rows)
    print(f"{len(rows) - failed} of {len(rows)} file(s) pass the gate")
    return 1 if failed else 0


def _merge(args: argparse.Namespace) -> int:
    from robohealth_mj.data.merge import merge_files

    manifest = merge_files(resolve(args.files), Path(args.out))
    print(
        f"merged {len(manifest['sources'])} file(s), {manifest['samples']} samples, "
        f"{len(manifest['recording_run_ids'])} run(s) -> {args.out}"
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.dataset",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("summarize", help="support statistics and the corpus gate")
    s.add_argument("files", nargs="+")
    s.add_argument("--min-samples", type=int, default=400, help="smaller files are rejected")
    s.add_argument(
        "--min-joint-share",
        type=float,
        default=0.5,
        help="each joint needs this fraction of a uniform share of faulted samples",
    )
    s.add_argument("--plot", help="write the fault-signature figure (thesis Fig. 7) here")
    s.add_argument("--json", help="also write the summaries as JSON")
    s.set_defaults(run=_summarize)
    m = sub.add_parser("merge", help="consolidate sessions into one corpus file")
    m.add_argument("files", nargs="+")
    m.add_argument("--out", required=True)
    m.set_defaults(run=_merge)
    args = parser.parse_args(argv)
    return exit_status("dataset", lambda: args.run(args), ValueError)
