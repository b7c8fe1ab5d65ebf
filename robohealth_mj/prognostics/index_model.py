"""How a joint's daily health index is read from a window model's scores, and its calibration.

A session's windows give per joint a raw index (:mod:`robohealth_mj.prognostics.health`: the mean
over windows of P(mechanical fault) x P(joint) x severity). :func:`session_reading` keeps three
forms of it: over every window, split by the mechanical mode the model names, and over only the
windows in which the joint turned. An :class:`IndexModel` chooses how to read them:

- ``raw``: ``all`` windows, or only those where the joint is ``moving`` (friction and backlash
  act only on a turning joint, so the still windows of a joint that turns a quarter of the time
  dilute its evidence fourfold), or, where the model names friction or backlash on the joint,
  that mode's own ``channel`` in severity units (:mod:`robohealth_mj.prognostics.channels`: the
  window model's severity head levels off for these two modes, the channels do not); or the
  channels alone through the four modes' signatures (:mod:`robohealth_mj.prognostics.signature`):
  ``signature`` (where the channels' call of the mode is sure, they name it and read its
  severity; elsewhere the ``channel`` form) or ``signature_named`` (the window model names the
  mode, the channels read its severity);
- ``calibration``: none (``none``: for the raw forms already in severity units), one isotonic
  map to severity for every joint (``pooled``), one per ``joint``,
  one per mechanical ``mode`` the model attributes most to the joint, or one per mode and joint
  (``mode_joint``, falling back to the mode's map, then the pooled one, where a cell had too few
  calibration days);
- ``monotone``: read the calibrated history as wear, which never heals: each day the
  non-decreasing fit of the days so far (:func:`robohealth_mj.prognostics.health.monotone_index`).

A fitted index is saved as JSON (the monitor's ``health.calibration``); a file of the older form
``{"x": [...], "y": [...]}`` reads as the pooled map over every window, not monotone.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.health import Calibration, monotone_index
from robohealth_mj.prognostics.signature import Signatures

MIN_CELL_DAYS = 30  # calibration days below which a cell uses the coarser map
RAWS = ("all", "moving", "channel", "signature", "signature_named")
CALIBRATIONS = ("none", "pooled", "joint", "mode", "mode_joint")
CHANNEL_MODES = (1, 0)  # positions in MECHANICAL_CLASSES of friction and backlash


@dataclass(frozen=True)
class IndexModel:
    raw: str = "all"
    calibration: str = "pooled"
    monotone: bool = False

    def __post_init__(self) -> None:
        if self.raw not in RAWS or self.calibration not in CALIBRATIONS:
            raise InputError(
                f"index model: raw {self.raw!r} (one of {list(RAWS)}), calibration "
                f"{self.calibration!r} (one of {list(CALIBRATIONS)})"
            )

    @property
    def name(self) -> str:
        return "+".join([self.raw, self.calibration] + (["monotone"] if self.monotone else []))


VARIANTS = tuple(
    IndexModel(raw, cal, mono) for raw in RAWS for cal in CALIBRATIONS for mono in (False, True)
)


def session_reading(by_mode: np.ndarray, moved: np.ndarray) -> dict[str, list]:
    """One session's raw forms from its windows' ``by_mode [K, M, J]`` attribution
    (:func:`robohealth_mj.prognostics.health.mode_attribution`) and ``moved [K, J]`` (the joint
    turned in the window): ``raw_modes [M][J]`` and ``raw_moving [J]`` (None for a joint that never
    turned)."""
    a = np.asarray(by_mode, float)
    m = np.asarray(moved, bool)
    per_joint = a.sum(axis=1)  # [K, J]
    turned = m.sum(axis=0)
    moving = (per_joint * m).sum(axis=0) / np.maximum(turned, 1)
    return {
        "raw_modes": a.mean(axis=0).round(8).tolist() if len(a) else [],
        "raw_moving": [float(v) if t else None for v, t in zip(moving, turned, strict=True)],
    }


@dataclass(frozen=True)
class ChannelFits:
    """What the recorded channels were fitted to: friction's and backlash's ``scales [2, J]``
    (the reading per unit severity; raw ``channel``) and the four modes' ``signatures`` (raw
    ``signature`` and ``signature_named``)."""

    scales: np.ndarray | None = None
    signatures: Signatures | None = None

    def serve(self, raw: str) -> bool:
        """Whether a raw form can be read through these fits."""
        needs_scales = raw in ("channel", "signature")
        needs_signatures = raw.startswith("signature")
        return (self.scales is not None or not needs_scales) and (
            self.signatures is not None or not needs_signatures
        )


NO_CHANNELS = ChannelFits()


def reading(
    day: dict, model: IndexModel, fits: ChannelFits = NO_CHANNELS
) -> tuple[np.ndarray, np.ndarray]:
    """``(raw [J], mode [J])``: the day's raw index under ``model.raw`` and the mechanical mode
    it is read as (calibrated per mode under ``mode`` calibrations). Raw forms: over every
    window; over the windows the joint turned in (a joint that never turned falls back to every
    window); where the model names friction or backlash on a joint, that mode's own channel in
    severity units (``day["channel"]`` over ``fits.scales``); the signatures' mode and severity
    where the channels' call is sure, else that channel form (``signature``); or the signatures'
    severity of the mode the model names (``signature_named``). A joint the channels could not
    read keeps the reading over the windows it turned in."""
    raw, named = np.asarray(day["raw"], float), mode_of(day)
    if model.raw == "all":
        return raw, named
    moving = np.asarray(day["raw_moving"], float)  # None reads as NaN
    out = np.where(np.isfinite(moving), moving, raw)
    if model.raw == "moving":
        return out, named
    channel = np.asarray(day["channel"], float)
    if model.raw in ("channel", "signature"):
        if fits.scales is None:
            raise InputError(f"index model raw={model.raw} needs the channels' scales")
        units = channel[: len(fits.scales)] / np.asarray(fits.scales, float)
        for k, mode in enumerate(CHANNEL_MODES):
            use = (named == mode) & np.isfinite(units[k])
            out[use] = np.clip(units[k][use], 0.0, 1.5)
        if model.raw == "channel":
            return out, named
    if fits.signatures is None:
        raise InputError(f"index model raw={model.raw} needs the channels' signatures")
    if model.raw == "signature":  # the channels' call where it is sure, else the channel form
        recent = day.get("recent_channel")  # the last days' readings: loads settle a sag
        called, severity, sure = fits.signatures.call(channel, recent)
        sure &= np.isfinite(severity)
        return np.where(sure, severity, out), np.where(sure, called, named)
    severity = fits.signatures.read(channel, named)
    return np.where(np.isfinite(severity), severity, out), named


def mode_of(day: dict) -> np.ndarray:
    """``[J]`` the mechanical mode the model attributes most to each joint."""
    return np.asarray(day["raw_modes"], float).argmax(axis=0)


def cell_keys(calibration: str, mode: int, joint: int) -> list[str]:
    """The maps a joint's reading tries, finest first (the pooled map is the last resort)."""
    return {
        "none": [],
        "pooled": [],
        "joint": [f"j{joint}"],
        "mode": [f"m{mode}"],
        "mode_joint": [f"m{mode}j{joint}", f"m{mode}"],
    }[calibration]


@dataclass
class FittedIndex:
    """An :class:`IndexModel` with its maps: ``pooled`` and ``cells`` keyed ``j<joint>``,
    ``m<mode>`` or ``m<mode>j<joint>``."""

    model: IndexModel
    pooled: Calibration
    cells: dict[str, Calibration] = field(default_factory=dict)
    channels: ChannelFits = field(default_factory=ChannelFits)

    def calibrate(self, day: dict) -> np.ndarray:
        """``[J]`` one day's calibrated index (before any monotone reading)."""
        raw, modes = reading(day, self.model, self.channels)
        out = self.pooled(raw)
        for j in range(len(raw)):
            keys = cell_keys(self.model.calibration, int(modes[j]), j)
            cal = next((self.cells[k] for k in keys if k in self.cells), None)
            if cal is not None:
                out[j] = cal(raw[j])
        return out

    def band(self, low: np.ndarray, high: np.ndarray, reading: np.ndarray) -> tuple:
        """The raw bootstrap band (``low``, ``high``) through the pooled map, widened to hold
        ``reading`` (the index as read; a per-cell map or a monotone reading may leave it)."""
        return np.minimum(self.pooled(low), reading), np.maximum(self.pooled(high), reading)

    def online(self, history: np.ndarray) -> np.ndarray:
        """A joint's calibrated history ``[k]`` as the trend reads it on the latest day."""
        return monotone_index(history) if self.model.monotone else np.asarray(history, float)

    def life(self, days: list[dict]) -> np.ndarray:
        """``[S, J]`` the index a monitor reads on each day, given only the days so far."""
        daily = np.stack([self.calibrate(d) for d in days])
        if not self.model.monotone:
            return daily
        return np.array(
            [
                [self.online(daily[: k + 1, j])[-1] for j in range(daily.shape[1])]
                for k in range(len(daily))
            ]
        )

    def to_json(self) -> dict[str, Any]:
        scales, signatures = self.channels.scales, self.channels.signatures
        return {
            "index_model": asdict(self.model),
            **asdict(self.pooled),
            "cells": {k: asdict(c) for k, c in self.cells.items()},
            "channel_scales": None if scales is None else np.round(scales, 8).tolist(),
            "signatures": None if signatures is None else signatures.to_json(),
        }

    @classmethod
    def load(cls, path: str | Path) -> FittedIndex:
        """A saved index (:meth:`to_json`) or an older pooled calibration file."""
        pooled = Calibration.load(path)  # checks the pooled knots, names the file
        data = json.loads(Path(path).read_text())
        try:
            model = IndexModel(**data.get("index_model", {}))
            cells = {
                str(k): Calibration([float(v) for v in c["x"]], [float(v) for v in c["y"]])
                for k, c in data.get("cells", {}).items()
            }
            scales = data.get("channel_scales")
            scales = None if scales is None else np.asarray(scales, float).reshape(2, -1)
        except (TypeError, ValueError, KeyError, AttributeError) as exc:
            raise InputError(f"{path}: not a health index file ({exc})") from None
        signatures = data.get("signatures")
        if signatures is not None:
            signatures = Signatures.from_json(signatures, f"{path}: signatures")
        if model.raw in ("channel", "signature") and scales is None:
            raise InputError(f"{path}: index model raw={model.raw} without channel_scales")
        if model.raw.startswith("signature") and signatures is None:
            raise InputError(f"{path}: index model raw={model.raw} without signatures")
        return cls(model, pooled, cells, ChannelFits(scales, signatures))


def fit_index(
    model: IndexModel, days: Iterable[dict], channels: ChannelFits = NO_CHANNELS
) -> FittedIndex:
    """Fit ``model``'s maps on ``days`` (each with ``truth [J]`` beside its raw forms); a cell
    needs :data:`MIN_CELL_DAYS` joint-days, some of them worn. ``channels``: what the channel
    raw forms read through."""
    raws, truths, groups = [], [], []
    for d in days:
        raw, modes = reading(d, model, channels)
        for j in range(len(raw)):
            raws.append(raw[j])
            truths.append(d["truth"][j])
            groups.append(cell_keys(model.calibration, int(modes[j]), j))
    raws, truths = np.array(raws), np.array(truths)
    if model.calibration == "none":  # a raw form in severity units, read as it is
        return FittedIndex(model, Calibration.identity(), channels=channels)
    fitted = FittedIndex(model, Calibration.fit(raws, truths), channels=channels)
    for key in sorted({k for keys in groups for k in keys}):
        take = np.array([key in keys for keys in groups])
        if take.sum() >= MIN_CELL_DAYS and truths[take].max() > 0:
            fitted.cells[key] = Calibration.fit(raws[take], truths[take])
    return fitted
