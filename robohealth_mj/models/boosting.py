"""The one LightGBM recipe every booster here is trained with: at most ``rounds`` rounds,
stopping ``patience`` rounds after the validation metric last improved."""

from __future__ import annotations

from typing import Any

import numpy as np


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
