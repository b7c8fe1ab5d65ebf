"""Lives: an arm's operating days, from healthy until a joint's wear crosses its failure threshold.

A life is one session per simulated operating day (a few minutes of the arm's normal program, the
day's speed and payload drawn from the life's seed). One joint wears in one mechanical mode along a
path (:mod:`robohealth_mj.faults.wear`) driven by the usage it accumulates day by day; each day is
recorded at the severity its wear has reached that morning. ``life.json`` carries the truth: each
day's severity of every joint, its usage, and the day the threshold is crossed (the failure day,
which is not recorded: the arm is down). A healthy life (no mode) runs its days with no wear.

``python -m robohealth_mj.corpus corpus=lives`` records every life of every role; lives run in
parallel, a life's days in order (each day's severity depends on the days before). A finished day
is kept, so an interrupted corpus resumes where it stopped.
"""

from __future__ import annotations

import hashlib
import json
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from robohealth_mj.arms.description import load_arm
from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.common.version import code_version
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.data.relative import to_raw
from robohealth_mj.faults.catalogue import MECHANICAL
from robohealth_mj.faults.wear import PATH_KINDS, draw_path, joint_usage, path_record
from robohealth_mj.recording.corpus import CORPUS_INDEX, SessionSpec, _is_complete, _session_config
from robohealth_mj.recording.recorder import GRAPHS_FILE, MANIFEST_FILE, record_session
from robohealth_mj.schema import JOINT_NAMES, feature_index

LIFE_FILE = "life.json"


@dataclass(frozen=True)
class LifeSpec:
    """One life to record: who wears, how, and how fast."""

    role: str
    name: str
    seed: int
    mode: str | None  # the wearing mode; None: a healthy life
    joint: str | None
    path: str | None
    design_days: float  # days to the threshold at the first day's duty
    max_days: int


def plan_lives(corpus: DictConfig) -> list[LifeSpec]:
    """Every life of every role: mode and path cycled, joint and design days drawn per life."""
    c = OmegaConf.to_container(corpus, resolve=True)
    specs = []
    for role, r in c["roles"].items():
        modes = r.get("modes") or [None]
        unknown = [m for m in modes if m is not None and m not in MECHANICAL]
        if unknown:
            raise InputError(
                f"corpus.roles.{role}.modes: {unknown} wear no mechanism; {MECHANICAL}"
            )
        paths = r.get("paths") or list(PATH_KINDS)
        joints = r.get("joints") or list(JOINT_NAMES)
        rng = stream("lives.draw", r["seed"])
        for i in range(int(r["lives"])):
            seed = int(r["seed"]) + i
            mode = modes[i % len(modes)]
            path = paths[(i // len(modes)) % len(paths)] if mode else None
            joint = str(rng.choice(joints)) if mode else None
            days = float(rng.uniform(*r["design_days"])) if mode else float(r["max_days"])
            specs.append(
                LifeSpec(
                    role,
                    f"{role}_{i:02d}_seed{seed}",
                    seed,
                    mode,
                    joint,
                    path,
                    days,
                    int(r["max_days"]),
                )
            )
    return specs


def _day_spec(
    spec: LifeSpec, corpus: DictConfig, day: int, severity: float, duty: dict, extra: list[str]
) -> SessionSpec:
    program = OmegaConf.to_container(corpus.program, resolve=True)
    fault = (
        [
            "faults=fixed",
            f"faults.schedule.fault_class={spec.mode}",
            f"faults.schedule.joint={spec.joint}",
            f"faults.schedule.severity={severity:.6f}",
        ]
        if severity > 0
        else ["faults=none"]
    )
    overrides = (
        f"seed={spec.seed * 1000 + day}",
        f"session.duration_s={corpus.session_s}",
        f"curriculum.families=[{','.join(program['families'])}]",
        f"curriculum.speed_scales=[{duty['speed_scale']}]",
        f"curriculum.payload_scales=[{duty['payload_scale']}]",
        *fault,
        *extra,
    )
    return SessionSpec(spec.role, f"day_{day:03d}", overrides)


def session_usage(session_dir: Path, rated_torque: np.ndarray) -> np.ndarray:
    """Usage per joint ``[J]`` of one recorded day (load-weighted revolutions). Read through the
    recordings' cache, which training on the lives then finds already built."""
    rec = load_recordings([session_dir / GRAPHS_FILE])
    x = to_raw(rec.x, rec.arms[0])[:, : len(JOINT_NAMES)]  # the arm's own readings
    manifest = json.loads((session_dir / MANIFEST_FILE).read_text())
    tick_s = 1.0 / float(manifest["rates"]["tick_hz"])
    return joint_usage(x[..., feature_index("vel")], x[..., feature_index("effort")], rated_torque,
                       tick_s)  # fmt: skip


def _life_id(spec: LifeSpec, corpus: DictConfig, extra: list[str]) -> str:
    data = {
        "spec": asdict(spec),
        "corpus": OmegaConf.to_container(corpus, resolve=True),
        "extra": extra,
    }
    data["corpus"].pop("roles", None)  # other roles' sizes do not change this life
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:12]


def record_life(spec: LifeSpec, corpus: DictConfig, out_dir: Path, extra: list[str]) -> dict:
    """Record one life's days into ``out_dir`` (``day_NNN/`` sessions + ``life.json``)."""
    life_id = _life_id(spec, corpus, extra)
    life_file = out_dir / LIFE_FILE
    try:
        done = json.loads(life_file.read_text())
        if done.get("status") == "complete" and done.get("life_id") == life_id:
            return done
    except (OSError, ValueError):
        pass
    threshold = float(corpus.threshold)
    rng = stream("lives.path", spec.seed)
    path = draw_path(spec.path, threshold, rng) if spec.mode else None
    arm = str(OmegaConf.select(corpus, "arm", default=None) or "ur5e")
    rated = load_arm(arm).rated_torque
    j = JOINT_NAMES.index(spec.joint) if spec.joint else None
    grid = OmegaConf.to_container(corpus.duty, resolve=True)
    cumulative = np.zeros(len(JOINT_NAMES))
    design_usage: float | None = None
    days: list[dict[str, Any]] = []
    failure_day = None
    life = {
        "life_id": life_id,
        "role": spec.role,
        "name": spec.name,
        "spec": asdict(spec),
        "threshold": threshold,
        "path": path_record(path) if path else None,
        "code_version": code_version(),
    }
    for day in range(spec.max_days):
        nu = cumulative[j] / design_usage if design_usage else 0.0
        severity = path.severity(nu) if path else 0.0
        if severity >= threshold:
            failure_day = day
            break
        duty = {k: float(rng.choice(v)) for k, v in grid.items()}
        day_spec = _day_spec(spec, corpus, day, severity, duty, extra)
        session_dir = out_dir / day_spec.name
        if not _is_complete(session_dir, day_spec):
            record_session(_session_config(day_spec), session_dir)
        usage = session_usage(session_dir, rated)
        if path and design_usage is None:
            design_usage = float(usage[j]) * spec.design_days
        cumulative += usage
        truth = np.zeros(len(JOINT_NAMES))
        if j is not None:
            truth[j] = severity
        days.append(
            {
                "day": day,
                "dir": day_spec.name,
                "seed": spec.seed * 1000 + day,
                **duty,
                "normalised_usage": round(float(nu), 6),
                "severity": dict(zip(JOINT_NAMES, truth.round(6).tolist(), strict=True)),
                "usage": dict(zip(JOINT_NAMES, usage.round(9).tolist(), strict=True)),
            }
        )
        atomic_write_json(life_file, {**life, "status": "running", "days": days})
    life.update(
        status="complete",
        days=days,
        failure_day=failure_day,
        censored=failure_day is None and path is not None,
        design_usage=design_usage,
    )
    atomic_write_json(life_file, life)
    return life


def _record_life(spec: LifeSpec, corpus: DictConfig, out_dir: str, extra: list[str]) -> dict:
    return record_life(spec, corpus, Path(out_dir), extra)


def build_lives(
    corpus: DictConfig, out_dir: Path, jobs: int, extra: list[str], progress: bool = True
) -> dict[str, Any]:
    """Record every life of ``corpus`` (lives in parallel) and write the corpus index."""
    out_dir.mkdir(parents=True, exist_ok=True)
    specs = plan_lives(corpus)
    bar = tqdm(total=len(specs), unit="life", desc=f"corpus {corpus.name}", disable=not progress)
    lives: dict[str, dict] = {}
    with ProcessPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = {
            pool.submit(_record_life, s, corpus, str(out_dir / s.name), extra): s for s in specs
        }
        for future in as_completed(futures):
            lives[futures[future].name] = future.result()  # a failed life fails the corpus
            bar.update(1)
    bar.close()
    index: dict[str, Any] = {
        "name": corpus.name,
        "kind": "lives",
        "code_version": code_version(),
        "config": OmegaConf.to_container(corpus, resolve=True),
        "extra_overrides": extra,
        "roles": {},
    }
    for s in specs:
        life = lives[s.name]
        index["roles"].setdefault(s.role, []).append(
            {
                "dir": s.name,
                "life": f"{s.name}/{LIFE_FILE}",
                "mode": s.mode,
                "joint": s.joint,
                "path": s.path,
                "days": len(life["days"]),
                "failure_day": life["failure_day"],
                "sessions": [f"{s.name}/{d['dir']}" for d in life["days"]],
                "samples": sum(
                    json.loads((out_dir / s.name / d["dir"] / MANIFEST_FILE).read_text())[
                        "sample_count"
                    ]
                    for d in life["days"]
                ),
            }
        )
    atomic_write_json(out_dir / CORPUS_INDEX, index)
    return index
