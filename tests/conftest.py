"""Shared fixtures: configs composed the way the entry points compose them, on tiny sizes."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering; must precede importing mujoco

from pathlib import Path

import pytest

from robohealth_mj.config import compose_config
from robohealth_mj.sim.model import build_model


@pytest.fixture(scope="session")
def model():
    return build_model()


@pytest.fixture
def record_cfg():
    """``conf/record.yaml`` composed with overrides; progress bars off."""

    def make(*overrides: str):
        return compose_config("record", ["session.progress=false", *overrides])

    return make


FAST = [  # a session of every fault class at one severity on two joints: seconds to record
    "session.progress=false",
    "faults.schedule.fault_s=1.0",
    "faults.schedule.healthy_s=1.0",
    "faults.schedule.severities=[0.9]",
    "faults.schedule.joints=[elbow,wrist_1]",
    "session.passes=1",
]


@pytest.fixture(scope="session")
def fast_session() -> list[str]:
    """Record overrides for a short session that still covers every fault class."""
    return list(FAST)


@pytest.fixture(scope="session")
def deployed(tmp_path_factory) -> dict[str, Path]:
    """A tiny trained model (structural and harness) exported to ONNX, and its held-out data."""
    from robohealth_mj.recorder import GRAPHS_FILE, record_session
    from robohealth_mj.runtime.export import export_checkpoint
    from robohealth_mj.train import run

    root = tmp_path_factory.mktemp("deploy")
    for name, seed in (("train_a", 1), ("train_b", 2), ("train_c", 3), ("heldout", 4)):
        record_session(compose_config("record", [*FAST, f"seed={seed}"]), root / name)
    paths = {"root": root, "heldout": root / "heldout" / GRAPHS_FILE}
    for graph in ("structural", "harness"):
        cfg = compose_config(
            "train",
            [
                f"data.train=[{root}/train_*]",
                f"data.evaluate.heldout={root}/heldout",
                "data.evaluate.probe=null",
                "trainer.epochs=1",
                "trainer.progress=false",
                "model.hidden=8",
                "window=8",
                "variant=anomaly_residual",
                f"graph={graph}",
            ],
        )
        run(cfg, root / graph)
        paths[f"{graph}_ckpt"] = root / graph / "best.ckpt"
        result = export_checkpoint(root / graph / "best.ckpt", root / graph / "model.onnx")
        paths[f"{graph}_onnx"] = Path(result["path"])
    return paths
