"""Corpus planning and recording: every dataset role of a corpus config as session specs, each
recorded once (resumable: a complete session with the same config is kept)."""

from __future__ import annotations

import json
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.version import code_version
from robohealth_mj.recording.recorder import (
    GRAPHS_FILE,
    MANIFEST_FILE,
    default_run_id,
    record_session,
)
from robohealth_mj.schema import SCHEMA_VERSION

CORPUS_INDEX = "corpus.json"


@dataclass(frozen=True)
class SessionSpec:
    role: str
    name: str
    overrides: tuple[str, ...]


def _grid_overrides(grid: dict[str, Any]) -> list[str]:
    return [f"curriculum.{k}=[{','.join(str(v) for v in vals)}]" for k, vals in grid.items()]


def plan(corpus: DictConfig, extra: list[str]) -> list[SessionSpec]:
    """The sessions of a corpus: role, directory name and record overrides."""
    c = OmegaConf.to_container(corpus, resolve=True)
    train = c["train"]
    specs = []
    for i in range(int(train["sessions"])):
        grid = train["grids"][i % len(train["grids"])]
        length = train["lengths"][i % len(train["lengths"])]
        seed = int(c["seed"]) + i
        specs.append(
            SessionSpec(
                "train",
                f"train_{i:02d}_seed{seed}",
                (
                    f"seed={seed}",
                    *_grid_overrides(grid),
                    *_length(length),
                    *train.get("overrides", []),
                    *extra,
                ),
            )
        )
    for role, r in c.items():
        if role in ("name", "seed", "train", "builder"):
            continue
        for seed in r["seeds"] if "seeds" in r else [r["seed"]]:
            specs.append(
                SessionSpec(
                    role,
                    f"{role}_seed{seed}",
                    (
                        f"seed={seed}",
                        *_grid_overrides(r["grid"]),
                        *_length(r["length"]),
                        *r.get("overrides", []),
                        *extra,
                    ),
                )
            )
    return specs


def _length(length: dict[str, Any]) -> list[str]:
    if "passes" in length:
        return [f"session.passes={length['passes']}"]
    return [f"session.duration_s={length['duration_s']}"]


def _session_config(spec: SessionSpec) -> DictConfig:
    return compose_config("record", ["session.progress=false", *spec.overrides])


def _record_one(spec: SessionSpec, out_dir: str) -> dict[str, Any]:
    result = record_session(_session_config(spec), out_dir)
    return {"status": result.manifest["status"], "samples": result.manifest["sample_count"]}


def _is_complete(session_dir: Path, spec: SessionSpec) -> bool:
    """A finished recording of exactly this session (schema version and run id agree)."""
    try:
        manifest = json.loads((session_dir / MANIFEST_FILE).read_text())
    except (OSError, json.JSONDecodeError):
        return False
    return (
        manifest.get("status") == "complete"
        and manifest.get("schema_version") == SCHEMA_VERSION
        and manifest.get("recording_run_id") == default_run_id(_session_config(spec))
        and (session_dir / GRAPHS_FILE).is_file()
    )


def build_corpus(
    corpus: DictConfig, out_dir: Path, jobs: int, extra: list[str], progress: bool = True
) -> dict[str, Any]:
    out_dir.mkdir(parents=True, exist_ok=True)
    specs = plan(corpus, extra)
    todo = [s for s in specs if not _is_complete(out_dir / s.name, s)]
    bar = tqdm(
        total=len(specs),
        initial=len(specs) - len(todo),
        unit="session",
        desc=f"corpus {corpus.name}",
        disable=not progress,
    )
    with ProcessPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = {pool.submit(_record_one, s, str(out_dir / s.name)): s for s in todo}
        for future in as_completed(futures):
            future.result()  # a failed session fails the corpus, loudly
            bar.update(1)
    bar.close()
    index = {
        "name": corpus.name,
        "code_version": code_version(),
        "config": OmegaConf.to_container(corpus, resolve=True),
        "extra_overrides": extra,
        "roles": {},
    }
    for s in specs:
        manifest = json.loads((out_dir / s.name / MANIFEST_FILE).read_text())
        index["roles"].setdefault(s.role, []).append(
            {
                "dir": s.name,
                "graphs": f"{s.name}/{GRAPHS_FILE}",
                "recording_run_id": manifest["recording_run_id"],
                "samples": manifest["sample_count"],
                "overrides": list(s.overrides),
            }
        )
    atomic_write_json(out_dir / CORPUS_INDEX, index)
    return index
