"""``python -m robohealth_mj.monitor``: the runtime diagnosing a live or replayed stream.

    python -m robohealth_mj.monitor model=model.onnx source=sim duration_s=120
    python -m robohealth_mj.monitor model=model.onnx source=replay file=graphs.jsonl speed=10
    python -m robohealth_mj.monitor model=model.onnx source=replay file=... evaluate=true
    python -m robohealth_mj.monitor model=model.onnx source=ros2 ros2.count=4 duration_s=0

Prints each change of diagnosis and every alarm raised or cleared (debouncing and hysteresis:
``alarm.raise_after``, ``alarm.clear_after``, ``alarm.min_confidence``, ``alarm.clear_confidence``;
see ``conf/monitor.yaml``). With ``evaluate=true`` it also writes on-line accuracy, localisation
accuracy, alarm detection rate, false alarms (per settled healthy tick and per hour) and debounced
detection latency to class and joint, per fault class and severity.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.common.threads import resolve_threads
from robohealth_mj.runtime.monitor import decide_every, monitor_policies, monitor_stream
from robohealth_mj.runtime.ready import resolve_file, resolve_model
from robohealth_mj.runtime.runtime import ModelRuntime


def main(argv: list[str] | None = None) -> dict | None:
    """The monitor's Hydra app (``conf/monitor.yaml``, ``ros2.*``); returns the evaluation."""
    return run_tool("monitor", run, argv)


def run(cfg: DictConfig) -> dict | None:
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    with one_line_errors("monitor"):
        cfg.model, cfg.file = resolve_model(cfg.model), resolve_file(cfg.file)  # model=stock
        cfg.source = cfg.source or ("replay" if cfg.file else "sim")
        alarm, evidence, contact = monitor_policies(cfg)
        runtime = ModelRuntime(
            cfg.model,
            threads=resolve_threads(cfg.threads, "threads"),
            alarm=alarm,
            incremental=cfg.incremental,
            evidence=evidence,
            observability=cfg.observability,
            contact=contact,
            strict=True,
            decide_every=decide_every(cfg.decide_every),  # every k-th tick, held between
        )  # fmt: skip (strict: a model named is read here, once, or refused)
        if cfg.source != "ros2":
            return monitor_stream(cfg, runtime, alarm, evidence)
        from robohealth_mj.ros2.live import monitor_arms

        return monitor_arms(cfg, runtime, alarm, evidence)


if __name__ == "__main__":
    main()
