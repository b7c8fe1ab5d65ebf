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

from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import InputError, one_line_errors
from robohealth_mj.runtime.alarms import AlarmPolicy
from robohealth_mj.runtime.contact import ContactPolicy
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.runtime.metadata import read_metadata
from robohealth_mj.runtime.monitor import monitor_stream, refuse_lacking_data
from robohealth_mj.runtime.runtime import ModelRuntime


def main(argv: list[str] | None = None) -> dict | None:
    """The monitor's Hydra app (``conf/monitor.yaml``, ``ros2.*``); returns the evaluation."""
    return run_tool("monitor", run, argv)


def run(cfg: DictConfig) -> dict | None:
    import logging

    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    policy = _policy("alarm", AlarmPolicy, cfg)
    evidence = _policy("evidence", EvidencePolicy, cfg)
    contact = _policy("contact", ContactPolicy, cfg)
    with one_line_errors("monitor"):
        return _monitor(cfg, policy, evidence, contact)


def _policy(key: str, kind: type, cfg: DictConfig):
    """The ``alarm``, ``evidence`` or ``contact`` block as its policy; a bad value is the user's
    to fix."""
    with one_line_errors("monitor"):
        try:
            return kind(**cfg[key])
        except (TypeError, ValueError) as exc:
            raise InputError(f"conf/monitor.yaml {key}: {exc}") from None


def _monitor(
    cfg: DictConfig, policy: AlarmPolicy, evidence: EvidencePolicy, contact: ContactPolicy
) -> dict | None:
    if cfg.model:
        read_metadata(cfg.model)  # a model named but unusable is the user's to fix
    runtime = ModelRuntime(
        cfg.model, threads=cfg.threads, alarm=policy, incremental=cfg.incremental,
        evidence=evidence, observability=cfg.observability, contact=contact,
    )  # fmt: skip
    if cfg.source != "ros2":
        return monitor_stream(cfg, runtime, policy, evidence)
    from robohealth_mj.ros2 import layout_sensing

    delivered = layout_sensing(cfg.ros2.layout)  # the channels the layout's topics carry
    if cfg.model:  # a model reading more is refused
        refuse_lacking_data(cfg.model, delivered, f"ros2.layout={cfg.ros2.layout}")
    from robohealth_mj.ros2.live import monitor_arms

    return monitor_arms(cfg, runtime, policy, evidence)


if __name__ == "__main__":
    main()
