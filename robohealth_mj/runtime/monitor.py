"""The monitor's loop over a simulated or replayed stream: each sample through the runtime, every
change of diagnosis and every alarm printed, the topics and diagnoses optionally written to a bag,
and with ``evaluate`` the on-line figures written beside the run (``python -m
robohealth_mj.monitor``; the live ROS 2 loop is :func:`robohealth_mj.ros2.live.monitor_arms`)."""

from __future__ import annotations

import time
from contextlib import ExitStack
from datetime import datetime
from pathlib import Path

import numpy as np
from omegaconf import DictConfig

from robohealth_mj.bags import is_bag
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.bags.writer import BagWriter
from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.read import recording_arm, recording_sensing
from robohealth_mj.data.sensing import refuse_missing_channels
from robohealth_mj.prognostics.health import (
    Calibration,
    attribution_from_probabilities,
    session_health,
)
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.runtime.alarms import AlarmPolicy
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.runtime.fleet import freeze_startup_heap
from robohealth_mj.runtime.health import HealthTracker, health_fields
from robohealth_mj.runtime.metadata import read_metadata
from robohealth_mj.runtime.online_eval import OnlineEvaluator, joint_activity
from robohealth_mj.runtime.online_report import online_markdown
from robohealth_mj.runtime.runtime import HealthDiagnosis, ModelRuntime
from robohealth_mj.runtime.sources import replay_stream, sim_stream
from robohealth_mj.schema import FAULT_CLASSES, JOINT_NAMES, GraphSample


def describe(d: HealthDiagnosis) -> str:
    if not d.valid:
        return f"INVALID ({d.reason})"
    contact = f"CONTACT @ {d.contact_joint}; " if d.contact else ""
    if d.fault_class is None:
        return f"{contact}no decision ({d.reason})"
    if not d.fault_present:
        return f"{contact}healthy (p={d.confidence:.2f})"
    return f"{contact}{d.fault_class} @ {d.localised_joint} (p={d.confidence:.2f})"


def refuse_lacking_data(model: str, data_sensing: str, source: str) -> None:
    """One line when the data lacks channels the exported model reads."""
    refuse_missing_channels(read_metadata(model).get("sensing", "full"), data_sensing, source)


def refuse_other_arm(model_arm: str, data_arm: str | None, source: str) -> None:
    """One line when a recording names another arm than the one the exported model reads (its
    readings would be read against the wrong ratings)."""
    if data_arm is not None and data_arm != model_arm:
        raise InputError(
            f"{source}: a recording of a {data_arm}; the model reads a {model_arm} (export one "
            f"for the {data_arm}: python -m robohealth_mj.export data=<a {data_arm} recording>)"
        )


def monitor_stream(
    cfg: DictConfig, runtime: ModelRuntime, policy: AlarmPolicy, evidence: EvidencePolicy
) -> dict | None:
    """Run the source through the runtime; with ``evaluate``, the on-line figures. Healthy ticks
    count as settled once the window, the evidence and the alarm have had time to let a fault
    go (``settle``)."""
    if cfg.source == "sim":
        stream = sim_stream(list(cfg.sim_overrides), cfg.duration_s)
    elif cfg.source == "replay":
        if not cfg.file or not (Path(cfg.file).is_file() or is_bag(cfg.file)):
            raise FileNotFoundError(
                f"source=replay needs file=PATH to a graphs.jsonl, a bag directory or a "
                f"controller log (.csv, .parquet) (got {cfg.file})"
            )
        if cfg.model:
            refuse_lacking_data(cfg.model, recording_sensing(cfg.file), cfg.file)
            refuse_other_arm(runtime.arm, recording_arm(cfg.file), cfg.file)
        stream = replay_stream(cfg.file)
    else:
        raise InputError(f"source must be sim, replay or ros2, got {cfg.source!r}")
    freeze_startup_heap()
    settle = runtime.window + policy.clear_after + evidence.clearing_ticks
    evaluator = OnlineEvaluator(settle_ticks=settle, arm=runtime.arm) if cfg.evaluate else None
    last, started, t0, valid = None, time.perf_counter(), None, 0
    wear = (
        SessionWear(cfg.stream_id, cfg.health) if cfg.get("health", {}).get("state_dir") else None
    )
    with ExitStack() as stack:
        bag = stack.enter_context(BagWriter(cfg.bag_out)) if cfg.bag_out else None
        for t, sample, truth in stream:
            if cfg.speed and t0 is not None:
                delay = (t - t0) / cfg.speed - (time.perf_counter() - started)
                if delay > 0:
                    time.sleep(delay)
            t0 = t if t0 is None else t0
            valid += isinstance(sample, GraphSample)
            d = runtime.process(cfg.stream_id, sample)
            if bag is not None and isinstance(sample, GraphSample):
                bag.write_sample(sample)
                bag.write_diagnosis(d, runtime.fleet.classes, runtime.fleet.joints)
            if evaluator is not None and truth is not None:
                activity = joint_activity(sample.x) if isinstance(sample, GraphSample) else ()
                evaluator.update(truth, d, *activity)
            if not cfg.quiet:
                last = print_change(cfg.stream_id, t, d, truth, last)
            if wear is not None:
                wear.add(d, runtime.fleet.joints)
    if not valid:  # nothing was diagnosed: not a run to pass off as a healthy one
        raise InputError(f"{cfg.file or cfg.source}: no valid sample to diagnose")
    if wear is not None:
        wear.finish()
    if cfg.bag_out:
        print(f"replayed topics and {BagTopics.load().health_diagnosis} -> {cfg.bag_out}")
    if evaluator is None:
        return None
    result = {
        "model": runtime.describe(),
        "source": cfg.source,
        "file": cfg.file,
        "alarm_policy": dict(cfg.alarm),
        "evidence_policy": dict(cfg.evidence),
        **evaluator.result(),
    }
    out = evaluation_path(cfg.out, "online_eval.json")
    atomic_write_json(out, result)
    atomic_write_text(out.with_suffix(".md"), online_markdown(result))
    alarms = result["alarms"]
    print(
        f"on-line accuracy {_num(result['online_accuracy'])}  localisation "
        f"{_num(result['localisation_accuracy'])} | alarms: detected "
        f"{alarms['detected']}/{alarms['episodes']} episodes, false alarms "
        f"{_num(result['false_alarm_rate'])} of settled healthy ticks "
        f"({_num(result['false_alarms_per_hour'])}/h), latency to class "
        f"{_num(alarms['class_latency_s_median'])} s, to joint "
        f"{_num(alarms['joint_latency_s_median'])} s (medians); contact calls "
        f"{result['contact_calls']} -> {out}"
    )
    return result


class SessionWear:
    """The session's decided windows, turned into the arm's health index when it ends and added
    to the arm's history (``health.state_dir``; :mod:`robohealth_mj.runtime.health`)."""

    def __init__(self, stream_id: str, cfg: DictConfig) -> None:
        if cfg.get("day") is None:
            raise InputError("health.state_dir needs health.day: this session's operating day")
        cal = cfg.get("calibration")
        self.calibration = Calibration.load(cal) if cal else None
        self.tracker = HealthTracker(
            Path(cfg.state_dir),
            TrendRul(threshold=float(cfg.threshold)),
            lead_days=float(cfg.lead_days),
            floor=float(cfg.floor),
        )
        self.tracker.history(stream_id)  # a broken state file is refused before the session
        self.stream_id, self.day = stream_id, float(cfg.day)
        self.probs: list[list[float]] = []
        self.joints: list[list[float]] = []

    def add(self, d: HealthDiagnosis, joints: list[str]) -> None:
        if d.valid and d.fault_class is not None:
            self.probs.append([d.class_probabilities.get(c, 0.0) for c in FAULT_CLASSES])
            self.joints.append([d.joint_scores[j] for j in joints])

    def finish(self) -> list:
        attribution = attribution_from_probabilities(
            np.array(self.probs).reshape(-1, len(FAULT_CLASSES)),
            np.array(self.joints).reshape(-1, len(JOINT_NAMES)),
        )
        health = session_health(attribution, self.calibration)
        if health.windows == 0:
            raise InputError(f"{self.stream_id}: no decided window this session: no health index")
        joints = self.tracker.update(self.stream_id, self.day, health)
        fields = dict(health_fields(joints))
        for j in joints:
            name = j.joint
            print(
                f"health {self.stream_id} day {self.day:g} {name}: {fields[f'health.{name}']} "
                f"[{fields[f'health.{name}.band']}] RUL {fields[f'rul_days.{name}']} d "
                f"[{fields[f'rul_days.{name}.band']}]" + ("  WEAR WARNING" if j.warning else "")
            )
        return joints


def print_change(
    stream_id: str, t: float, d: HealthDiagnosis, truth, last: str | None
) -> str | None:
    """Print an alarm raised or cleared, and each change of diagnosis with the truth."""
    if d.alarm in ("raised", "cleared"):
        where = f" @ {d.alarm_joint}" if d.alarm_joint else ""
        print(f"t={t:8.2f}s {stream_id}: ALARM {d.alarm.upper()} {d.alarm_class or ''}{where}")
    shown = describe(d)
    if shown.split(" (")[0] == (last or "").split(" (")[0]:
        return last
    label = ""
    if truth is not None:
        label = (
            f"   [truth: {truth.fault_class} @ {truth.joint} sev {truth.severity:g}]"
            if truth.active
            else "   [truth: healthy]"
        )
    print(f"t={t:8.2f}s {stream_id}: {shown}{label}", flush=True)
    return shown


def _num(value: float | None) -> str:
    return "n/a" if value is None else f"{value:.3f}"


def evaluation_path(out: str | None, name: str) -> Path:
    """Where an on-line evaluation goes: ``out``, or a new run directory under ``outputs/``."""
    stamp = datetime.now().strftime("%Y-%m-%d_%H-%M-%S")
    return Path(out or Path("outputs/monitor") / stamp / name)
