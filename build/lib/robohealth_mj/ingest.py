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
import os
import tempfile
from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.errors import exit_status


def ingest(log: Path, column_map: str | None, out: Path, tick_hz: float) -> dict:
    """Write ``out/graphs.jsonl`` and ``out/manifest.json`` (each atomically); the manifest."""
    from robohealth_mj.common.version import code_version
    from robohealth_mj.data.jsonl import format_line
    from robohealth_mj.logs.convert import convert_log, session_samples

    cmap, sessions = convert_log(log, column_map, tick_hz)
    out.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".graphs.jsonl.", suffix=".tmp", dir=out)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            for session in sessions:
                for g in session_samples(session):
                    line = format_line(g.recording_run_id, g.sample_index, g.t, g.x, g.fault,
                                       g.segment)  # fmt: skip
                    handle.write(line)
        os.chmod(tmp, 0o644)
        os.replace(tmp, out / "graphs.jsonl")
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    manifest = {
        "kind": "controller_log",
        "source": str(log),
        "column_map": cmap.name,
        "column_map_file": cmap.source,
        "sensing": "stock",
        "tick_hz": tick_hz,
        "labels": "none: a log has no ground truth",
        "sessions": {s.run_id: s.stats for s in sessions},
        "sample_count": int(sum(len(s.t) for s in sessions)),
        "code_version": code_version(),
    }
    atomic_write_json(out / "manifest.json", manifest)
    return manifest


def _run(args: argparse.Namespace) -> int:
    manifest = ingest(Path(args.log), args.map, Path(args.out), args.tick_hz)
    for run_id, stats in manifest["sessions"].items():
        print(
            f"{run_id}: {stats['rows']} rows at {stats['rate_hz']:g} Hz -> {stats['ticks']} ticks"
            f" at {args.tick_hz:g} Hz ({stats['ticks_in_gaps']} in gaps)"
        )
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
