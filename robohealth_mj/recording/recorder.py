"""Recording one labelled session: simulator -> GraphSample JSONL + manifest.

The manifest is written atomically at the start (status ``running``), and again at the end
(``complete``) or on interruption (``incomplete``). JSONL lines are written whole and flushed per
chunk, so an interrupted session leaves a readable prefix.
"""

from __future__ import annotations

import hashlib
import json
import signal
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from hydra.utils import instantiate
from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from robohealth_mj.arms.description import DEFAULT_ARM, ArmDescription, load_arm, short_name
from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.errors import USER_ERRORS, InputError
from robohealth_mj.common.version import code_version
from robohealth_mj.data.jsonl import format_line, node_features
from robohealth_mj.data.windows import recorded_run_id
from robohealth_mj.faults.injector import FaultInjector
from robohealth_mj.recording.arm import ArmSimulator, TickChunk
from robohealth_mj.schema import SCHEMA_VERSION, FaultLabel
from robohealth_mj.sim.curriculum import Curriculum
from robohealth_mj.sim.pushes import read_pushes
from robohealth_mj.sim.twin_file import read_twin_noise

GRAPHS_FILE = "graphs.jsonl"
MANIFEST_FILE = "manifest.json"
_IDENTITY_EXCLUDE = ("out_dir", "progress", "run_id")
# settings added after recordings were made: left out of the id while unset, so that adding
# them kept every earlier recording's id
_OPTIONAL = (("sim", "friction_solref"), ("sim", "friction_solimp"), ("sensors", "joint_torque"))


def session_config(cfg: DictConfig) -> dict[str, Any]:
    """The resolved config as plain data (what the manifest records)."""
    return OmegaConf.to_container(cfg, resolve=True)  # type: ignore[return-value]


def default_run_id(cfg: DictConfig) -> str:
    """A run id fixed by what was simulated (same config, same id, same bytes)."""
    data = session_config(cfg)
    data["session"] = {k: v for k, v in data["session"].items() if k not in _IDENTITY_EXCLUDE}
    for section, key in _OPTIONAL:
        if data.get(section, {}).get(key, 0) is None:
            del data[section][key]
    if data["session"].get("pushes") == []:  # added later too: out of the id while empty
        del data["session"]["pushes"]
    digest = hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:10]
    return recorded_run_id(short_name(arm_name(cfg)), cfg.seed, digest)


def arm_name(cfg: DictConfig) -> str:
    """The arm a record config simulates (``arm=varied`` alone: the default arm)."""
    return str(cfg.arm.get("name", DEFAULT_ARM))


@dataclass
class SessionStats:
    """Running totals that end up in the manifest and the printed summary."""

    joints: tuple[str, ...]  # the arm's, base to tool
    samples: int = 0
    sq_error: np.ndarray = field(default_factory=lambda: np.zeros(1))
    max_error: np.ndarray = field(default_factory=lambda: np.zeros(1))
    saturated_steps: np.ndarray = field(default_factory=lambda: np.zeros(1, dtype=int))
    max_contacts: int = 0
    visits: list[int] = field(default_factory=list)
    families: dict[str, int] = field(default_factory=dict)
    classes: dict[str, int] = field(default_factory=dict)
    faulted: dict[str, int] = field(default_factory=dict)
    scenarios: set[tuple[str, str, float]] = field(default_factory=set)

    def __post_init__(self) -> None:
        n = len(self.joints)
        self.sq_error, self.max_error = np.zeros(n), np.zeros(n)
        self.saturated_steps = np.zeros(n, dtype=int)

    def add(self, chunk: TickChunk, segment: dict[str, Any], fault: FaultLabel) -> None:
        err = chunk.true_pos - chunk.reference
        n = len(chunk.t)
        self.samples += n
        self.sq_error += (err**2).sum(axis=0)
        self.max_error = np.maximum(self.max_error, np.abs(err).max(axis=0))
        self.saturated_steps += chunk.saturated_steps
        self.max_contacts = max(self.max_contacts, chunk.contacts)
        if not self.visits or self.visits[-1] != chunk.visit:
            self.visits.append(chunk.visit)
        self.families[segment["family"]] = self.families.get(segment["family"], 0) + n
        self.classes[fault.fault_class] = self.classes.get(fault.fault_class, 0) + n
        if fault.active:
            self.faulted[fault.joint] = self.faulted.get(fault.joint, 0) + n
            self.scenarios.add((fault.fault_class, fault.joint, fault.severity))

    def as_dict(self) -> dict[str, Any]:
        rms = np.sqrt(self.sq_error / max(self.samples, 1))
        return {
            "samples": self.samples,
            "tracking_rms_rad": dict(zip(self.joints, rms.round(6).tolist(), strict=True)),
            "tracking_max_rad": dict(
                zip(self.joints, self.max_error.round(6).tolist(), strict=True)
            ),
            "torque_saturated_steps": dict(
                zip(self.joints, self.saturated_steps.tolist(), strict=True)
            ),
            "max_contacts": self.max_contacts,
            "segments_visited": len(self.visits),
            "samples_per_family": dict(sorted(self.families.items())),
            "samples_per_class": dict(sorted(self.classes.items())),
            "faulted_samples_per_joint": dict(sorted(self.faulted.items())),
            "scenarios_covered": len(self.scenarios),
        }


@dataclass
class _StopRequest:
    """The signal that asked the recording to stop, if any (see :func:`_stop_between_chunks`)."""

    signum: int | None = None

    def check(self) -> None:
        if self.signum is not None:
            raise KeyboardInterrupt(f"signal {self.signum}")


@contextmanager
def _stop_between_chunks():
    """Ctrl-C and SIGTERM (a killed job) stop the recording at the next chunk boundary, so the
    lines on disk and the manifest's sample count always agree; an exception raised by the
    signal itself could land between writing a chunk and counting it."""
    request = _StopRequest()
    if threading.current_thread() is not threading.main_thread():
        yield request  # signals reach the main thread only
        return

    def handler(signum: int, frame: Any) -> None:
        request.signum = signum

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield request
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def build_curriculum(cfg: DictConfig, description: ArmDescription) -> Curriculum:
    """The session's curriculum on the arm ``description`` (its ratings, limits and joints)."""
    make_curriculum = instantiate(
        cfg.curriculum,
        seed=cfg.seed,
        rated_payload_kg=description.payload_kg,
        speed_limit_rad_s=description.speed_limit.tolist(),
        _convert_="all",
        _partial_=True,  # the arm is an object, not config: given to the partial
    )
    try:
        return make_curriculum(arm=description)
    except USER_ERRORS as exc:  # named as Hydra names a config object it could not build
        raise InputError(f"config 'curriculum': {exc}") from None


def build_simulator(cfg: DictConfig) -> ArmSimulator:
    """Instantiate model, curriculum, controller and sensors from the composed config."""
    variation = instantiate(cfg.arm)
    description = load_arm(variation.name)
    nominal = instantiate(cfg.sim, arm=description.name)
    model, arm = variation.draw(nominal, cfg.seed)  # the physics: this session's arm
    curriculum = build_curriculum(cfg, description)
    controller = instantiate(cfg.control, model=nominal)  # the controller: the datasheet's
    sensors = instantiate(cfg.sensors, physics_rate_hz=1.0 / model.opt.timestep, _convert_="all")
    # the drive's torque sensing resolves the same fraction of its rating on every arm (each
    # joint against its UR5e counterpart's)
    reference = np.asarray(cfg.sim.reference_torque_nm, dtype=float)
    sensors.effort_scale = description.rated_torque / reference[description.ur_counterpart_index()]
    noise = read_twin_noise(cfg.sim.twin, description.name) if cfg.sim.get("twin") else None
    if noise is not None:  # a twin reads its effort as noisily as the real arm's current does
        sensors.effort_scale = noise / sensors.noise.effort
    variation.apply_to_sensors(sensors, arm)
    tick_s = round(1.0 / (cfg.session.tick_hz * model.opt.timestep)) * model.opt.timestep
    schedule = instantiate(
        cfg.faults.schedule,
        tick_s=tick_s,
        seed=cfg.seed,
        arm_joints=list(description.joint_keys),
        _convert_="all",
    )
    params = instantiate(cfg.fault_params, seed=cfg.seed, _convert_="all")
    faults = FaultInjector(
        schedule, params, cfg.faults.fault_model, model, tick_s, cfg.seed, ramp_s=cfg.faults.ramp_s
    )
    sim = ArmSimulator(
        model,
        curriculum,
        controller,
        sensors,
        seed=cfg.seed,
        tick_hz=cfg.session.tick_hz,
        chunk_s=cfg.session.chunk_s,
        faults=faults,
        pushes=read_pushes(cfg.session.get("pushes") or [], model),
        torque_sensors=(
            description.torque_sensors if sensors.joint_torque is None else sensors.joint_torque
        ),
    )
    sim.arm = arm  # the drawn factors ({} for the nominal arm), for the manifest
    sim.ratings = description.ratings()
    return sim


@dataclass
class RecordingResult:
    out_dir: Path
    manifest: dict[str, Any]
    wall_s: float


def record_session(cfg: DictConfig, out_dir: Path | str) -> RecordingResult:
    """Record one session into ``out_dir`` (graphs.jsonl + manifest.json)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    sim = build_simulator(cfg)
    n_ticks = _session_ticks(cfg, sim)
    run_id = cfg.session.run_id or default_run_id(cfg)
    manifest: dict[str, Any] = {
        "schema_version": SCHEMA_VERSION,
        "recording_run_id": run_id,
        "status": "running",
        "start_time": datetime.now(UTC).isoformat(timespec="seconds"),
        "code_version": code_version(),
        "files": {"graphs": GRAPHS_FILE},
        "graph": sim.graph.as_dict(),
        "rates": {"physics_hz": 1.0 / sim.dt, "tick_hz": 1.0 / sim.tick_s},
        "expected_samples": n_ticks,
        "faults": sim.faults.describe(),
        "arm": sim.ratings["arm"],  # the arm's name; the factors drawn for it apart
        "arm_variation": sim.arm,
        "arm_ratings": sim.ratings,
        "config": session_config(cfg),
    }
    atomic_write_json(out_dir / MANIFEST_FILE, manifest)
    stats = SessionStats(sim.graph.joints)
    started = time.perf_counter()
    status, reason = "incomplete", "interrupted"
    progress = tqdm(
        total=n_ticks,
        unit="tick",
        desc=f"record {run_id}",
        leave=False,
        disable=not cfg.session.progress,
        dynamic_ncols=True,
    )
    try:
        with (
            _stop_between_chunks() as stop,
            (out_dir / GRAPHS_FILE).open("w", encoding="utf-8") as out,
        ):
            for chunk in sim.run(n_ticks):
                out.write(_chunk_lines(sim, chunk, run_id, stats))
                out.flush()
                progress.update(len(chunk.t))
                stop.check()
        status, reason = "complete", None
    except KeyboardInterrupt:
        reason = "interrupted"
        raise
    except Exception as exc:
        reason = f"error: {type(exc).__name__}: {exc}"
        raise
    finally:
        progress.close()
        wall = time.perf_counter() - started
        warnings = {str(i): int(w.number) for i, w in enumerate(sim.data.warning) if w.number}
        manifest.update(
            {
                "status": status,
                "end_time": datetime.now(UTC).isoformat(timespec="seconds"),
                "wall_s": round(wall, 3),
                "sample_count": stats.samples,
                "stats": stats.as_dict(),
                "mujoco_warnings": warnings,
            }
        )
        if reason:
            manifest["incomplete_reason"] = reason
        atomic_write_json(out_dir / MANIFEST_FILE, manifest)
    return RecordingResult(out_dir, manifest, wall)


def _session_ticks(cfg: DictConfig, sim: ArmSimulator) -> int:
    """Session length in ticks: whole fault-schedule passes if asked, else the duration."""
    passes = cfg.session.get("passes")
    if passes is not None:
        pass_ticks = getattr(sim.faults.schedule, "pass_ticks", None)
        if pass_ticks is None:
            raise InputError("session.passes needs the fault scheduler (faults=schedule)")
        if int(passes) < 1:
            raise InputError(f"session.passes must be >= 1, got {passes}")
        return int(passes) * pass_ticks
    duration = float(cfg.session.duration_s)
    if duration <= 0:
        raise InputError(f"session.duration_s must be > 0, got {duration}")
    return round(duration / sim.tick_s)


def segment_info(sim: ArmSimulator, chunk: TickChunk) -> dict[str, Any]:
    """The curriculum fields every GraphSample of a chunk carries."""
    seg = sim.curriculum.scheduled(chunk.visit).segment
    return {
        "index": seg.index,
        "visit": chunk.visit,
        "family": seg.family,
        "waveform": seg.waveform,
        "speed_scale": seg.speed_scale,
        "payload_scale": seg.payload_scale,
    }


def chunk_features(chunk: TickChunk) -> np.ndarray:
    """Node features ``[n, 2J, F]`` of every tick of a chunk, in the schema's channel order."""
    state = np.stack(
        [chunk.pos, chunk.vel, chunk.effort, chunk.pos_error, chunk.effort_residual], axis=-1
    )
    sensor = np.concatenate(
        [chunk.vib[..., None], chunk.acc, chunk.bands, chunk.kurtosis[..., None]], axis=-1
    )
    return node_features(state, sensor)


def chunk_lines(sim: ArmSimulator, chunk: TickChunk, run_id: str) -> list[str]:
    """One GraphSample JSON line per tick of a just-simulated chunk."""
    segment = segment_info(sim, chunk)
    first = sim.tick - len(chunk.t)
    x = chunk_features(chunk)
    return [
        format_line(run_id, first + k, float(chunk.t[k]), x[k], chunk.fault, segment, sim.graph)
        for k in range(len(chunk.t))
    ]


def _chunk_lines(sim: ArmSimulator, chunk: TickChunk, run_id: str, stats: SessionStats) -> str:
    stats.add(chunk, segment_info(sim, chunk), chunk.fault)
    return "".join(chunk_lines(sim, chunk, run_id))


def summary_text(result: RecordingResult) -> str:
    """A short human-readable account of a recorded session."""
    m = result.manifest
    s = m["stats"]
    sim_s = s["samples"] / m["rates"]["tick_hz"]
    worst = max(s["tracking_rms_rad"].values()) if s["samples"] else float("nan")
    lines = [
        f"session   {m['recording_run_id']}  [{m['status']}]",
        f"directory {result.out_dir}",
        f"samples   {s['samples']} of {m['expected_samples']} ({sim_s:.1f} s simulated at "
        f"{m['rates']['tick_hz']:.0f} Hz, {sim_s / max(result.wall_s, 1e-9):.0f}x real time)",
        f"segments  {s['segments_visited']} visited; samples per family {s['samples_per_family']}",
        f"classes   {s['samples_per_class']}",
        f"faults    {m['faults']['fault_model']} model; {s['scenarios_covered']} joint x fault x "
        f"severity scenarios covered",
        f"tracking  worst joint RMS {worst:.5f} rad; per joint {s['tracking_rms_rad']}",
        f"torque    saturated physics steps {s['torque_saturated_steps']}",
        f"contacts  max {s['max_contacts']}; MuJoCo warnings {m['mujoco_warnings'] or 'none'}",
    ]
    return "\n".join(lines)
