"""Consolidating training sessions into one corpus file, with provenance.

Every line is validated and copied unchanged, so each sample keeps its ``recording_run_id`` and
``sample_index``; the sidecar manifest lists every source with its run ids, counts and checksum.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.version import code_version
from robohealth_mj.data.read import read_samples
from robohealth_mj.schema import SCHEMA_VERSION


def merge_files(sources: list[Path], out: Path) -> dict:
    """Write ``out`` (JSONL) and ``out`` + ``.manifest.json``; refuse a run id seen twice."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    provenance, owner = [], {}
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as dst:
            for position, src in enumerate(sources):
                runs: dict[str, int] = {}
                for sample in read_samples(src):  # validates every line, raises on any problem
                    run = sample.recording_run_id
                    first = owner.setdefault(run, (position, str(src)))
                    if first[0] != position:
                        raise ValueError(
                            f"{src}: recording_run_id {run!r} already came from "
                            f"{first[1]}; a session must be merged once"
                        )
                    runs[run] = runs.get(run, 0) + 1
                digest = hashlib.sha256()
                with open(src, "rb") as handle:
                    for block in iter(lambda h=handle: h.read(1 << 20), b""):
                        digest.update(block)
                        dst.write(block.decode("utf-8"))
                provenance.append(
                    {
                        "path": str(src),
                        "sha256": digest.hexdigest(),
                        "samples": sum(runs.values()),
                        "runs": runs,
                    }
                )
        os.chmod(tmp, 0o644)
        os.replace(tmp, out)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    manifest = {
        "schema_version": SCHEMA_VERSION,
        "kind": "merged_corpus",
        "code_version": code_version(),
        "samples": sum(p["samples"] for p in provenance),
        "recording_run_ids": sorted(owner),
        "sources": provenance,
    }
    atomic_write_json(out.with_name(out.name + ".manifest.json"), manifest)
    return manifest
