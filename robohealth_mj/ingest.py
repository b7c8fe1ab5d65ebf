"""``python -m robohealth_mj.ingest``: a stock arm's controller log -> a recording.

    python -m robohealth_mj.ingest LOG.csv --map ur_rtde --out DIR      # UR RTDE CSV
    python -m robohealth_mj.ingest test.parquet --map voraus_ad --out DIR
    python -m robohealth_mj.ingest LOG --map my_arm.yaml --out DIR      # any table, a column map

``DIR/graphs.jsonl`` holds the samples at the tick rate (joint channels only, labelled healthy:
a log has no ground truth), ``DIR/manifest.json`` the source, the map, each session's rate, rows,
ticks and fitted torque constants. ``monitor source=replay file=LOG`` and ``evaluate data=LOG``
read a log directly too (the shipped map whose columns it has); column maps:
``conf/logmap/``; resampling: :mod:`robohealth_mj.logs.convert`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from robohealth_mj.common.errors import exit_status
from robohealth_mj.logs.ingest import ingest


def _run(args: argparse.Namespace) -> int:
    manifest = ingest(Path(args.log), args.map, Path(args.out), args.tick_hz)
    for run_id, stats in manifest["sessions"].items():
        print(
            f"{run_id}: {stats['rows']} rows at {stats['rate_hz']:g} Hz -> {stats['ticks']} ticks"
            f" at {args.tick_hz:g} Hz ({stats['ticks_in_gaps']} in gaps)"
        )
    dropped = "; ".join(f"{c} dropped ({why})" for c, why in manifest["dropped"].items())
    print(f"sensing profile {manifest['sensing']}" + (f": {dropped}" if dropped else ""))
    print(f"wrote {manifest['sample_count']} samples -> {Path(args.out) / 'graphs.jsonl'}")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m robohealth_mj.ingest",
        description=__doc__.split("\n\n")[0],
        epilog=__doc__.split("\n\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("log", help="a controller log: .csv or .parquet")
    parser.add_argument(
        "--map",
        default=None,
        help="column map: a name in conf/logmap/ (ur_rtde, voraus_ad) or a YAML file; "
        "default: the shipped map whose columns the log has",
    )
    parser.add_argument("--out", required=True, help="the recording directory to write")
    parser.add_argument("--tick-hz", type=float, default=20.0, help="sample rate (default 20)")
    args = parser.parse_args(argv)
    return exit_status("ingest", lambda: _run(args))


if __name__ == "__main__":
    raise SystemExit(main())
