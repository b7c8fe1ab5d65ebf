"""Shared fixtures: configs composed the way the entry points compose them, on tiny sizes.

``ROBOHEALTH_TEST_CACHE=DIR`` keeps the recorded and trained fixtures in ``DIR`` between pytest
sessions (the mutation tester starts one session per mutant; see the README). Without it, every
session builds them afresh in its own temporary directory.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering; must precede importing mujoco
if os.environ.get("PYTEST_XDIST_WORKER"):
    # Spread over workers (`make test`: one per core), each keeps to one thread: torch's and
    # OpenMP's pools (LightGBM's too) sized to every core would oversubscribe them. Inherited by
    # the subprocesses the tests start; set before anything imports torch.
    for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ.setdefault(_var, "1")

import json
from collections.abc import Callable
from pathlib import Path

import pytest

from robohealth_mj.common.config import compose_config
from robohealth_mj.runtime.alarms import AlarmPolicy
from robohealth_mj.sim.model import build_model

# Tests that read a model trained for the session are ``slow`` (so are those that train in their
# own body, marked where they are): ``pytest -m "not slow"`` is the quick loop while developing.
TRAINED_FIXTURES = frozenset({"deployed", "stock_deployed", "joint_states_deployed"})


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if TRAINED_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.slow)


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

LEARNABLE = [  # three faults that show with the joint at rest, on three joints, 3 s each
    "session.progress=false",
    "faults.schedule.fault_s=3.0",
    "faults.schedule.healthy_s=1.5",
    "faults.schedule.severities=[0.9]",
    "faults.schedule.classes=[jam,backlash,sensor_drift]",
    "faults.schedule.joints=[shoulder_lift,elbow,wrist_2]",
    "session.passes=2",
]
LEARNABLE_SESSIONS = {**{f"train_{s}": s for s in range(1, 5)}, "heldout": 99}

# The alarm policy the runtime tests use with the deployed model: its fault decisions reach this
# confidence for a few ticks running in most episodes of the held-out session.
DECIDING_ALARM = AlarmPolicy(raise_after=3, clear_after=4, min_confidence=0.8)


@pytest.fixture(scope="session")
def fast_session() -> list[str]:
    """Record overrides for a short session that still covers every fault class."""
    return list(FAST)


@pytest.fixture(scope="session")
def deciding_alarm() -> AlarmPolicy:
    return DECIDING_ALARM


@pytest.fixture(scope="session")
def deciding_alarm_args() -> list[str]:
    """:data:`DECIDING_ALARM` as the monitor's ``alarm.*=`` overrides."""
    return [f"alarm.{k}={getattr(DECIDING_ALARM, k)}"
            for k in ("raise_after", "clear_after", "min_confidence")]  # fmt: skip


def _shared_root(tmp_path_factory) -> Path | None:
    """Where fixtures are built once for every process of this run: ``ROBOHEALTH_TEST_CACHE``
    (kept between runs), or, with ``pytest -n`` (xdist), the temporary directory its workers
    share; ``None`` in a plain single-process session."""
    if cache := os.environ.get("ROBOHEALTH_TEST_CACHE"):
        return Path(cache)
    if os.environ.get("PYTEST_XDIST_WORKER"):
        return tmp_path_factory.getbasetemp().parent / "shared"
    return None


def cached(tmp_path_factory, name: str, build: Callable[[Path], dict]) -> dict:
    """``build(root)`` once per run: in a single process, once per session; with xdist workers
    or a ``ROBOHEALTH_TEST_CACHE`` directory, once under a file lock (the first worker to need it
    builds, the others wait and read), its JSON-able result kept beside what it wrote."""
    shared = _shared_root(tmp_path_factory)
    if shared is None:
        return build(tmp_path_factory.mktemp(name))
    from filelock import FileLock

    root = shared / name
    done = root / "fixture.json"
    root.mkdir(parents=True, exist_ok=True)
    with FileLock(str(shared / f"{name}.lock")):
        if done.is_file():
            return json.loads(done.read_text())
        result = build(root)
        done.write_text(json.dumps(result))
    return result


def _recorder(overrides: list[str], sessions: dict[str, int]) -> Callable[[Path], dict]:
    def record(root: Path) -> dict:
        from robohealth_mj.recording.recorder import record_session

        for name, seed in sessions.items():
            record_session(compose_config("record", [*overrides, f"seed={seed}"]), root / name)
        return {"root": str(root)}

    return record


@pytest.fixture(scope="session")
def tiny_corpus(tmp_path_factory) -> Path:
    """Three short training sessions and a held-out one, each covering every fault class."""
    sessions = {"train_a": 1, "train_b": 2, "train_c": 3, "heldout": 4}
    return Path(cached(tmp_path_factory, "tiny", _recorder(FAST, sessions))["root"])


@pytest.fixture(scope="session")
def learnable_corpus(tmp_path_factory) -> Path:
    """Four short training sessions and a held-out one (seed 99): jam, backlash and sensor drift
    at severity 0.9 on three joints, which a few epochs learn to tell apart."""
    recorder = _recorder(LEARNABLE, LEARNABLE_SESSIONS)
    return Path(cached(tmp_path_factory, "learnable", recorder)["root"])


@pytest.fixture(scope="session")
def tiny_train_config() -> Callable:
    """``(corpus, *overrides)`` -> the training config of the tests' small models."""
    return _tiny_train_config


def _tiny_train_config(corpus: Path, *overrides: str):
    """The training config of the tests' small models: W = 8 on ``corpus``'s sessions."""
    return compose_config(
        "train",
        [
            f"data.train=[{corpus}/train_*]",
            f"data.evaluate.heldout={corpus}/heldout",
            "data.evaluate.probe=null",
            "trainer.progress=false",
            "window=8",
            *overrides,
        ],
    )


def _train_and_export(corpus: Path, root: Path) -> dict:
    from robohealth_mj.deploy.export import export_checkpoint
    from robohealth_mj.learn.run import train_and_evaluate as run

    paths = {"root": str(corpus), "heldout": str(corpus / "heldout" / "graphs.jsonl")}
    models = {  # structural: a model that decides; harness: the headline variant, barely trained,
        # its window encoder pooling no record of the oldest snapshot (the two incremental forms)
        "structural": ["variant=stgnn_fixed", "model.hidden=32", "trainer.epochs=8"],
        "harness": ["variant=anomaly_residual", "model.hidden=8", "trainer.epochs=1",
                    "model.backbone.first_record=false"],
    }  # fmt: skip
    for graph, overrides in models.items():
        cfg = _tiny_train_config(corpus, f"graph={graph}", *overrides)
        run(cfg, root / graph)
        paths[f"{graph}_ckpt"] = str(root / graph / "best.ckpt")
        result = export_checkpoint(root / graph / "best.ckpt", root / graph / "model.onnx")
        paths[f"{graph}_onnx"] = result["path"]
    return paths


@pytest.fixture(scope="session")
def deployed(tmp_path_factory, learnable_corpus) -> dict[str, Path]:
    """Two trained models exported to ONNX, and their held-out data (``learnable_corpus``).

    ``structural`` (``stgnn_fixed``, 8 epochs) decides: on the held-out session it calls faults
    with the right class and joint and, under :data:`DECIDING_ALARM`, raises and clears alarms, so
    the runtime, monitor, alarm and bag tests run the fault path. ``harness``
    (``anomaly_residual`` on the unknown-placement graph, 1 epoch) covers the coupling model."""
    paths = cached(
        tmp_path_factory, "deploy", lambda root: _train_and_export(learnable_corpus, root)
    )
    return {key: Path(value) for key, value in paths.items()}


def _train_stock(corpus: Path, root: Path, sensing: str = "stock") -> dict:
    from robohealth_mj.deploy.export import export_checkpoint
    from robohealth_mj.learn.run import train_and_evaluate as run

    cfg = _tiny_train_config(
        corpus, "trainer.epochs=1", f"sensing={sensing}", "variant=stgnn_fixed", "model.hidden=8"
    )
    run(cfg, root / "run")
    onnx = export_checkpoint(root / "run" / "best.ckpt", root / "model.onnx")["path"]
    return {"ckpt": str(root / "run" / "best.ckpt"), "onnx": onnx,
            "heldout": str(corpus / "heldout" / "graphs.jsonl")}  # fmt: skip


@pytest.fixture(scope="session")
def stock_deployed(tmp_path_factory, tiny_corpus) -> dict[str, Path]:
    """A ``stgnn_fixed`` trained (1 epoch) with ``sensing=stock`` and exported, and its
    held-out data (``tiny_corpus``, which has every fault class)."""
    paths = cached(tmp_path_factory, "stock", lambda root: _train_stock(tiny_corpus, root))
    return {key: Path(value) for key, value in paths.items()}


@pytest.fixture(scope="session")
def joint_states_deployed(tmp_path_factory, tiny_corpus) -> dict[str, Path]:
    """As ``stock_deployed``, with the reduced ``sensing=joint_states`` profile: what any ROS 2
    arm driver's ``/joint_states`` carries (the live UR driver tests' model)."""
    paths = cached(tmp_path_factory, "joint_states",
                   lambda root: _train_stock(tiny_corpus, root, "joint_states"))  # fmt: skip
    return {key: Path(value) for key, value in paths.items()}
