"""``python -m robohealth_mj.corpus``: record the thesis's dataset roles in one command (§2.6.1).

- ``train``: sessions varied in seed, speed/payload grid and length (merged for training);
- ``heldout``: one session with its own seed (the cited test numbers);
- ``probe_payload_high``: the same fault mix at a payload outside the training range;
- any further role the corpus config names (``seed`` or ``seeds``, grid, length, overrides),
  e.g. ``probe_unseen_arms``: sessions each on its own drawn arm (``arm=varied``), and
  ``healthy_unseen_arms``: ten healthy minutes of each of those arms, to commission on.

Sessions run in parallel (one process per core by default). A finished session (manifest
``complete``) is skipped, so an interrupted corpus resumes where it stopped.

    python -m robohealth_mj.corpus                      # standard corpus
    python -m robohealth_mj.corpus corpus=quick         # small corpus for the main job and tests
    python -m robohealth_mj.corpus corpus=quick fault_model=hybrid   # + the thesis's signatures
    python -m robohealth_mj.corpus 'record_overrides=["faults.ramp_s=1.0"]'   # any record override

A list element that holds ``=`` must be quoted for Hydra's grammar, as above. A session on disk is
reused only when its manifest is complete, of this schema version and of the same run id (the
same config), so changing the fault model or any override re-records it.
"""

from __future__ import annotations

import json
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import hydra
from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.config import compose_config
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.common.resources import HYDRA_CONF
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
        if role in ("name", "seed", "train"):
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


@hydra.main(config_path=HYDRA_CONF, config_name="corpus", version_base="1.3")
def main(cfg: DictConfig) -> None:
    out_dir = Path(cfg.out_dir)
    jobs = cfg.jobs or os.cpu_count() or 1
    extra = [f"faults.fault_model={cfg.fault_model}", *cfg.record_overrides]
    with one_line_errors("corpus"):
        index = build_corpus(cfg.corpus, out_dir, jobs, extra, cfg.progress)
    for role, sessions in index["roles"].items():
        total = sum(s["samples"] for s in sessions)
        print(f"{role:<20} {len(sessions):>3} session(s) {total:>9} samples")
    print(f"corpus index: {out_dir / CORPUS_INDEX}")


if __name__ == "__main__":
    main()
