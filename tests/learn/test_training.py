"""Training and evaluation: leakage-free splits, normalisation, labels, the harness, and a tiny
end-to-end train -> evaluate run on data the test records itself."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from robohealth_mj import schema
from robohealth_mj.common.config import compose_config
from robohealth_mj.data.arrays import Recording, load_recordings
from robohealth_mj.data.graphs import DEFAULT_C0, coupling_correlation, harness_graph
from robohealth_mj.data.windows import (
    make_windows,
    normalisation,
    run_aware_split,
    target_joint_moved,
)
from robohealth_mj.learn.checkpoint import (
    checkpoint_digest,
    load_checkpoint,
    model_from_checkpoint,
)
from robohealth_mj.learn.evaluation import evaluate_checkpoint
from robohealth_mj.learn.run import train_and_evaluate as run
from robohealth_mj.recording.recorder import GRAPHS_FILE

pytestmark = pytest.mark.slow  # every test here trains a model

F = schema.N_FEATURES


def _recording(runs: list[int], seed: int = 0) -> Recording:
    """Synthetic arrays: ``runs[k]`` samples for run k; labels change every 10 samples."""
    rng = np.random.default_rng(seed)
    total = sum(runs)
    run = np.concatenate([np.full(n, k, np.int32) for k, n in enumerate(runs)])
    index = np.concatenate([np.arange(n) for n in runs]).astype(np.int64)
    cls = (np.arange(total) // 10) % 7
    return Recording(
        x=rng.normal(size=(total, 12, F)).astype(np.float32),
        run=run,
        run_ids=[f"run{k}" for k in range(len(runs))],
        sample_index=index,
        fault_class=cls,
        fault_joint=np.where(cls > 0, cls % 6, -1),
        severity=np.where(cls > 0, 0.6, 0.0).astype(np.float32),
        active=cls > 0,
        payload_scale=np.ones(total, np.float32),
        sources=["synthetic"],
    )


def test_motion_strata_flag_windows_whose_faulted_joint_turned():
    """Friction acts only on a moving joint: the evaluation splits faulted windows by motion."""
    rec = _recording([80])
    vel = schema.feature_index("vel")
    rec.x[..., vel] = 0.0
    rec.x[12, 2, vel] = 0.5  # joint 2 turns once, inside the class-2 block (samples 10-19)
    windows = make_windows(rec, 4, stride=1)
    moved = target_joint_moved(rec, windows)
    label_joint = rec.fault_joint[windows.end]
    assert moved[(windows.start <= 12) & (windows.end >= 12) & (label_joint == 2)].all()
    assert moved.sum() == ((windows.start <= 12) & (windows.end >= 12) & (label_joint == 2)).sum()
    assert not moved[label_joint < 0].any()  # healthy windows are never "moving faults"


def test_split_keeps_every_session_in_one_split_and_is_seeded():
    rec = _recording([200, 150, 300, 120, 180, 220, 90, 260])
    windows = make_windows(rec, 16)
    splits = run_aware_split(rec, windows, seed=42)
    owners = {name: {int(r) for r in rec.run[w.end]} for name, w in splits.items()}
    assert all(owners.values())
    assert not (owners["train"] & owners["val"]) and not (owners["train"] & owners["test"])
    assert not (owners["val"] & owners["test"])
    assert sum(len(w) for w in splits.values()) == len(windows)
    again = run_aware_split(rec, windows, seed=42)
    assert all(np.array_equal(again[k].start, splits[k].start) for k in splits)
    share = len(splits["train"]) / len(windows)
    assert 0.5 < share < 0.85


def test_split_refuses_fewer_than_three_sessions():
    rec = _recording([200, 200])
    with pytest.raises(ValueError, match="at least 3 recording sessions"):
        run_aware_split(rec, make_windows(rec, 16), seed=0)


def test_windows_stay_inside_a_run_and_take_the_final_snapshot_label():
    rec = _recording([50, 50, 50])
    rec.sample_index[70] += 5  # a gap inside run 1: no window may span it
    windows = make_windows(rec, 16, stride=4)
    idx = windows.start[:, None] + np.arange(16)
    assert np.all(rec.run[idx] == rec.run[idx[:, :1]])
    assert np.all(np.diff(rec.sample_index[idx], axis=1) == 1)
    from robohealth_mj.learn.data import WindowTensors

    tensors = WindowTensors(
        rec.x, rec, np.zeros((12, F), np.float32), np.ones((12, F), np.float32), torch.device("cpu")
    )
    batch = tensors.batch(windows, np.arange(len(windows)))
    np.testing.assert_array_equal(batch.fault_class.numpy(), rec.fault_class[windows.end])
    np.testing.assert_array_equal(batch.fault_joint.numpy(), rec.fault_joint[windows.end])


def test_normalisation_uses_the_training_windows_only():
    rec = _recording([100, 100, 100, 100])
    windows = make_windows(rec, 8)
    splits = run_aware_split(rec, windows, seed=1)
    test_runs = {int(r) for r in rec.run[splits["test"].end]}
    poisoned = rec.x.copy()
    poisoned[np.isin(rec.run, list(test_runs))] += 1000.0
    mean, _ = normalisation(poisoned, splits["train"])
    clean_mean, _ = normalisation(rec.x, splits["train"])
    np.testing.assert_allclose(mean, clean_mean, atol=1e-5)
    assert np.abs(mean).max() < 10


def test_harness_mixes_the_sensor_packages_through_c0():
    x = np.random.default_rng(0).normal(size=(5, 12, F)).astype(np.float32)
    graph = harness_graph()
    h = graph.transform(x)
    assert h.shape == (5, 10, F)
    np.testing.assert_array_equal(h[:, :6], x[:, :6])
    expected = np.einsum("jm,tjc->tmc", DEFAULT_C0, x[:, 6:, schema.SENSOR_CHANNELS])
    np.testing.assert_allclose(h[:, 6:, schema.SENSOR_CHANNELS], expected, rtol=1e-5, atol=1e-6)
    # no joint state on harness sensors
    np.testing.assert_array_equal(h[:, 6:, schema.STATE_CHANNELS], 0.0)
    np.testing.assert_array_equal(h[:, 6:, 1], 1.0)
    assert graph.adjacency[:6, 6:].all() and not graph.adjacency[6:, 6:].any()
    assert coupling_correlation(DEFAULT_C0 * 3.0, DEFAULT_C0) == pytest.approx(1.0)
    assert coupling_correlation(np.ones((6, 4)), DEFAULT_C0) == 0.0


def _train_cfg(corpus: Path, *extra: str, network: bool = True):
    return compose_config(
        "train",
        [
            f"data.train=[{corpus}/train_*]",
            f"data.evaluate.heldout={corpus}/heldout",
            "data.evaluate.probe=null",
            "trainer.epochs=2",
            "trainer.progress=false",
            *(["model.hidden=8"] if network else []),
            "window=8",
            *extra,
        ],
    )


def test_tiny_train_then_evaluate_end_to_end(tiny_corpus, tmp_path):
    cfg = _train_cfg(tiny_corpus, "variant=anomaly_residual")
    results = run(cfg, tmp_path)
    summary = results["train"]
    assert 1 <= summary["best_epoch"] <= 2
    assert sum(len(v) for v in summary["split_runs"].values()) == 3
    ckpt = load_checkpoint(tmp_path / "best.ckpt")  # weights_only=True
    assert ckpt["schema"]["node_names"] == list(schema.NODE_NAMES)
    assert ckpt["norm_mean"].shape == (12, F) and ckpt["variant"] == "anomaly_residual"
    assert ckpt["data_fingerprint"] == summary["data_fingerprint"]
    heldout = json.loads((tmp_path / "eval_heldout.json").read_text())
    m = heldout["metrics"]
    for key in (
        "accuracy",
        "fault_present_accuracy",
        "macro_f1",
        "localisation_accuracy",
        "confusion_matrix",
        "per_class",
        "by_severity",
    ):
        assert key in m
    assert set(m["by_severity"]) == {"0.9"}
    assert (tmp_path / "eval_heldout.csv").read_text().startswith("metric,value")
    assert list((tmp_path / "tensorboard").glob("events.*"))
    # evaluating again reproduces the same numbers from the checkpoint alone
    again = evaluate_checkpoint(tmp_path / "best.ckpt", str(tiny_corpus / "heldout"))
    assert again["metrics"]["accuracy"] == m["accuracy"]


def test_same_seed_same_model(tiny_corpus, tmp_path):
    # bytes repeat per thread count (docs/training.md), so the rerun names the count
    cfg = _train_cfg(tiny_corpus, "variant=stgnn_fixed", "trainer.epochs=1", "threads=1")
    run(cfg, tmp_path / "a")
    run(cfg, tmp_path / "b")
    a, b = (load_checkpoint(tmp_path / d / "best.ckpt")["state_dict"] for d in "ab")
    assert all(torch.equal(a[k], b[k]) for k in a)


def test_evaluation_refuses_a_checkpoint_with_another_topology(tiny_corpus, tmp_path):
    run(_train_cfg(tiny_corpus, "variant=mlp", "trainer.epochs=1"), tmp_path)
    ckpt = torch.load(tmp_path / "best.ckpt", weights_only=True)
    ckpt["schema"]["node_names"] = ckpt["schema"]["node_names"][::-1]
    ckpt["sha256"] = checkpoint_digest(ckpt)  # a sound file, written for another graph
    torch.save(ckpt, tmp_path / "other.ckpt")
    with pytest.raises(ValueError, match="node order"):
        evaluate_checkpoint(tmp_path / "other.ckpt", str(tiny_corpus / "heldout"))
    ckpt["schema"]["node_names"] = list(schema.NODE_NAMES)
    ckpt["schema"]["edges"] = ckpt["schema"]["edges"][2:]
    ckpt["sha256"] = checkpoint_digest(ckpt)
    torch.save(ckpt, tmp_path / "other.ckpt")
    with pytest.raises(ValueError, match="altered"):
        ckpt["window"] += 1  # the same file edited afterwards
        torch.save(ckpt, tmp_path / "edited.ckpt")
        evaluate_checkpoint(tmp_path / "edited.ckpt", str(tiny_corpus / "heldout"))
    with pytest.raises(ValueError, match="topology"):
        evaluate_checkpoint(tmp_path / "other.ckpt", str(tiny_corpus / "heldout"))


def test_a_relaunched_campaign_skips_finished_runs(tiny_corpus, tmp_path):
    cfg = _train_cfg(tiny_corpus, "variant=mlp", "trainer.epochs=1")
    run(cfg, tmp_path)
    stamp = (tmp_path / "best.ckpt").stat().st_mtime_ns
    assert run(cfg, tmp_path) == {"skipped": True}
    assert (tmp_path / "best.ckpt").stat().st_mtime_ns == stamp
    # the same paths holding other data (a re-recorded corpus): trained again, not skipped
    other = tmp_path / "rerecorded"
    shutil.copytree(tiny_corpus, other, ignore=shutil.ignore_patterns("*.cache.npz"))
    shutil.copy(other / "heldout" / GRAPHS_FILE, other / "train_c" / GRAPHS_FILE)
    again = run(_train_cfg(other, "variant=mlp", "trainer.epochs=1"), tmp_path)
    assert "train" in again and (tmp_path / "best.ckpt").stat().st_mtime_ns != stamp


def test_the_harness_trains_and_reports_the_coupling_correlation(tiny_corpus, tmp_path):
    """The reported correlation is the trained head's learned C against the true C0."""
    cfg = _train_cfg(tiny_corpus, "variant=anomaly_residual", "graph=harness", "trainer.epochs=1")
    results = run(cfg, tmp_path)
    assert results["train"]["graph"] == "harness"
    heldout = results["heldout"]
    ckpt = load_checkpoint(tmp_path / "best.ckpt")
    learned = model_from_checkpoint(ckpt).anomaly.coupling().detach().numpy()
    truth = np.asarray(ckpt["graph"]["coupling"], np.float32)
    np.testing.assert_array_equal(truth, DEFAULT_C0)
    np.testing.assert_allclose(heldout["coupling"], learned, atol=1e-5)
    expected = coupling_correlation(learned, truth)
    assert heldout["coupling_correlation"] == pytest.approx(expected, abs=1e-6)
    assert heldout["coupling_correlation"] < 0.999  # one epoch does not find C0 exactly


def test_the_recording_cache_is_used_and_refreshed(tiny_corpus, tmp_path):
    src = tiny_corpus / "train_a" / GRAPHS_FILE
    copy = tmp_path / GRAPHS_FILE
    copy.write_bytes(src.read_bytes())
    first = load_recordings([copy])
    cache = copy.with_name(copy.name + ".cache.npz")
    assert cache.is_file()
    stamp = cache.stat().st_mtime_ns
    second = load_recordings([copy])
    assert cache.stat().st_mtime_ns == stamp
    np.testing.assert_array_equal(first.x, second.x)
    lines = copy.read_text().splitlines(keepends=True)
    copy.write_text("".join(lines[:100]))  # the source changed: the cache must not be trusted
    assert len(load_recordings([copy])) == 100


def test_the_gbdt_baseline_trains_saves_reloads_and_evaluates(tiny_corpus, tmp_path):
    """The classical baseline goes through the same command, split, checkpoint and metrics."""
    results = run(
        _train_cfg(tiny_corpus, "variant=gbdt", "model.rounds=20", network=False), tmp_path
    )
    assert results["train"]["variant"] == "gbdt" and results["train"]["best_epoch"] == 1
    ckpt = load_checkpoint(tmp_path / "best.ckpt")  # weights_only=True: boosters are bytes
    assert ckpt["state_dict"]["class_booster"].numel() > 0
    assert ckpt["state_dict"]["joint_booster"].numel() > 0
    assert ckpt["state_dict"]["severity_booster"].numel() > 0  # the severity regressor
    again = evaluate_checkpoint(tmp_path / "best.ckpt", str(tiny_corpus / "heldout"))
    m = results["heldout"]["metrics"]
    assert again["metrics"]["severity_mae_faulted"] == m["severity_mae_faulted"] < 0.2
    assert again["metrics"]["accuracy"] == m["accuracy"]
    assert again["metrics"]["localisation_accuracy"] == m["localisation_accuracy"]
    rec = load_recordings([tiny_corpus / "heldout" / GRAPHS_FILE])
    assert m["accuracy"] > np.bincount(rec.fault_class).max() / len(rec)  # above the majority


def test_gbdt_boosters_are_byte_identical_for_one_seed(tiny_corpus, tmp_path):
    """``deterministic=True``: the same seed and data give the same trees, byte for byte, whatever
    thread count the machine had free (``threads: auto`` differs between a loaded and an idle
    machine)."""
    boosters = []
    for name, seed, threads in (("a", 42, 1), ("b", 42, 2), ("c", 7, 1)):
        cfg = _train_cfg(
            tiny_corpus, "variant=gbdt", "model.rounds=20", f"seed={seed}", f"threads={threads}",
            network=False,
        )  # fmt: skip
        cfg.data.evaluate.heldout = None
        run(cfg, tmp_path / name)
        state = load_checkpoint(tmp_path / name / "best.ckpt")["state_dict"]
        boosters.append({k: state[k].numpy().tobytes() for k in ("class_booster", "joint_booster")})
    assert boosters[0] == boosters[1]
    assert all(len(b) > 1000 for b in boosters[0].values())
    assert boosters[2] != boosters[0]  # the seed reaches the trees (bagging, split order)


@pytest.mark.parametrize(
    "override, needle",
    [
        ("model.severity_objective=l3", "train: error: model.severity_objective: 'l3'; known:"),
        ("model.channels=[torque]", "train: error: model.channels: unknown ['torque']"),
    ],
)
def test_a_bad_gbdt_setting_is_one_line_and_exit_status_2(tiny_corpus, tmp_path, override, needle):
    """The trees' own settings, refused where the model is built (after the data are read): one
    line naming the key, exit status 2, no traceback."""
    import subprocess
    import sys

    args = [sys.executable, "-m", "robohealth_mj.train", "variant=gbdt", override,
            f"data.train=[{tiny_corpus}/train_*]", "data.evaluate.heldout=null",
            "data.evaluate.probe=null", "trainer.progress=false", "window=8",
            f"out_dir={tmp_path}"]  # fmt: skip
    proc = subprocess.run(args, capture_output=True, text=True, timeout=300)
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert len(lines) == 1 and needle in lines[0], proc.stderr


@pytest.mark.parametrize("variant", ["stgnn_fixed", "anomaly_residual"])
def test_a_short_run_learns_far_above_chance(learnable_corpus, tmp_path, variant):
    """Would fail if the default backbone could not learn: a few epochs on a small corpus must
    beat the majority class by a clear margin on the held-out session, and (with the
    localisation head; the coupling head needs more data to find C) chance localisation too."""
    cfg = _train_cfg(learnable_corpus, f"variant={variant}", "trainer.epochs=8", "model.hidden=32")
    m = run(cfg, tmp_path)["heldout"]["metrics"]
    rec = load_recordings([learnable_corpus / "heldout" / GRAPHS_FILE])
    majority = np.bincount(rec.fault_class).max() / len(rec)
    assert m["accuracy"] > majority + 0.15
    if variant == "stgnn_fixed":
        assert m["localisation_accuracy"] > 1 / 3 + 0.2  # three joints carry faults
