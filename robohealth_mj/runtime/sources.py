"""Where samples come from for the monitor and the simulated robot: the simulator itself, or a
recording (graphs.jsonl, bag or controller log) replayed."""

from __future__ import annotations

import json
from collections.abc import Iterator

from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.read import RecordingFile, open_recording
from robohealth_mj.logs import log_samples
from robohealth_mj.schema import FaultLabel, GraphSample, SchemaError, validate_sample


def sim_stream(
    overrides: list[str], duration_s: float
) -> Iterator[tuple[float, GraphSample, FaultLabel]]:
    """GraphSamples straight from the simulator (with its fault schedule)."""
    from robohealth_mj.recording.recorder import build_simulator, chunk_features, segment_info

    sim = build_simulator(compose_config("record", ["session.progress=false", *overrides]))
    for chunk in sim.run(round(duration_s / sim.tick_s)):
        first, x, segment = sim.tick - len(chunk.t), chunk_features(chunk), segment_info(sim, chunk)
        for k, t in enumerate(chunk.t.tolist()):
            sample = GraphSample("sim", first + k, t, x[k].astype("float32"), chunk.fault, segment)
            yield t, sample, chunk.fault


def replay_stream(
    recording: RecordingFile | str,
) -> Iterator[tuple[float, str | GraphSample, FaultLabel | None]]:
    """``(t, sample, truth)`` per recorded sample of a recording looked at once
    (:func:`robohealth_mj.data.read.open_recording`): a graphs.jsonl's lines (a line that does
    not parse goes to the runtime as it is, which flags it), a bag's assembled samples or a
    controller log's ticks (no ground truth: read as healthy, so evaluate counts false alarms)."""
    rec = open_recording(recording) if isinstance(recording, str) else recording
    if rec.kind == "log":
        for sample in log_samples(rec.path):
            yield sample.t, sample, sample.fault
        return
    if rec.kind == "bag":
        from robohealth_mj.bags.reader import read_bag_samples

        for sample in read_bag_samples(rec.path):
            yield sample.t, sample, sample.fault
        return
    path = rec.path
    with open(path, "rb") as handle:
        for number, raw in enumerate(handle, start=1):
            try:
                line = raw.decode("utf-8")
            except UnicodeDecodeError:
                raise InputError(
                    f"{path}:{number}: not text (bytes that are not UTF-8): replay reads a "
                    "graphs.jsonl, a bag directory or a controller log (.csv, .parquet)"
                ) from None
            try:
                sample = validate_sample(json.loads(line), source=str(path), line=number)
            except (ValueError, SchemaError):
                yield 0.0, line, None
                continue
            yield sample.t, sample, sample.fault
