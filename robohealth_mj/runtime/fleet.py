"""The fleet runtime: many 20 Hz streams diagnosed in bulk, one batch per tick.

Samples arrive as arrays, one row per sample: ``slots [R]`` (from :meth:`FleetRuntime.register`),
``sample_index [R]``, ``t [R]``, ``x [R, 2J, F]`` on the model's arm graph (and optionally
``layout_ok [R]``, whether the sender's node order is the model's). Every check is vectorised
over the rows, each stream's window lives in preallocated arrays
(:mod:`robohealth_mj.runtime.incremental`), the model runs once per tick on every stream whose
window is full, each stream's evidence accumulates over its windows
(:mod:`robohealth_mj.runtime.evidence`; reset with the window on a gap), and the alarms update
in bulk on the accumulated probabilities. With ``observability="motion"`` a stream's window
calls friction and backlash only on joints that moved in it
(:mod:`robohealth_mj.data.observability`; the last sample index at which each joint moved is
kept per stream). A model commissioned with contact thresholds also runs the contact watch
on every valid row (:mod:`robohealth_mj.runtime.contact`: a push on an arm that holds a pose),
warming rows included. A bad row
never raises: it comes back flagged with its reason. Several rows from one stream in one tick
(a burst) are taken in order, up to ``max_burst``; the rest are flagged and dropped.
"""

from __future__ import annotations

import base64
import gc
import logging
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.description import DEFAULT_ARM
from robohealth_mj.common.errors import USER_ERRORS, InputError
from robohealth_mj.common.numeric import joint_scores_from_logits, softmax
from robohealth_mj.common.threads import onnx_session_options
from robohealth_mj.data.observability import MOVING_RAD_S, check_observability, hide_unobservable
from robohealth_mj.data.sensing import load_profile
from robohealth_mj.runtime.alarms import AlarmBank, AlarmPolicy
from robohealth_mj.runtime.contact import ContactBank, ContactPolicy, contact_metadata
from robohealth_mj.runtime.evidence import EvidenceBank, EvidencePolicy
from robohealth_mj.runtime.hold import DecisionHold
from robohealth_mj.runtime.incremental import IncrementalEngine, WindowedEngine
from robohealth_mj.runtime.phases import NO_CLOCK, NoClock

log = logging.getLogger(__name__)

DECIDED, WARMING, INVALID, NO_MODEL, BUFFERED = 0, 1, 2, 3, 4
JOINT_SCORES = ("softmax", "sigmoid")  # how joint logits become scores (ONNX metadata)

_NEVER = -(2**62)  # the sample index at which a joint that has not moved yet last moved
_VEL = schema.feature_index("vel")


@dataclass
class TickResult:
    """One row per submitted sample, in submission order (bursts: each sample in turn)."""

    slot: np.ndarray  # [R]
    sample_index: np.ndarray  # [R]
    t: np.ndarray  # [R]
    status: np.ndarray  # [R] DECIDED, WARMING, INVALID, NO_MODEL or BUFFERED (burst catch-up)
    probs: np.ndarray  # [R, C] class probabilities (zero unless decided)
    accumulated: np.ndarray  # [R, C] the evidence accumulated over windows the alarms read
    joint_scores: (
        np.ndarray
    )  # [R, J] joint scores, softmax or sigmoid as trained (zero unless decided)
    alarm: np.ndarray  # [R] alarms.NONE/RAISED/HELD/CLEARED (decided rows)
    alarm_class: np.ndarray  # [R] alarmed class index, 0 when none
    alarm_joint: np.ndarray  # [R] alarmed joint index, -1 when none
    contact: np.ndarray  # [R] the contact watch's call (valid rows; False when it is off)
    contact_joint: np.ndarray  # [R] the joint nearest the contact, -1 when none
    reasons: dict[int, str] = field(default_factory=dict)  # row -> why flagged / undecided
    inference_ms: float = 0.0

    def __len__(self) -> int:
        return len(self.slot)


def _empty(n: int, classes: int, joints: int) -> dict[str, np.ndarray]:
    return {
        "status": np.full(n, INVALID, np.int8),
        "probs": np.zeros((n, classes), np.float32),
        "accumulated": np.zeros((n, classes), np.float32),
        "joint_scores": np.zeros((n, joints), np.float32),
        "alarm": np.zeros(n, np.int8),
        "alarm_class": np.zeros(n, np.int64),
        "alarm_joint": np.full(n, -1, np.int64),
        "contact": np.zeros(n, bool),
        "contact_joint": np.full(n, -1, np.int64),
    }


def freeze_startup_heap() -> None:
    """Move every object alive now (torch, onnxruntime, the model) out of the cyclic garbage
    collector's reach. A full collection walks them all (about 0.2 s with torch imported), which
    would land inside some tick; a long-running runtime process calls this once after start-up."""
    gc.collect()
    gc.freeze()


PREFERRED_PROVIDERS = ("CUDAExecutionProvider", "CPUExecutionProvider")


def execution_providers(asked: Sequence[str] | None, available: Sequence[str]) -> list[str]:
    """The ONNX Runtime providers to open sessions with: those ``asked`` (first preferred), or
    CUDA where onnxruntime-gpu finds a GPU and else the CPU. A name this install lacks is an
    error rather than ORT's silent fall-back to the CPU."""
    if not asked:
        return [name for name in PREFERRED_PROVIDERS if name in available]
    missing = [name for name in asked if name not in available]
    if missing:
        raise InputError(
            f"execution provider {missing[0]!r} is not in this onnxruntime install; "
            f"available: {', '.join(available)}"
        )
    return list(asked)


class FleetRuntime:
    """Per-stream windows, bulk validation, one model call per tick, alarms."""

    def __init__(
        self,
        model_path: str | Path | None,
        *,
        threads: int = 1,
        alarm: AlarmPolicy | None = None,
        evidence: EvidencePolicy | None = None,
        incremental: bool = True,
        capacity: int = 64,
        max_streams: int = 8192,
        max_burst: int = 8,
        max_gap_s: float = 0.25,
        idle_ticks: int = 1200,
        shards: int = 1,
        chunk: int = 256,
        providers: Sequence[str] | None = None,
        observability: str = "all",
        contact: ContactPolicy | None = None,
        strict: bool = False,
        decide_every: int = 1,
    ) -> None:
        """``strict``: a model named but missing or unusable raises (a command's user named
        it) instead of leaving the runtime running without one (a library's caller).
        ``decide_every``: run the model on a stream every this many ticks and hold its outputs
        in between (:mod:`robohealth_mj.runtime.hold`); 1: every tick."""
        self.observability = check_observability(observability)
        self.contact_policy = contact or ContactPolicy()
        self.contact: ContactBank | None = None  # set by a model that carries thresholds
        self.max_streams, self.max_burst = max_streams, max_burst
        self.chunk = max(1, chunk)
        self.max_gap_s, self.idle_ticks = max_gap_s, idle_ticks
        self.shards, self.threads = max(1, shards), threads
        capacity = max(1, min(capacity, max_streams))
        self._pool = ThreadPoolExecutor(self.shards) if self.shards > 1 else None
        self.window, self.model_id, self.problem = 16, "none", None
        self.joint_scores = "softmax"
        self.arm = DEFAULT_ARM  # the arm whose raw readings the model takes
        self.sensing = "full"  # the model's sensing profile (data/sensing.py)
        self.graph = schema.UR_GRAPH  # the arm graph the model reads (its metadata's)
        self.classes, self.joints = list(schema.FAULT_CLASSES), list(self.graph.joints)
        self.engine: IncrementalEngine | WindowedEngine | None = None
        self.mode = "none"
        self.providers: list[str] = []  # the execution providers the sessions run on
        if providers:  # a wrong name is the caller's mistake, not a broken model
            import onnxruntime as ort

            providers = execution_providers(providers, ort.get_available_providers())
        self._load(model_path, threads, incremental, capacity, providers, strict)
        if self.engine is not None and observability == "motion":  # the model must read motion
            check_observability(observability, load_profile(self.sensing).joint_channels)
        self.hold = DecisionHold(decide_every, capacity)
        self.alarms = AlarmBank(alarm or AlarmPolicy(), len(self.joints), capacity)
        self.evidence = EvidenceBank(evidence or EvidencePolicy(), len(self.classes), capacity)
        self.last_t = np.full(capacity, -np.inf)
        self.last_index = np.full(capacity, -1, np.int64)
        self.last_seen = np.zeros(capacity, np.int64)
        self.last_moved = np.full((capacity, self.graph.n_joints), _NEVER, np.int64)
        self.active = np.zeros(capacity, bool)
        self.ids: dict[str, int] = {}
        self.names: list[str | None] = [None] * capacity
        self.ticks = 0
        self.clock = NO_CLOCK

    @property
    def clock(self) -> NoClock:
        """Where the step's time goes (:class:`~robohealth_mj.runtime.phases.PhaseClock`);
        measures nothing by default."""
        return self._clock

    @clock.setter
    def clock(self, clock: NoClock) -> None:
        self._clock = clock
        if self.engine is not None:
            self.engine.clock = clock

    # model

    def _load(
        self, model_path, threads: int, incremental: bool, capacity: int,
        providers: Sequence[str] | None, strict: bool,
    ) -> None:  # fmt: skip
        if not model_path:
            self.problem = "no model configured"
        elif not Path(model_path).is_file():
            if strict:
                raise FileNotFoundError(f"{model_path}: no model file")
            self.problem = f"no model file at {model_path}"
        else:
            try:
                self._open(Path(model_path), threads, incremental, capacity, providers)
            except Exception as exc:  # a broken model must not take a library's caller down
                if strict and isinstance(exc, USER_ERRORS):
                    raise
                if strict:  # an old schema, a file onnxruntime cannot load: the user's to fix
                    raise InputError(
                        f"{model_path}: unusable ({type(exc).__name__}: {exc})"
                    ) from exc
                self.engine = None
                self.problem = f"model {model_path} unusable: {type(exc).__name__}: {exc}"
        if self.engine is None:
            log.warning(
                "runtime running without a model (%s): every diagnosis will say 'no model', "
                "fault absent, confidence 0",
                self.problem,
            )

    def _open(
        self, path: Path, threads: int, incremental: bool, capacity: int,
        providers: Sequence[str] | None,
    ) -> None:  # fmt: skip
        import onnxruntime as ort

        from robohealth_mj.runtime.metadata import read_metadata

        meta = read_metadata(path)  # checks the schema version and the arm graph
        self.graph = meta["arm_graph"]
        options = onnx_session_options(threads)
        # named providers were checked in __init__; else CUDA where present, else the CPU
        wanted = list(providers or execution_providers(None, ort.get_available_providers()))
        if "CUDAExecutionProvider" in wanted and hasattr(ort, "preload_dlls"):
            ort.preload_dlls()  # CUDA and cuDNN from the pip-installed nvidia-* packages

        def session(model: str | bytes):
            opened = ort.InferenceSession(model, options, providers=wanted)
            self.providers = opened.get_providers()
            return opened

        self.window = int(meta["window"])
        self.arm = meta.get("arm", DEFAULT_ARM)  # models exported before arms were data: UR5e
        self.sensing = meta.get("sensing", "full")
        self.classes, self.joints = meta["classes"], meta["joints"]
        # models exported before the key existed were all trained with the softmax joint loss
        self.joint_scores = meta.get("joint_scores", "softmax")
        if self.joint_scores not in JOINT_SCORES:
            raise ValueError(f"joint_scores {self.joint_scores!r} is not one of {JOINT_SCORES}")
        if incremental and "incremental_encode" in meta:
            self.engine = IncrementalEngine(
                session(base64.b64decode(meta["incremental_encode"])),
                session(base64.b64decode(meta["incremental_head"])),
                self.window,
                int(meta["incremental_nodes"]),
                schema.N_FEATURES,
                int(meta["incremental_channels"]),
                int(meta["first_signal"]),
                capacity,
            )
            self.mode = "incremental"
        else:
            self.engine = WindowedEngine(
                session(str(path)), self.window, self.graph.n_nodes, schema.N_FEATURES, capacity
            )
            self.mode = "windowed"
        self.model_id = meta["model_id"]
        watch = contact_metadata(meta, str(path))
        if watch is not None and self.contact_policy.enabled:
            threshold, placing = watch
            self.contact = ContactBank(self.contact_policy, threshold, self.arm, capacity, placing)

    # streams

    @property
    def capacity(self) -> int:
        return len(self.active)

    def register(self, stream_ids: Sequence[str]) -> np.ndarray:
        """Slots of these streams (new ones get free slots; -1 past ``max_streams``)."""
        out = np.empty(len(stream_ids), np.int64)
        for k, sid in enumerate(stream_ids):
            slot = self.ids.get(sid)
            if slot is None:
                slot = self._allocate(sid)
            out[k] = slot
        return out

    def _allocate(self, sid: str) -> int:
        if len(self.ids) >= self.max_streams:
            return -1
        free = np.flatnonzero(~self.active)
        if not len(free):
            if self.capacity >= self.max_streams:
                return -1
            self._grow(min(2 * self.capacity, self.max_streams))
            free = np.flatnonzero(~self.active)
        slot = int(free[0])
        self.active[slot], self.names[slot], self.ids[sid] = True, sid, slot
        self.last_t[slot], self.last_index[slot] = -np.inf, -1
        self.last_seen[slot] = self.ticks
        self.last_moved[slot] = _NEVER
        if self.engine is not None:
            self.engine.reset(np.array([slot]))
        self.hold.reset(np.array([slot]))
        self.alarms.reset(np.array([slot]))
        self.evidence.reset(np.array([slot]))
        if self.contact is not None:
            self.contact.reset(np.array([slot]))
        return slot

    def _grow(self, capacity: int) -> None:
        if self.engine is not None:
            self.engine.ensure(capacity)
        self.hold.ensure(capacity)
        self.alarms.ensure(capacity)
        self.evidence.ensure(capacity)
        if self.contact is not None:
            self.contact.ensure(capacity)
        n = capacity - self.capacity
        self.last_t = np.concatenate([self.last_t, np.full(n, -np.inf)])
        self.last_index = np.concatenate([self.last_index, np.full(n, -1, np.int64)])
        self.last_seen = np.concatenate([self.last_seen, np.zeros(n, np.int64)])
        self.last_moved = np.concatenate(
            [self.last_moved, np.full((n, self.graph.n_joints), _NEVER, np.int64)]
        )
        self.active = np.concatenate([self.active, np.zeros(n, bool)])
        self.names += [None] * n

    def release(self, slots: np.ndarray) -> None:
        """Free these streams' slots (their windows and alarms are forgotten)."""
        for slot in np.asarray(slots, np.int64).tolist():
            name = self.names[slot]
            if name is not None:
                del self.ids[name]
            self.names[slot], self.active[slot] = None, False

    @property
    def streams(self) -> list[str]:
        return list(self.ids)

    # the tick

    def step(
        self,
        slots: np.ndarray,
        sample_index: np.ndarray,
        t: np.ndarray,
        x: np.ndarray,
        layout_ok: np.ndarray | None = None,
    ) -> TickResult:
        """Diagnose one tick's samples (rows); see the module docstring."""
        self._clock.start()
        slots = np.asarray(slots, np.int64)
        n = len(slots)
        sample_index = np.asarray(sample_index, np.int64)
        t = np.asarray(t, np.float64)
        out = _empty(n, len(self.classes), len(self.joints))
        reasons: dict[int, str] = {}
        self.ticks += 1
        x = np.asarray(x, np.float32)
        nodes = x.shape[1] if x.ndim == 3 else 0
        if self.engine is None and nodes != self.graph.n_nodes and nodes >= 4 and nodes % 2 == 0:
            # no model: any arm's samples are checked as they come, and said to have no model
            self.graph = schema.ArmGraph(tuple(f"joint{k + 1}" for k in range(nodes // 2)))
        if x.shape[1:] != (self.graph.n_nodes, schema.N_FEATURES):
            shape = (self.graph.n_nodes, schema.N_FEATURES)
            for k in range(n):
                reasons[k] = f"x has shape {x.shape[1:]}, not {shape} (the model's arm graph)"
            return TickResult(slots, sample_index, t, reasons=reasons, **out)
        known = (slots >= 0) & (slots < self.capacity)
        known[known] &= self.active[slots[known]]
        rank, size = _burst_rank(np.where(known, slots, -1 - np.arange(n)))
        # a burst is buffered in order and decided once, with its last sample: the alarms count
        # ticks, and a stream catching up must not advance them several times in one tick
        final = rank == np.minimum(size, self.max_burst) - 1
        inference = 0.0
        for r in range(int(rank.max(initial=-1)) + 1):
            rows = np.flatnonzero(rank == r)
            if r >= self.max_burst:
                for k in rows.tolist():
                    reasons[k] = (
                        f"burst: more than {self.max_burst} samples from this stream in one "
                        "tick; dropped"
                    )
                continue
            ok_layout = None if layout_ok is None else np.asarray(layout_ok, bool)[rows]
            inference += self._round(
                rows, slots[rows], sample_index[rows], t[rows], x[rows], known[rows], ok_layout,
                final[rows], out, reasons,
            )  # fmt: skip
        self._release_idle()
        result = TickResult(slots, sample_index, t, reasons=reasons, inference_ms=inference, **out)
        self._clock.mark("result")
        return result

    def _round(self, rows, slots, index, t, x, known, layout_ok, final, out, reasons) -> float:
        """Rows with distinct slots: validate, buffer, infer (``final`` rows), alarm. Returns
        the model step's ms."""
        bad = _validate(x, t, known, layout_ok, self.graph)  # [n] reason code, 0 = fine
        s = np.where(known, slots, 0)
        backwards = (bad == 0) & ((t <= self.last_t[s]) | (index <= self.last_index[s]))
        bad[backwards] = _BACKWARDS
        good = bad == 0
        gs, gi, gt = s[good], index[good], t[good]
        gap = (self.last_index[gs] >= 0) & (
            (gi != self.last_index[gs] + 1) | (gt - self.last_t[gs] > self.max_gap_s)
        )
        for k in np.flatnonzero(bad).tolist():
            reasons[int(rows[k])] = _reason(bad[k], x[k], t[k], index[k], s[k], self)
        self.last_seen[gs] = self.ticks
        if self.engine is None:
            out["status"][rows[good]] = NO_MODEL
            for k in rows[good].tolist():
                reasons[k] = self.problem or "no model"
            self.last_t[gs], self.last_index[gs] = gt, gi
            return 0.0
        gr = rows[good]
        gap_rows = gr[gap]
        for k, slot, new in zip(gap_rows.tolist(), gs[gap].tolist(), gi[gap].tolist(), strict=True):
            reasons[k] = (
                f"gap in sample_index ({int(self.last_index[slot])} -> {new}) or over "
                f"{self.max_gap_s} s of time; window restarted"
            )
        if gap.any():  # the window restarts, and the evidence with it
            self.engine.reset(gs[gap])
            self.hold.reset(gs[gap])
            self.evidence.reset(gs[gap])
            self.last_moved[gs[gap]] = _NEVER
            if self.contact is not None:
                self.contact.reset(gs[gap])
        self.last_t[gs], self.last_index[gs] = gt, gi
        xg = x[good]  # one copy of the valid rows for every step below
        if self.observability == "motion":
            fast = np.abs(xg[:, : self.graph.n_joints, _VEL]) > MOVING_RAD_S  # [g, J]
            self.last_moved[gs] = np.where(fast, gi[:, None], self.last_moved[gs])
        if self.contact is not None:  # every valid row, before its window is full too
            out["contact"][gr], out["contact_joint"][gr] = self.contact.update(gs, xg)
        self._clock.mark("validate, bookkeeping")
        start = time.perf_counter()
        decide = final[good]
        full, outputs = self._model_step(gs, xg, decide)
        elapsed = (time.perf_counter() - start) * 1e3
        self._clock.start()  # the model step's phases were charged on the threads that ran them
        warming = gr[~full & ~gap]
        out["status"][warming] = WARMING
        for k in warming.tolist():
            reasons[k] = "warming up: window not full yet"
        buffered = gr[full & ~decide]
        out["status"][buffered] = BUFFERED
        for k in buffered.tolist():
            reasons[k] = "burst: buffered; decided with this stream's last sample of the tick"
        full &= decide
        ready = gs[full]
        if not len(ready):
            return elapsed
        probs = softmax(outputs[0])
        joint_scores = joint_scores_from_logits(outputs[1], self.joint_scores)
        if self.observability == "motion":  # a joint moved within the window's W samples
            moved = self.last_index[ready][:, None] - self.last_moved[ready] < self.window
            probs = hide_unobservable(probs, joint_scores, moved, self.classes)
        accumulated = self.evidence.update(ready, probs)
        state, alarm, joint = self.alarms.update(ready, accumulated, joint_scores)
        target = gr[full]
        out["status"][target] = DECIDED
        out["probs"][target], out["joint_scores"][target] = probs, joint_scores
        out["accumulated"][target] = accumulated
        out["alarm"][target], out["alarm_class"][target] = state, alarm
        out["alarm_joint"][target] = joint
        self._clock.mark("evidence, alarms")
        return elapsed

    def _model_step(
        self, slots: np.ndarray, x: np.ndarray, decide: np.ndarray
    ) -> tuple[np.ndarray, list[np.ndarray]]:
        """Buffer ``x`` and run the model on the ``decide`` streams whose window is full, in
        contiguous parts of at most ``chunk`` streams (at least ``shards`` parts) spread over
        ``shards`` threads (numba, numpy and onnxruntime release the GIL, so the parts run on
        separate cores). Returns the full mask and the outputs of the rows that are full and
        decided."""
        n = len(slots)
        shards = self.shards if n >= 64 * self.shards else 1  # small: not worth a thread
        # parts of at most ``chunk`` streams: each part's arrays stay in the core's cache
        parts = [
            p for p in np.array_split(np.arange(n), max(shards, -(-n // self.chunk))) if len(p)
        ]
        if not parts:
            return np.zeros(0, bool), []

        def shard(p: np.ndarray) -> tuple[np.ndarray, list[np.ndarray] | None]:
            self._clock.start()
            s = slots[p]
            self.engine.push(s, x[p])
            full = self.engine.full(s)
            ready = full & decide[p]
            return full, self.hold.decide(s[ready], self.engine.infer) if ready.any() else None

        pool = self._pool if shards > 1 else None
        done = list(pool.map(shard, parts)) if pool is not None else [shard(p) for p in parts]
        full = np.concatenate([f for f, _ in done])
        outputs = [o for _, o in done if o is not None]
        return full, [np.concatenate(k) for k in zip(*outputs, strict=True)] if outputs else []

    def _release_idle(self) -> None:
        if self.ticks % 20:
            return  # once a second of ticks is enough
        idle = self.active & (self.ticks - self.last_seen > self.idle_ticks)
        if idle.any():
            self.release(np.flatnonzero(idle))

    def close(self) -> None:
        """Stop the shard threads; later steps run on the calling thread."""
        if self._pool is not None:
            self._pool.shutdown()
            self._pool = None
            self.shards = 1

    def describe(self) -> dict:
        return {
            "model_id": self.model_id,
            "arm": self.arm,
            "window": self.window,
            "mode": self.mode,
            "threads": self.threads,
            "decide_every": self.hold.every,
            "joint_scores": self.joint_scores,
            "observability": self.observability,
            "contact": None if self.contact is None else self.contact.threshold.tolist(),
            "problem": self.problem,
        }


_UNKNOWN, _LAYOUT, _TIME, _NAN, _FLAG, _STRAY, _BACKWARDS = range(1, 8)


def _burst_rank(slots: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each row, how many earlier rows of this tick came from the same slot, and how many
    rows that slot has in all."""
    order = np.argsort(slots, kind="stable")
    sorted_slots = slots[order]
    starts = np.flatnonzero(np.r_[True, sorted_slots[1:] != sorted_slots[:-1]])
    counts = np.diff(np.r_[starts, len(slots)])
    group_start = np.repeat(starts, counts)
    rank, size = np.empty(len(slots), np.int64), np.empty(len(slots), np.int64)
    rank[order] = np.arange(len(slots)) - group_start
    size[order] = np.repeat(counts, counts)
    return rank, size


def _validate(
    x: np.ndarray,
    t: np.ndarray,
    known: np.ndarray,
    layout_ok: np.ndarray | None,
    graph: schema.ArmGraph,
) -> np.ndarray:
    """Reason code per row (0 = valid), the first failing check in this order."""
    checks = [
        ~known,
        np.zeros(len(x), bool) if layout_ok is None else ~layout_ok,
        ~np.isfinite(t),
        ~np.isfinite(x).all(axis=(1, 2)),
        (x[:, :, :2] != graph.type_flags()).any(axis=(1, 2)),
        (x[:, : graph.n_joints, schema.SENSOR_CHANNELS] != 0.0).any(axis=(1, 2)),
    ]
    code = np.zeros(len(x), np.int64)
    for value, failed in reversed(list(enumerate(checks, start=1))):
        code[failed] = value
    return code


def _reason(code: int, x: np.ndarray, t: float, index: int, slot: int, fleet: FleetRuntime) -> str:
    """The message for one flagged row (only bad rows pay for this)."""
    if code == _UNKNOWN:
        return f"unknown stream or stream limit ({fleet.max_streams}) reached"
    if code == _LAYOUT:
        return f"node order differs from the model's {list(fleet.graph.nodes)}"
    if code == _TIME:
        return "field 't': not finite"
    if code == _NAN:
        node, feat = np.argwhere(~np.isfinite(x))[0]
        return f"field 'x[{fleet.graph.nodes[node]}].{schema.FEATURE_NAMES[feat]}': NaN or Inf"
    if code == _FLAG:
        return "field 'x.is_joint/is_sensor': node-type indicators do not match the node order"
    if code == _STRAY:
        return "field 'x': joint nodes must zero the sensor channels"
    return (
        f"time went backwards: t={t} (sample_index {index}) after t={fleet.last_t[slot]} "
        f"(sample_index {fleet.last_index[slot]})"
    )
