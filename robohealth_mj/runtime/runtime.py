"""The per-sample face of the streaming runtime: JSON lines, dicts or GraphSamples in,
``HealthDiagnosis`` objects out.

``ModelRuntime`` parses and validates each sample (a user's line gets the schema's named-field
errors), queues it, and on :meth:`tick` hands every queued sample to one
:class:`~robohealth_mj.runtime.fleet.FleetRuntime` step, which owns the windows, the model and
the alarms. Every submitted sample gets a diagnosis; a bad one is flagged invalid with the reason,
never an exception. Without a usable model, diagnoses say so explicitly (fault absent, confidence
0) and nothing from the input's labels is ever echoed. For many streams at once, use
``FleetRuntime`` directly: it takes arrays and returns arrays.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj import schema
from robohealth_mj.runtime.alarms import STATE_NAMES, AlarmPolicy
from robohealth_mj.runtime.contact import ContactPolicy
from robohealth_mj.runtime.evidence import EvidencePolicy
from robohealth_mj.runtime.fleet import DECIDED, INVALID, FleetRuntime, TickResult
from robohealth_mj.schema import GraphSample, SchemaError, validate_sample


@dataclass
class HealthDiagnosis:
    stamp: float  # sim/robot time of the sample that completed the window
    stream_id: str
    sample_index: int | None
    valid: bool
    fault_present: bool = False
    fault_class: str | None = None
    class_probabilities: dict[str, float] = field(default_factory=dict)  # this window's
    # ... accumulated over windows (runtime.evidence), what the alarm reads; the window's own
    # when the evidence has no memory
    accumulated_probabilities: dict[str, float] = field(default_factory=dict)
    joint_scores: dict[str, float] = field(default_factory=dict)
    localised_joint: str | None = None
    confidence: float = 0.0
    inference_latency_ms: float = 0.0
    model_id: str = "none"
    reason: str | None = None  # why invalid, or why there is no decision (warming up, no model)
    alarm: str = "none"  # none | raised | held | cleared (debounced, see runtime.alarms)
    alarm_class: str | None = None
    alarm_joint: str | None = None
    # the contact watch (runtime.contact): an external force on an arm holding a pose
    contact: bool = False
    contact_joint: str | None = None  # the joint nearest it (the most distal joint it loads)

    def to_json(self) -> str:
        return json.dumps(asdict(self), sort_keys=True)


def diagnoses(fleet: FleetRuntime, result: TickResult) -> list[HealthDiagnosis]:
    """The rows of a fleet tick as HealthDiagnosis objects (per-row Python: not for the hot
    path of a large fleet)."""
    out = []
    for k in range(len(result)):
        slot = int(result.slot[k])
        name = fleet.names[slot] if 0 <= slot < fleet.capacity else None
        status = int(result.status[k])
        d = HealthDiagnosis(
            stamp=float(result.t[k]),
            stream_id=name or "?",
            sample_index=int(result.sample_index[k]),
            valid=status != INVALID,
            model_id=fleet.model_id,
            reason=result.reasons.get(k),
        )
        if result.contact[k]:
            d.contact, d.contact_joint = True, fleet.joints[int(result.contact_joint[k])]
        if status == DECIDED:
            decide(
                d, result.probs[k], result.joint_scores[k], int(result.alarm[k]),
                int(result.alarm_class[k]), int(result.alarm_joint[k]), fleet.classes, fleet.joints,
                result.accumulated[k],
            )  # fmt: skip
            d.inference_latency_ms = result.inference_ms
        out.append(d)
    return out


def decide(
    d: HealthDiagnosis,
    probs: np.ndarray,
    scores: np.ndarray,
    state: int,
    alarm_class: int,
    alarm_joint: int,
    classes: list[str],
    joints: list[str],
    accumulated: np.ndarray | None = None,
) -> None:
    """Fill ``d`` with one decided tick: class probabilities ``[C]`` (and ``accumulated`` over
    windows, the window's own if not given), joint scores ``[J]`` and the stream's alarm
    (state, class index or 0, joint index)."""
    c = int(probs.argmax())
    d.fault_class, d.fault_present, d.confidence = classes[c], c != 0, float(probs[c])
    d.class_probabilities = {n: float(p) for n, p in zip(classes, probs, strict=True)}
    d.accumulated_probabilities = {
        n: float(p)
        for n, p in zip(classes, probs if accumulated is None else accumulated, strict=True)
    }
    d.joint_scores = {n: float(v) for n, v in zip(joints, scores, strict=True)}
    d.localised_joint = joints[int(scores.argmax())] if d.fault_present else None
    d.alarm = STATE_NAMES[state]
    if alarm_class > 0:
        d.alarm_class, d.alarm_joint = classes[alarm_class], joints[alarm_joint]


class ModelRuntime:
    """Per-sample submission over a :class:`FleetRuntime` (one batched model call per tick)."""

    def __init__(
        self,
        model_path: str | Path | None,
        threads: int = 1,
        alarm: AlarmPolicy | None = None,
        incremental: bool = True,
        evidence: EvidencePolicy | None = None,
        observability: str = "all",
        contact: ContactPolicy | None = None,
        strict: bool = False,
        decide_every: int = 1,
    ) -> None:
        self.fleet = FleetRuntime(
            model_path, threads=threads, alarm=alarm, evidence=evidence, incremental=incremental,
            observability=observability, contact=contact, strict=strict,
            decide_every=decide_every,
        )  # fmt: skip
        self._queue: list[tuple[int, GraphSample]] = []

    @property
    def window(self) -> int:
        return self.fleet.window

    @property
    def model_id(self) -> str:
        return self.fleet.model_id

    @property
    def arm(self) -> str:
        """The arm whose raw readings the model takes."""
        return self.fleet.arm

    @property
    def problem(self) -> str | None:
        return self.fleet.problem

    def submit(self, stream_id: str, sample: dict | str | GraphSample) -> HealthDiagnosis | None:
        """Validate and queue one sample. Returns an invalid diagnosis at once for a sample that
        does not parse or match the schema; otherwise None (the diagnosis comes from the next
        :meth:`tick`)."""
        slot = int(self.fleet.register([stream_id])[0])
        try:
            s = self._parse(sample)
        except SchemaError as exc:
            return HealthDiagnosis(
                stamp=0.0,
                stream_id=stream_id,
                sample_index=None,
                valid=False,
                model_id=self.model_id,
                reason=str(exc),
            )
        self._queue.append((slot, s))
        return None

    def _parse(self, sample: dict | str | GraphSample) -> GraphSample:
        """A sample on the model's arm graph, or SchemaError naming the field."""
        graph = self.fleet.graph
        if isinstance(sample, GraphSample):
            if sample.x.shape != (graph.n_nodes, schema.N_FEATURES):
                raise SchemaError(f"shape {sample.x.shape}", field="x")
            if sample.graph.nodes != graph.nodes:
                raise SchemaError(f"nodes of joints {list(sample.graph.joints)}; the model "
                                  f"reads {list(graph.joints)}", field="nodes")  # fmt: skip
            return sample
        if isinstance(sample, str):
            try:
                sample = json.loads(sample)
            except json.JSONDecodeError as exc:
                raise SchemaError(f"invalid JSON ({exc.msg})", field="<json>") from None
        if self.fleet.engine is None:  # no model: any arm's sample is read as itself
            return validate_sample(sample, source="stream")
        return validate_sample(sample, source="stream", graph=graph)

    def tick(self) -> list[HealthDiagnosis]:
        """Diagnose every queued sample (one fleet step)."""
        if not self._queue:
            return []
        queue, self._queue = self._queue, []
        result = self.fleet.step(
            np.array([slot for slot, _ in queue], np.int64),
            np.array([s.sample_index for _, s in queue], np.int64),
            np.array([s.t for _, s in queue]),
            np.stack([s.x for _, s in queue]).astype(np.float32),
        )
        return diagnoses(self.fleet, result)

    def process(self, stream_id: str, sample: dict | str | GraphSample) -> HealthDiagnosis:
        """Submit one sample and diagnose it right away (single-stream convenience)."""
        invalid = self.submit(stream_id, sample)
        if invalid is not None:
            return invalid
        return self.tick()[-1]

    @property
    def streams(self) -> list[str]:
        return self.fleet.streams

    def forget(self, stream_id: str) -> None:
        """Drop a stream's window, evidence and alarm state and its queued samples (a stream that
        comes back starts afresh, as after an idle release)."""
        slot = self.fleet.ids.get(stream_id)
        self._queue = [(k, s) for k, s in self._queue if slot is None or k != slot]
        if slot is not None:
            self.fleet.release(np.array([slot]))

    def describe(self) -> dict[str, Any]:
        return self.fleet.describe()
