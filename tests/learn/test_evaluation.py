"""Scoring a checkpoint under a placement: the one helper the research scripts share."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.data.graphs import harness_graph
from robohealth_mj.data.observability import hide_unobservable
from robohealth_mj.data.windows import joints_moved, make_windows
from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint
from robohealth_mj.learn.evaluation import (
    evaluate_checkpoint,
    score_checkpoint,
    score_under_placement,
    validation_windows,
)
from robohealth_mj.models.heads import COUPLING_FLOOR

pytestmark = pytest.mark.slow


def test_under_its_own_placement_a_checkpoint_scores_as_its_evaluation(deployed):
    ckpt = load_checkpoint(deployed["harness_ckpt"])
    held = load_recordings([deployed["heldout"]])
    mine = score_under_placement(ckpt, held)
    theirs = evaluate_checkpoint(deployed["harness_ckpt"], str(deployed["heldout"]), "cpu")[
        "metrics"
    ]
    for key in ("windows", "accuracy", "localisation_accuracy", "macro_f1"):
        assert mine[key] == pytest.approx(theirs[key]), key


def test_a_told_placement_is_set_in_the_model_and_validation_is_its_own_runs(deployed):
    ckpt = load_checkpoint(deployed["harness_ckpt"])
    train = load_recordings(expand_paths(ckpt["config"]["data"]["train"]))
    other = np.asarray(harness_graph(coupling_seed=7, coupling_sensors=4).coupling)
    model = model_from_checkpoint(ckpt)
    told = score_under_placement(ckpt, train, other, tell_model=True, model=model,
                                 validation_only=True)  # fmt: skip
    learned = model.anomaly.coupling().detach().numpy()  # set, up to the floor softplus keeps
    np.testing.assert_allclose(learned, np.maximum(other, COUPLING_FLOOR), atol=1e-5)
    val = validation_windows(ckpt, train)
    runs = set(ckpt["split_runs"]["val"])
    every = make_windows(train, int(ckpt["window"]))
    assert 0 < told["windows"] == len(val.end) < len(every.end)
    assert {np.asarray(train.run_ids)[train.run[e]] for e in val.end} <= runs


def test_motion_observability_calls_friction_and_backlash_only_where_a_joint_moved(deployed):
    """Per window, as the monitor does per tick: the model's belief in a motion-only fault on
    the joints that stood still goes to none; windows in which every joint moved are unchanged."""
    ckpt, held = deployed["structural_ckpt"], str(deployed["heldout"])
    plain = score_checkpoint(ckpt, held, "cpu")
    gated = score_checkpoint(ckpt, held, "cpu", observability="motion")
    moved = joints_moved(plain.rec, plain.windows)
    still, every = ~moved.any(axis=1), moved.all(axis=1)
    assert (~every).sum() > len(every) // 4  # sweeps leave some joints still in most windows

    def probs(logits):
        e = np.exp(logits - logits.max(axis=1, keepdims=True))
        return e / e.sum(axis=1, keepdims=True)

    joint = probs(plain.predictions.joint_logits.astype(np.float64))
    classes = plain.ckpt["labels"]["classes"]
    want = hide_unobservable(probs(plain.predictions.class_logits), joint, moved, classes)
    np.testing.assert_allclose(probs(gated.predictions.class_logits), want, atol=1e-5)
    calls = gated.predictions.class_logits.argmax(1)
    motion_only = [classes.index("backlash"), classes.index("friction")]
    assert not np.isin(calls[still], motion_only).any()
    before = plain.predictions.class_logits.argmax(1)
    assert (np.isin(calls, motion_only) <= np.isin(before, motion_only)).all()  # only fewer
    assert (np.isin(calls, motion_only) < np.isin(before, motion_only)).any()  # ... and some
    np.testing.assert_array_equal(calls[every], before[every])
    result = evaluate_checkpoint(ckpt, held, "cpu", observability="motion")
    assert result["observability"] == "motion"
    assert result["metrics"]["windows"] == len(calls)


def test_evaluate_refuses_an_unknown_observability_in_one_line(deployed):
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "robohealth_mj.evaluate", f"ckpt={deployed['structural_ckpt']}",
         f"data={deployed['heldout']}", "observability=moving"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    errors = [line for line in done.stderr.splitlines() if "error" in line]
    assert errors == [
        "evaluate: error: observability must be one of ['all', 'motion'], got 'moving'"
    ]
