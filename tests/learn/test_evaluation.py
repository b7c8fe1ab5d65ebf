"""Scoring a checkpoint under a placement: the one helper the research scripts share."""

from __future__ import annotations

import numpy as np
import pytest

from robohealth_mj.data.arrays import expand_paths, load_recordings
from robohealth_mj.data.graphs import harness_graph
from robohealth_mj.data.windows import make_windows
from robohealth_mj.learn.checkpoint import load_checkpoint, model_from_checkpoint
from robohealth_mj.learn.evaluation import (
    evaluate_checkpoint,
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
