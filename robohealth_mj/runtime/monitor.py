"""The monitor (``python -m robohealth_mj.monitor``): one session that takes each diagnosis,
whatever the source: every change of diagnosis and every alarm printed, the topics and
diagnoses optionally written to a bag, each stream's on-line evaluation and wear. A simulated or
replayed stream is pulled through it here; live arms on the bus push into it
(:func:`robohealth_mj.ros2.live.monitor_arms`)."""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Iterator
from contextlib import ExitStack
from datetime import datetime
from pathlib import Path

import numpy as np
from omegaconf import DictConfig

from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.bags.writer import BagWriter
from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.common.errors import InputError
from robohealth_mj.data.observability import MOVING_RAD_S
from robohealth_mj.data.read import open_recording
from robohealth_mj.data.sensing import refuse_missing_channels
from robohealth_mj.prognostics.channels import ChannelSums
from robohealth_mj.prognostics.health import (
    attribution_from_probabilities,
    mode_probabilities,
    session_health,
)
from robohealth_mj.prognostics.index_model import FittedIndex, session_reading
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.prognostics.signature import LOAD_DAYS
from robohealth_mj.runtime.alarms import AlarmPolicy
from robohealth_mj.runtime.contact import ContactPolicy
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.runtime.fleet import freeze_startup_heap
from robohealth_mj.runtime.health import HealthTracker, health_fields
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


def refuse_lacking_data(model_sensing: str, data_sensing: str, source: str) -> None:
    """One line when the data lacks channels the exported model reads."""
    refuse_missing_channels(model_sensing, data_sensing, source)


def refuse_other_arm(model_arm: str, data_arm: str | None, source: str) -> None:
    """One line when a recording names another arm than the one the exported model reads (its
    readings would be read against the wrong ratings)."""
    if data_arm is not None and data_arm != model_arm:
        raise InputError(
            f"{source}: a recording of a {data_arm}; the model reads a {model_arm} (export one "
            f"for the {data_arm}: python -m robohealth_mj.export data=<a {data_arm} recording>)"
        )


def decide_every(value: object) -> int:
    """``decide_every`` as a tick count, or a one-line refusal."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InputError(f"decide_every: {value!r} is not a whole number of ticks >= 1")
    return value


def monitor_policies(cfg: DictConfig) -> tuple[AlarmPolicy, EvidencePolicy, ContactPolicy]:
    """The ``alarm``, ``evidence`` and ``contact`` blocks as their policies; a bad value is the
    user's to fix, named by its block."""
    built = []
    for key, kind in (("alarm", AlarmPolicy), ("evidence", EvidencePolicy),
                      ("contact", ContactPolicy)):  # fmt: skip
        try:
            built.append(kind(**cfg[key]))
        except (TypeError, ValueError) as exc:
            raise InputError(f"conf/monitor.yaml {key}: {exc}") from None
    return built[0], built[1], built[2]


def pulled_source(cfg: DictConfig, runtime: ModelRuntime) -> tuple[Iterator[tuple], bool]:
    """``(t, sample, truth)`` from the simulator or a replayed recording (looked at once: its
    kind, profile and arm), after refusing data the model cannot read; and whether its truth is
    known (a controller log has none: read as healthy, it counts false alarms, never shown)."""
    if cfg.source == "sim":
        return sim_stream(list(cfg.sim_overrides), cfg.duration_s), True
    if cfg.source != "replay":
        raise InputError(f"source must be sim, replay or ros2, got {cfg.source!r}")
    if not cfg.file:
        raise InputError("source=replay needs file=PATH to a graphs.jsonl, a bag directory or a "
                         "controller log (.csv, .parquet), or file=sample")  # fmt: skip
    recording = open_recording(cfg.file)
    if runtime.fleet.engine is not None:
        refuse_lacking_data(runtime.fleet.sensing, recording.sensing, cfg.file)
        refuse_other_arm(runtime.arm, recording.arm, cfg.file)
    return replay_stream(recording), recording.kind != "log"


def paced(stream: Iterator[tuple], speed: float) -> Iterator[tuple]:
    """The stream at ``speed`` x the time its samples carry (0: as fast as it comes)."""
    started, t0 = time.perf_counter(), None
    for item in stream:
        if speed and t0 is not None:
            delay = (item[0] - t0) / speed - (time.perf_counter() - started)
            if delay > 0:
                time.sleep(delay)
        t0 = item[0] if t0 is None else t0
        yield item


def monitor_stream(
    cfg: DictConfig, runtime: ModelRuntime, policy: AlarmPolicy, evidence: EvidencePolicy
) -> dict | None:
    """``source=sim`` or ``replay``: the source's samples pulled through the runtime into the
    monitor's session, one stream (``stream_id``)."""
    stream, labelled = pulled_source(cfg, runtime)
    freeze_startup_heap()
    valid = 0
    shown = not cfg.quiet
    with MonitorSession(cfg, runtime, policy, evidence, shown, labelled) as session:
        for t, sample, truth in paced(stream, cfg.speed):
            valid += isinstance(sample, GraphSample)
            session.diagnosed(
                cfg.stream_id, t, sample, truth, runtime.process(cfg.stream_id, sample)
            )
    if not valid:  # nothing was diagnosed: not a run to pass off as a healthy one
        raise InputError(f"{cfg.file or cfg.source}: no valid sample to diagnose")
    return session.finish()


class MonitorSession:
    """What the monitor does with each diagnosis, whatever the source (simulated, replayed or
    live): print each change and alarm, write the topics and diagnoses to a bag, feed each
    stream's on-line evaluation against its truth and its wear; when it ends, the wear into each
    arm's health history and the evaluation into a file. The simulator and a replay are pulled
    through it (:func:`monitor_stream`); live arms push into it
    (:func:`robohealth_mj.ros2.live.monitor_arms`)."""

    def __init__(
        self, cfg: DictConfig, runtime: ModelRuntime, policy: AlarmPolicy,
        evidence: EvidencePolicy, print_changes: bool = True, labelled: bool = True,
    ) -> None:  # fmt: skip
        self.cfg, self.runtime, self.print_changes = cfg, runtime, print_changes
        self.labelled = labelled  # the source's truth is known, so printed beside each change
        self.settle = runtime.window + policy.clear_after + evidence.clearing_ticks
        self.evaluators: dict[str, OnlineEvaluator] = {}
        self.wear: dict[str, SessionWear] = {}
        self.last: dict[str, str | None] = {}
        health = cfg.get("health", {})
        self.health = health if health.get("state_dir") else None
        if self.health is not None and cfg.source != "ros2":
            # a bad health block is refused before the session
            self.wear[cfg.stream_id] = SessionWear(cfg.stream_id, self.health, runtime.window)
        self._stack = ExitStack()
        self.bag = self._stack.enter_context(BagWriter(cfg.bag_out)) if cfg.get("bag_out") else None

    def __enter__(self) -> MonitorSession:
        return self

    def __exit__(self, *exc) -> None:
        self._stack.close()

    def diagnosed(
        self, stream_id: str, t: float, sample: GraphSample | str, truth, d: HealthDiagnosis
    ) -> None:
        """One diagnosis of ``stream_id``'s sample (``truth``: its fault label, None unknown)."""
        fleet = self.runtime.fleet
        wanted = self.health is not None or (self.cfg.evaluate and truth is not None)
        activity = joint_activity(sample.x) if wanted and isinstance(sample, GraphSample) else ()
        if self.bag is not None and isinstance(sample, GraphSample):
            self.bag.write_sample(sample)
            self.bag.write_diagnosis(d, fleet.classes, fleet.joints)
        if self.cfg.evaluate and truth is not None:
            if stream_id not in self.evaluators:
                self.evaluators[stream_id] = OnlineEvaluator(
                    settle_ticks=self.settle, arm=self.runtime.arm
                )
            self.evaluators[stream_id].update(truth, d, *activity)
        if self.print_changes:
            shown = truth if self.labelled else None
            self.last[stream_id] = print_change(stream_id, t, d, shown, self.last.get(stream_id))
        if self.health is not None:
            if stream_id not in self.wear:
                self.wear[stream_id] = SessionWear(stream_id, self.health, self.runtime.window)
            x = sample.x if isinstance(sample, GraphSample) else None
            self.wear[stream_id].add(d, fleet.joints, activity[0] if activity else None, x)

    def finish(self) -> dict | None:
        """Wear into each arm's history; the evaluation written (one stream: its figures; live
        arms: per arm) and returned."""
        for wear in self.wear.values():
            wear.finish()
        if self.bag is not None:
            print(f"replayed topics and {BagTopics.load().health_diagnosis} -> {self.cfg.bag_out}")
        if not self.cfg.evaluate:
            return None
        if self.cfg.source == "ros2":
            result = {arm: e.result() for arm, e in self.evaluators.items()}
            out = evaluation_path(self.cfg.out, "online_eval_ros2.json")
            atomic_write_json(out, {"model": self.runtime.describe(), "source": "ros2",
                                    "arms": result})  # fmt: skip
            print(f"on-line evaluation of {len(result)} arms -> {out}")
            return result
        evaluator = self.evaluators.get(self.cfg.stream_id) or OnlineEvaluator(
            settle_ticks=self.settle, arm=self.runtime.arm
        )
        result = {
            "model": self.runtime.describe(),
            "source": self.cfg.source,
            "file": self.cfg.file,
            "alarm_policy": dict(self.cfg.alarm),
            "evidence_policy": dict(self.cfg.evidence),
            **evaluator.result(),
        }
        out = evaluation_path(self.cfg.out, "online_eval.json")
        atomic_write_json(out, result)
        atomic_write_text(out.with_suffix(".md"), online_markdown(result))
        print(summary_line(result, out))
        return result


def summary_line(result: dict, out: Path) -> str:
    alarms = result["alarms"]
    return (
        f"on-line accuracy {_num(result['online_accuracy'])}  localisation "
        f"{_num(result['localisation_accuracy'])} | alarms: detected "
        f"{alarms['detected']}/{alarms['episodes']} episodes, false alarms "
        f"{_num(result['false_alarm_rate'])} of settled healthy ticks "
        f"({_num(result['false_alarms_per_hour'])}/h), latency to class "
        f"{_num(alarms['class_latency_s_median'])} s, to joint "
        f"{_num(alarms['joint_latency_s_median'])} s (medians); contact calls "
        f"{result['contact_calls']} -> {out}"
    )


class SessionWear:
    """The session's decided windows, turned into the arm's health index when it ends and added
    to the arm's history (``health.state_dir``; :mod:`robohealth_mj.runtime.health`)."""

    def __init__(self, stream_id: str, cfg: DictConfig, window: int = 32) -> None:
        """``window``: the model's, in snapshots (a window *moved* a joint if any of its
        snapshots turned it, as :func:`robohealth_mj.data.windows.joints_moved` reads it)."""
        if cfg.get("day") is None:
            raise InputError("health.state_dir needs health.day: this session's operating day")
        cal = cfg.get("calibration")
        self.index = FittedIndex.load(cal) if cal else None  # how the index is read (studies/wear)
        self.tracker = HealthTracker(
            Path(cfg.state_dir),
            TrendRul(
                threshold=float(cfg.threshold),
                min_sessions=int(cfg.get("min_sessions", 3)),
                since=float(cfg.floor) if cfg.get("fit_since_floor") else None,
            ),
            lead_days=float(cfg.lead_days),
            floor=float(cfg.floor),
            monotone=bool(self.index and self.index.model.monotone),
        )
        self.tracker.history(stream_id)  # a broken state file is refused before the session
        self.stream_id, self.day = stream_id, float(cfg.day)
        self.probs: list[list[float]] = []
        self.joints: list[list[float]] = []
        self.moved: list[np.ndarray] = []  # per decided window: each joint turned in it
        self.speeds: deque[np.ndarray] = deque(maxlen=max(1, int(window)))
        self.names: list[str] = list(JOINT_NAMES)  # the model's joints (the arm's)
        self.channels: ChannelSums | None = None  # the session's friction and backlash channels

    def add(
        self,
        d: HealthDiagnosis,
        joints: list[str],
        speeds: np.ndarray | None = None,
        x: np.ndarray | None = None,
    ) -> None:
        """One diagnosis; ``speeds [J]``: the joints' |velocity| in the sample that completed it,
        ``x [N, F]`` the sample (its channels feed the friction and backlash readings)."""
        self.names = list(joints)
        if speeds is not None and len(speeds) == len(joints):
            self.speeds.append(np.asarray(speeds, float))
        if x is not None:
            if self.channels is None:
                self.channels = ChannelSums(len(joints))
            self.channels.add(x)
        if d.valid and d.fault_class is not None:
            self.probs.append([d.class_probabilities.get(c, 0.0) for c in FAULT_CLASSES])
            self.joints.append([d.joint_scores[j] for j in joints])
            turned = np.max(self.speeds, axis=0) if self.speeds else np.zeros(len(joints))
            self.moved.append(turned > MOVING_RAD_S)

    def finish(self) -> list:
        p_class = np.array(self.probs).reshape(-1, len(FAULT_CLASSES))
        p_joint = np.array(self.joints).reshape(-1, len(self.names))
        health = session_health(attribution_from_probabilities(p_class, p_joint))
        if health.windows == 0:
            raise InputError(f"{self.stream_id}: no decided window this session: no health index")
        channel = None if self.channels is None else self.channels.readings()
        if self.index is not None:  # the calibrated reading and its band
            day = {"raw": health.raw, **session_reading(
                mode_probabilities(p_class, p_joint), np.array(self.moved).reshape(p_joint.shape)
            )}  # fmt: skip
            if channel is not None:  # with the last days' readings, oldest first
                day["channel"] = channel
                earlier = self.tracker.recent_channels(self.stream_id, LOAD_DAYS - 1)
                if all(r.shape == channel.shape for r in earlier):
                    day["recent_channel"] = [*earlier, channel]
            elif self.index.model.raw == "channel":
                raise InputError(f"{self.stream_id}: the index reads the joints' channels, and "
                                 "this source gave none")  # fmt: skip
            health.index = self.index.calibrate(day)
            health.low, health.high = self.index.band(health.low, health.high, health.index)
        joints = self.tracker.update(self.stream_id, self.day, health, self.names, channel)
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
