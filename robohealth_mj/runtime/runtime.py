"""The streaming health-monitoring runtime.

``ModelRuntime`` keeps a sliding window per robot stream, validates every incoming GraphSample,
and once per tick runs the ONNX model on all streams whose window is full, as one batch. Every
submitted sample gets a ``HealthDiagnosis``; a bad sample gets one flagged invalid with the reason,
never an exception. Without a usable model, diagnoses say so explicitly (fault absent, confidence
0) and nothing from the input's labels is ever echoed.
"""

from __future__ import annotations

import json
import logging
import time
from collections import deque
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj import schema
from robohealth_mj.schema import GraphSample, SchemaError, validate_sample

log = logging.getLogger(__name__)


@dataclass
class HealthDiagnosis:
    stamp: float  # sim/robot time of the sample that completed the window
    stream_id: str
    sample_index: int | None
    valid: bool
    fault_present: bool = False
    fault_class: str | None = None
    class_probabilities: dict[str, float] = field(default_factory=dict)
    joint_scores: dict[str, float] = field(default_factory=dict)
    localised_joint: str | None = None
    confidence: float = 0.0
    inference_latency_ms: float = 0.0
    model_id: str = "none"
    reason: str | None = None  # why invalid, or why there is no decision (warming up, no model)

    def to_json(self) -> str:
        return json.dumps(asdict(self), sort_keys=True)


@dataclass
class _Stream:
    window: deque
    last_t: float | None = None
    last_index: int | None = None
    pending: tuple[float, int] | None = None  # a new sample not yet diagnosed


def _softmax(z: np.ndarray) -> np.ndarray:
    e = np.exp(z - z.max(axis=-1, keepdims=True))
    return e / e.sum(axis=-1, keepdims=True)


class ModelRuntime:
    """Sliding windows per stream + one batched ONNX call per tick."""

    def __init__(self, model_path: str | Path | None, threads: int = 1) -> None:
        self.session = None
        self.model_id = "none"
        self.window = 16
        self.classes = list(schema.FAULT_CLASSES)
        self.joints = list(schema.JOINT_NAMES)
        self.problem: str | None = None
        self._streams: dict[str, _Stream] = {}
        self._load(model_path, threads)

    def _load(self, model_path: str | Path | None, threads: int) -> None:
        if not model_path:
            self.problem = "no model configured"
        elif not Path(model_path).is_file():
            self.problem = f"no model file at {model_path}"
        else:
            try:
                import onnxruntime as ort

                from robohealth_mj.runtime.export import read_metadata

                meta = read_metadata(model_path)
                if meta.get("node_names") != list(schema.NODE_NAMES):
                    raise ValueError("model node order differs from this schema")
                if meta.get("schema_version") != schema.SCHEMA_VERSION:
                    raise ValueError(
                        f"model schema {meta.get('schema_version')} != {schema.SCHEMA_VERSION}"
                    )
                options = ort.SessionOptions()
                options.intra_op_num_threads = threads
                self.session = ort.InferenceSession(
                    str(model_path), options, providers=ort.get_available_providers()
                )
                self.window = int(meta["window"])
                self.classes, self.joints = meta["classes"], meta["joints"]
                self.model_id = meta["model_id"]
            except Exception as exc:  # a broken model must not take the monitor down
                self.session = None
                self.problem = f"model {model_path} unusable: {type(exc).__name__}: {exc}"
        if self.session is None:
            log.warning(
                "ModelRuntime running without a model (%s): every diagnosis will say "
                "'no model', fault absent, confidence 0",
                self.problem,
            )

    # ingestion

    def submit(self, stream_id: str, sample: dict | str | GraphSample) -> HealthDiagnosis | None:
        """Validate and buffer one sample. Returns an invalid diagnosis at once for a bad
        sample; otherwise None (the diagnosis comes from the next :meth:`tick`)."""
        stream = self._streams.setdefault(stream_id, _Stream(deque(maxlen=self.window)))
        try:
            s = self._parse(sample)
        except SchemaError as exc:
            return self._invalid(stream_id, stream, str(exc))
        if stream.last_t is not None and s.t <= stream.last_t:
            return self._invalid(
                stream_id,
                stream,
                f"time went backwards: t={s.t} after {stream.last_t}",
                stamp=s.t,
                index=s.sample_index,
            )
        gap = stream.last_index is not None and s.sample_index != stream.last_index + 1
        previous = stream.last_index
        stream.last_t, stream.last_index = s.t, s.sample_index
        if gap:
            stream.window.clear()  # a window must be contiguous: start again from this sample
        stream.window.append(s.x)
        stream.pending = (s.t, s.sample_index)
        if gap:
            return self._invalid(
                stream_id,
                stream,
                f"gap in sample_index ({previous} -> {s.sample_index}); window restarted",
                stamp=s.t,
                index=s.sample_index,
            )
        return None

    @staticmethod
    def _parse(sample: dict | str | GraphSample) -> GraphSample:
        if isinstance(sample, GraphSample):
            if not np.all(np.isfinite(sample.x)):
                raise SchemaError("NaN or Inf", field="x")
            if sample.x.shape != (schema.N_NODES, schema.N_FEATURES):
                raise SchemaError(f"shape {sample.x.shape}", field="x")
            return sample
        if isinstance(sample, str):
            try:
                sample = json.loads(sample)
            except json.JSONDecodeError as exc:
                raise SchemaError(f"invalid JSON ({exc.msg})", field="<json>") from None
        return validate_sample(sample, source="stream")

    def _invalid(
        self,
        stream_id: str,
        stream: _Stream,
        reason: str,
        stamp: float | None = None,
        index: int | None = None,
    ) -> HealthDiagnosis:
        return HealthDiagnosis(
            stamp=stamp if stamp is not None else (stream.last_t or 0.0),
            stream_id=stream_id,
            sample_index=index,
            valid=False,
            model_id=self.model_id,
            reason=reason,
        )

    # inference

    def tick(self) -> list[HealthDiagnosis]:
        """Diagnose every stream that received a sample since the last tick (one batch)."""
        ready, waiting = [], []
        for sid, stream in self._streams.items():
            if stream.pending is None:
                continue
            (ready if len(stream.window) == self.window else waiting).append(sid)
        out = [self._no_decision(sid, "warming up: window not full yet") for sid in waiting]
        if ready:
            out += (
                self._infer(ready)
                if self.session is not None
                else [self._no_decision(sid, self.problem or "no model") for sid in ready]
            )
        for sid in ready + waiting:
            self._streams[sid].pending = None
        return out

    def process(self, stream_id: str, sample: dict | str | GraphSample) -> HealthDiagnosis:
        """Submit one sample and diagnose its stream right away (single-stream convenience)."""
        invalid = self.submit(stream_id, sample)
        if invalid is not None and not invalid.reason.startswith("gap"):
            return invalid
        results = {d.stream_id: d for d in self.tick()}
        return invalid or results[stream_id]

    def _no_decision(self, stream_id: str, reason: str) -> HealthDiagnosis:
        t, index = self._streams[stream_id].pending or (0.0, None)
        return HealthDiagnosis(
            stamp=t,
            stream_id=stream_id,
            sample_index=index,
            valid=True,
            model_id=self.model_id,
            reason=reason,
        )

    def _infer(self, stream_ids: list[str]) -> list[HealthDiagnosis]:
        batch = np.stack([np.stack(self._streams[s].window) for s in stream_ids]).astype(np.float32)
        start = time.perf_counter()
        outputs = self.session.run(None, {"x": batch})
        latency = (time.perf_counter() - start) * 1e3
        probs = _softmax(outputs[0])
        joints = 1.0 / (1.0 + np.exp(-outputs[1]))
        out = []
        for k, sid in enumerate(stream_ids):
            t, index = self._streams[sid].pending
            c = int(probs[k].argmax())
            present = c != 0
            out.append(
                HealthDiagnosis(
                    stamp=t,
                    stream_id=sid,
                    sample_index=index,
                    valid=True,
                    fault_present=present,
                    fault_class=self.classes[c],
                    class_probabilities={
                        n: float(p) for n, p in zip(self.classes, probs[k], strict=True)
                    },
                    joint_scores={n: float(v) for n, v in zip(self.joints, joints[k], strict=True)},
                    localised_joint=self.joints[int(outputs[1][k].argmax())] if present else None,
                    confidence=float(probs[k, c]),
                    inference_latency_ms=latency,
                    model_id=self.model_id,
                )
            )
        return out

    @property
    def streams(self) -> list[str]:
        return list(self._streams)

    def describe(self) -> dict[str, Any]:
        return {"model_id": self.model_id, "window": self.window, "problem": self.problem}
