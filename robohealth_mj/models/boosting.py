"""The one LightGBM recipe every booster here is trained with: at most ``rounds`` rounds,
stopping ``patience`` rounds after the validation metric last improved."""

from __future__ import annotations

import re
from typing import Any

import numpy as np

# LightGBM writes the parameters a booster was trained with after its trees, the thread count
# among them. The count belongs to the machine, not to the model (``deterministic`` trees are the
# same whatever it is), so it is written as 0 (LightGBM's "OpenMP default"): one seed and one
# dataset then give the same bytes on a loaded machine and an idle one.
_THREADS_LINE = re.compile(rb"^\[num_threads: \d+\]$", re.MULTILINE)


def booster_text(booster: Any) -> bytes:
    """A LightGBM booster's text dump without the thread count it happened to be trained with."""
    return _THREADS_LINE.sub(b"[num_threads: 0]", booster.model_to_string().encode())


def train_early_stopped(
    params: dict[str, Any],
    train: tuple[np.ndarray, np.ndarray],
    val: tuple[np.ndarray, np.ndarray],
    rounds: int,
    patience: int,
    evals: dict | None = None,
):
    """A booster trained on ``train`` (features ``[K, D]``, targets ``[K]``), stopped early on
    ``val``; ``evals`` (if given) receives the validation metric per round under ``"val"``."""
    import lightgbm as lgb

    dtrain = lgb.Dataset(train[0], train[1], free_raw_data=True)
    callbacks = [lgb.early_stopping(patience, verbose=False)]
    if evals is not None:
        callbacks.append(lgb.record_evaluation(evals))
    return lgb.train(
        params,
        dtrain,
        num_boost_round=rounds,
        valid_sets=[lgb.Dataset(val[0], val[1], reference=dtrain)],
        valid_names=["val"],
        callbacks=callbacks,
    )
