"""``python -m robohealth_mj.monitor``: the runtime diagnosing a live or replayed stream.

    python -m robohealth_mj.monitor model=model.onnx source=sim duration_s=120
    python -m robohealth_mj.monitor model=model.onnx source=replay file=graphs.jsonl speed=10
    python -m robohealth_mj.monitor model=model.onnx source=replay file=... evaluate=true

Prints each change of diagnosis. With ``evaluate=true`` it also writes on-line accuracy,
localisation accuracy, false-alarm rate and detection latency per fault class and severity.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from datetime import datetime
from pathlib import Path

from omegaconf import DictConfig

from robohealth_mj.atomic import atomic_write_json
from robohealth_mj.config import compose_config, load_cli_config
from robohealth_mj.runtime.online_eval import OnlineEvaluator
from robohealth_mj.runtime.runtime import HealthDiagnosis, ModelRuntime
from robohealth_mj.schema import FaultLabel, validate_sample


def sim_stream(overrides: list[str], duration_s: float) -> Iterator[tuple[float, str]]:
    """GraphSample lines straight from the simulator (with its fault schedule)."""
    from robohealth_mj.recorder import build_simulator, chunk_lines

    sim = build_simulator(compose_config("record", ["session.progress=false", *overrides]))
    for chunk in sim.run(round(duration_s / sim.tick_s)):
        yield from zip(chunk.t.tolist(), chunk_lines(sim, chunk, "sim"), strict=True)


def replay_stream(path: str) -> Iterator[tuple[float, str]]:
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            try:
                import json

                t = float(json.loads(line).get("t", 0.0))
            except (ValueError, AttributeError):
                t = 0.0  # the runtime will flag the line itself
            yield t, line


def truth_of(line: str) -> FaultLabel | None:
    try:
        import json

        return validate_sample(json.loads(line)).fault
    except Exception:
        return None


def describe(d: HealthDiagnosis) -> str:
    if not d.valid:
        return f"INVALID ({d.reason})"
    if d.fault_class is None:
        return f"no decision ({d.reason})"
    if not d.fault_present:
        return f"healthy (p={d.confidence:.2f})"
    return f"{d.fault_class} @ {d.localised_joint} (p={d.confidence:.2f})"


def load_config(argv: list[str]) -> DictConfig:
    return load_cli_config("monitor", argv, "robohealth_mj.monitor")


def main(argv: list[str] | None = None) -> dict | None:
    import logging

    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    cfg = load_config(sys.argv[1:] if argv is None else argv)
    runtime = ModelRuntime(cfg.model)
    if cfg.source == "sim":
        stream = sim_stream(list(cfg.sim_overrides), cfg.duration_s)
    elif cfg.source == "replay":
        if not cfg.file or not Path(cfg.file).is_file():
            raise SystemExit(f"source=replay needs file=PATH to a graphs.jsonl (got {cfg.file})")
        stream = replay_stream(cfg.file)
    else:
        raise SystemExit(f"source must be sim or replay, got {cfg.source!r}")
    evaluator = OnlineEvaluator() if cfg.evaluate else None
    last, started, t0 = None, time.perf_counter(), None
    for t, line in stream:
        if cfg.speed and t0 is not None:
            delay = (t - t0) / cfg.speed - (time.perf_counter() - started)
            if delay > 0:
                time.sleep(delay)
        t0 = t if t0 is None else t0
        d = runtime.process(cfg.stream_id, line)
        truth = truth_of(line)
        if evaluator is not None and truth is not None:
            evaluator.update(truth, d)
        shown = describe(d)
        if shown.split(" (")[0] != (last or "").split(" (")[0]:
            label = (
                ""
                if truth is None
                else (
                    f"   [truth: {truth.fault_class} @ {truth.joint} sev {truth.severity:g}]"
                    if truth.active
                    else "   [truth: healthy]"
                )
            )
            if not cfg.quiet:
                print(f"t={t:8.2f}s {cfg.stream_id}: {shown}{label}", flush=True)
            last = shown
    if evaluator is not None:
        result = {"model": runtime.describe(), "source": cfg.source, **evaluator.result()}
        stamp = datetime.now().strftime("%Y-%m-%d_%H-%M-%S")
        out = Path(cfg.out or Path("outputs/monitor") / stamp / "online_eval.json")
        atomic_write_json(out, result)
        lat = result["detection_latency"]
        print(
            f"on-line accuracy {_num(result['online_accuracy'])}  localisation "
            f"{_num(result['localisation_accuracy'])}  false alarms "
            f"{_num(result['false_alarm_rate'])}  class latency "
            f"{_num(lat['class_latency_s_mean'])} s  joint latency "
            f"{_num(lat['joint_latency_s_mean'])} s over {result['episodes']} episodes -> {out}"
        )
        return result
    return None


def _num(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.3f}"


if __name__ == "__main__":
    main()
