"""The ``gbdt`` baseline: gradient-boosted trees (LightGBM) on the window statistics of every node.

It is the bar the graph models are measured against, so it goes through the same commands,
splits, checkpoints and metrics: it is an ``nn.Module`` whose boosters live in byte buffers
(their text dumps), so ``state_dict``, ``torch.load(weights_only=True)`` and evaluation work as
for the networks. It is fitted by :meth:`fit`, not by gradients.

Boosters: the fault class over all windows, the faulted joint over faulted windows, and (with
``severity: true``) a severity head over faulted windows beside the networks': level classifiers
per (fault class, joint) read through the class and joint posteriors (``severity_objective:
levels``, :mod:`robohealth_mj.models.severity_levels`), or a regression. Features:
:func:`window_statistics` of every node, flattened (N * S * 7 columns).

Shapes: ``x [B, W, N, F]`` -> ``class_logits [B, C]``, ``joint_logits [B, J]`` (raw scores),
``severity [B]`` (with a severity booster).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import nn

from robohealth_mj import schema
from robohealth_mj.common.errors import InputError
from robohealth_mj.models.boosting import booster_text, train_early_stopped
from robohealth_mj.models.severity_levels import SeverityLevels
from robohealth_mj.models.statistics import window_statistics


def _booster_bytes(booster: Any | None) -> torch.Tensor:
    """A booster (or :class:`SeverityLevels`) as a uint8 buffer, so checkpoints hold it."""
    if booster is None:
        return torch.zeros(0, dtype=torch.uint8)
    text = booster.to_bytes() if hasattr(booster, "to_bytes") else booster_text(booster)
    return torch.frombuffer(bytearray(text), dtype=torch.uint8).clone()


def _booster_from(buffer: torch.Tensor, levels: bool = False):
    import lightgbm as lgb

    if buffer.numel() == 0:
        return None
    data = bytes(buffer.cpu().numpy())
    return SeverityLevels.from_bytes(data) if levels else lgb.Booster(model_str=data.decode())


# The severity head's objectives: squared error predicts the conditional mean, which pulls the
# outer severity levels toward the middle when the windows leave the level uncertain; absolute
# error (regression_l1) the conditional median; ``levels`` classifies the level per (fault class,
# joint) and predicts the median of their mixture under the class and joint posteriors
# (models/severity_levels.py).
SEVERITY_OBJECTIVES = ("regression", "regression_l1", "levels")


class GradientBoostedTrees(nn.Module):
    """LightGBM multiclass boosters on flattened per-node window statistics."""

    def __init__(
        self,
        adjacency: torch.Tensor,
        num_joints: int,
        in_features: int,
        window: int,
        num_classes: int = 7,
        rounds: int = 300,
        early_stopping_rounds: int = 30,
        learning_rate: float = 0.1,
        num_leaves: int = 63,
        min_child_samples: int = 20,
        feature_fraction: float = 0.5,
        max_bin: int = 63,
        metric: str = "multi_error",
        first_signal: int = 2,
        channels: list[str] | None = None,
        severity: bool = False,
        severity_objective: str = "regression",  # what checkpoints without the key hold
        backbone: Any = None,
        max_pool: Any = None,
    ) -> None:
        super().__init__()
        del adjacency, window, backbone, max_pool  # trees see no graph and have no backbone
        self.num_joints, self.num_classes, self.in_features = num_joints, num_classes, in_features
        self.first_signal = first_signal
        # added to the class logits; set by commissioning (deploy/operating_point.py)
        self.register_buffer("class_offset", torch.zeros(num_classes), persistent=False)
        # Channel ablations: the signal channels the trees read (None: all of the schema's).
        names = schema.FEATURE_NAMES[first_signal:]
        unknown = sorted(set(channels or ()) - set(names))
        if unknown:
            raise InputError(f"model.channels: unknown {unknown}; known: {list(names)}")
        keep = [first_signal + names.index(c) for c in channels] if channels else None
        self.register_buffer("channel_index", torch.tensor(keep if keep else [], dtype=torch.long))
        self.params = {
            "learning_rate": learning_rate,
            "num_leaves": num_leaves,
            "min_child_samples": min_child_samples,
            "feature_fraction": feature_fraction,
            "max_bin": max_bin,
            "metric": metric,
            "verbosity": -1,
            "deterministic": True,
            "force_col_wise": True,
        }
        self.rounds, self.early_stopping_rounds = int(rounds), int(early_stopping_rounds)
        self.register_buffer("class_booster", _booster_bytes(None))
        self.register_buffer("joint_booster", _booster_bytes(None))
        self.register_buffer("severity_booster", _booster_bytes(None))  # empty: no severity head
        self.fits_severity = bool(severity)
        if severity_objective not in SEVERITY_OBJECTIVES:
            known = ", ".join(SEVERITY_OBJECTIVES)
            raise InputError(f"model.severity_objective: {severity_objective!r}; known: {known}")
        self.severity_objective = severity_objective
        self._boosters: dict[str, Any] = {}

    def features(self, x: torch.Tensor) -> np.ndarray:
        """``[B, W, N, F]`` -> ``[B, N * S * 7]`` float32."""
        if self.channel_index.numel():
            x = torch.cat([x[..., : self.first_signal], x[..., self.channel_index]], dim=-1)
        with torch.no_grad():
            stats = window_statistics(x.float(), self.first_signal)
        return stats.flatten(1).cpu().numpy()

    def fit(
        self,
        train: tuple[np.ndarray, np.ndarray, np.ndarray],
        val: tuple[np.ndarray, np.ndarray, np.ndarray],
        seed: int,
        threads: int | None = None,
        only: tuple[str, ...] | None = None,
    ) -> dict[str, Any]:
        """Fit the boosters. ``train``/``val``: (features ``[K, D]``, class ``[K]``, joint
        ``[K]`` with -1 on healthy windows[, severity ``[K]``]). Early stopping on the validation
        split's ``metric`` (error rate by default: the log-loss turns up long before accuracy stops
        improving); the severity booster's on its mean absolute error. ``only``: fit just these
        heads (``class``, ``joint``, ``severity``), keeping the others as they are; each head's
        trees depend on its own objective, data and seed alone, so a refit head equals a fresh
        one."""
        params = {**self.params, "seed": int(seed), "num_threads": int(threads or 0)}
        record: dict[str, Any] = {}
        heads = [
            ("class", 1, lambda c, j: np.ones(len(c), bool),
             {"objective": "multiclass", "num_class": self.num_classes}, self.params["metric"]),
            ("joint", 2, lambda c, j: j >= 0,
             {"objective": "multiclass", "num_class": self.num_joints}, self.params["metric"]),
        ]  # fmt: skip
        wanted = {"class", "joint", "severity"} if only is None else set(only)
        if not (self.fits_severity and len(train) > 3):
            wanted.discard("severity")
        levels = self.severity_objective == "levels"  # not one booster: models/severity_levels.py
        if "severity" in wanted and not levels:
            objective = {"objective": self.severity_objective, "metric": "l1"}
            heads.append(("severity", 3, lambda c, j: j >= 0, objective, "l1"))
        heads = [head for head in heads if head[0] in wanted]
        if "severity" in wanted and levels:
            tr, va = train[2] >= 0, val[2] >= 0
            self._boosters["severity"], record["severity"] = SeverityLevels.fit(
                tuple(a[tr] for a in train[:4]),
                tuple(a[va] for a in val[:4]),
                params,
                self.rounds,
                self.early_stopping_rounds,
            )
            self.severity_booster = _booster_bytes(self._boosters["severity"])
        for name, target, pick, objective, metric in heads:
            tr, va = pick(train[1], train[2]), pick(val[1], val[2])
            evals: dict = {}
            booster = train_early_stopped(
                {**params, **objective},
                (train[0][tr], train[target][tr]),
                (val[0][va], val[target][va]),
                self.rounds,
                self.early_stopping_rounds,
                evals,
            )
            self._boosters[name] = booster
            setattr(self, f"{name}_booster", _booster_bytes(booster))
            record[name] = {
                "best_iteration": int(booster.best_iteration),
                f"val_{metric}": [float(v) for v in evals["val"][metric]],
            }
        return record

    def _booster(self, name: str):
        if name not in self._boosters:
            levels = name == "severity" and self.severity_objective == "levels"
            booster = _booster_from(getattr(self, f"{name}_booster"), levels)
            if booster is None:
                raise RuntimeError("the gbdt model has not been fitted")
            self._boosters[name] = booster
        return self._boosters[name]

    def _load_from_state_dict(self, state_dict, prefix, local_metadata, strict, missing, *rest):
        for name in ("class_booster", "joint_booster", "severity_booster"):
            key = prefix + name
            if key in state_dict:
                setattr(self, name, state_dict[key].detach().clone().to(torch.uint8))
            elif strict and name != "severity_booster":  # older checkpoints have no severity
                missing.append(key)
        self._boosters = {}

    def forward(self, x: torch.Tensor) -> dict[str, torch.Tensor]:
        feats = self.features(x)
        out = {}
        for name, key in (("class", "class_logits"), ("joint", "joint_logits")):
            booster = self._booster(name)
            raw = booster.predict(feats, raw_score=True)
            out[key] = torch.from_numpy(np.asarray(raw, np.float32)).to(x.device)
        out["class_logits"] = out["class_logits"] + self.class_offset
        if self.severity_booster.numel():
            if self.severity_objective == "levels":  # a mixture under the fault's posterior
                classes = torch.softmax(out["class_logits"].float(), dim=1).cpu().numpy()
                joints = torch.softmax(out["joint_logits"].float(), dim=1).cpu().numpy()
                raw = self._booster("severity").predict(feats, classes, joints)
            else:
                raw = self._booster("severity").predict(feats)
            out["severity"] = torch.from_numpy(np.clip(raw, 0.0, 1.0).astype(np.float32))
            out["severity"] = out["severity"].to(x.device)
        return out
