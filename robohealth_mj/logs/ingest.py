"""A controller log converted to a recording (``python -m robohealth_mj.ingest``): resampled to
the tick rate, written as ``graphs.jsonl`` and a manifest like a simulated session's."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_json


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
        "sensing": cmap.sensing(),
        "dropped": dict(cmap.dropped),  # channel -> why: channels the log cannot give
        "tick_hz": tick_hz,
        "labels": "none: a log has no ground truth",
        "sessions": {s.run_id: s.stats for s in sessions},
        "sample_count": int(sum(len(s.t) for s in sessions)),
        "code_version": code_version(),
    }
    atomic_write_json(out / "manifest.json", manifest)
    return manifest
