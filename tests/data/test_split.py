"""The run-aware split: a session recorded on several arms is one session (one program, one fault
schedule, scaled to each arm), so no split can see it on another arm; one arm splits as before."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from omegaconf import DictConfig, open_dict

from robohealth_mj.common.config import compose_config
from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.windows import make_windows, run_aware_split, session_of
from robohealth_mj.recording.recorder import default_run_id

W = 8
SEEDS = range(100, 108)


@cache
def _record_config(arm: str) -> DictConfig:
    return compose_config("record", [f"arm={arm}"])


def _run_id(arm: str, seed: int) -> str:
    """The id the recorder gives ``arm``'s session ``seed``."""
    cfg = _record_config(arm).copy()
    cfg.seed = seed
    return default_run_id(cfg)


def _recording(run_ids: list[str], seed: int = 0) -> Recording:
    """``run_ids`` of 40-90 samples each, in order."""
    rng = np.random.default_rng(seed)
    sizes = rng.integers(40, 90, len(run_ids))
    total = int(sizes.sum())
    return Recording(
        x=np.zeros((total, 12, 15), np.float32),
        run=np.repeat(np.arange(len(run_ids), dtype=np.int32), sizes),
        run_ids=run_ids,
        sample_index=np.concatenate([np.arange(n) for n in sizes]).astype(np.int64),
        fault_class=np.zeros(total, np.int64),
        fault_joint=-np.ones(total, np.int64),
        severity=np.zeros(total, np.float32),
        active=np.zeros(total, bool),
        payload_scale=np.ones(total, np.float32),
        sources=["synthetic"],
    )


def _by_run(rec: Recording, windows, seed: int, fractions=(0.7, 0.15, 0.15)) -> np.ndarray:
    """The split by run id alone (the split before sessions were grouped), for one arm: the split
    of each window."""
    run_of = rec.run[windows.end]
    runs, counts = np.unique(run_of, return_counts=True)
    order = np.random.default_rng(seed).permutation(len(runs))
    assigned, split_of = np.zeros(3), {}
    for position, k in enumerate(order):
        target = (
            position
            if position < 3
            else int(np.argmax(np.asarray(fractions) * counts.sum() - assigned))
        )
        split_of[int(runs[k])] = target
        assigned[target] += counts[k]
    return np.array([split_of[int(r)] for r in run_of])


@pytest.fixture(scope="module")
def three_arms() -> Recording:
    ids = {arm: [_run_id(arm, s) for s in SEEDS] for arm in ("ur3e", "ur10e", "ur16e")}
    return _recording([i for arm in ids.values() for i in arm])  # arm after arm, as data.train


def test_the_recorder_names_the_session_whatever_the_arm():
    assert session_of(_run_id("ur3e", 101)) == session_of(_run_id("ur16e", 101)) == "seed 101"
    assert session_of(_run_id("ur3e", 101)) != session_of(_run_id("ur3e", 102))
    assert session_of("ur-20_01_17-p1") == "ur-20_01_17-p1"  # an ingested log: its own session


@pytest.mark.parametrize("seed", [42, 43, 44, 45, 46])
def test_a_session_recorded_on_three_arms_lands_in_one_split(three_arms, seed):
    windows = make_windows(three_arms, W)
    splits = run_aware_split(three_arms, windows, seed)
    owner: dict[str, set[str]] = {}
    for name, part in splits.items():
        assert len(part), name
        for r in np.unique(three_arms.run[part.end]):
            owner.setdefault(session_of(three_arms.run_ids[r]), set()).add(name)
    assert len(owner) == len(SEEDS)
    assert all(len(where) == 1 for where in owner.values()), owner
    assert sum(len(part) for part in splits.values()) == len(windows)


@pytest.mark.parametrize("seed", [42, 43, 44])
def test_one_arm_splits_as_by_run(seed):
    shuffled = (105, 100, 107, 101, 103, 102, 106, 104)  # sessions in no sorted order
    rec = _recording([_run_id("ur5e", s) for s in shuffled], seed=seed)
    windows = make_windows(rec, W)
    splits = run_aware_split(rec, windows, seed)
    which = _by_run(rec, windows, seed)
    for i, name in enumerate(("train", "val", "test")):
        np.testing.assert_array_equal(splits[name].start, windows.start[which == i])


def test_friction_settings_left_unset_keep_the_run_id_of_a_config_without_them():
    cfg = _record_config("ur5e").copy()
    older = cfg.copy()  # a config from before the settings existed
    with open_dict(older.sim):
        del older.sim["friction_solref"], older.sim["friction_solimp"]
    assert default_run_id(cfg) == default_run_id(older)
    cfg.sim.friction_solref = [0.002, 1.0]  # set, it is part of what was simulated
    assert default_run_id(cfg) != default_run_id(older)


def test_no_pushes_keep_the_run_id_of_a_config_without_them():
    cfg = _record_config("ur5e").copy()
    older = cfg.copy()  # a config from before session.pushes existed
    with open_dict(older.session):
        del older.session["pushes"]
    assert default_run_id(cfg) == default_run_id(older)
    cfg.session.pushes = [{"at_s": 1, "for_s": 1, "link": "forearm_link", "force_n": [0, 9, 0]}]
    assert default_run_id(cfg) != default_run_id(older)
