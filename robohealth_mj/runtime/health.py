"""Health across sessions: each arm's per-joint index history, its RUL and the wear warning,
persisted per arm so that a restarted monitor carries on where it stopped.

The history keeps each session's calibrated index as it was read; with ``monotone`` the joints'
estimates read it as wear that never heals (its non-decreasing fit), as the wear study chose.
A session ends -> :meth:`HealthTracker.update` with the session's :class:`SessionHealth` and its
operating day -> the history grows, the state file is rewritten atomically, and the joints' RUL
estimates and warnings come back (and as ``/diagnostics`` key/values, :func:`health_fields`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.errors import InputError
from robohealth_mj.prognostics.health import SessionHealth, monotone_index
from robohealth_mj.prognostics.rul import RulEstimate, TrendRul
from robohealth_mj.schema import JOINT_NAMES

STATE_VERSION = 1


@dataclass
class JointHealth:
    joint: str
    index: float
    low: float
    high: float
    rul: RulEstimate
    warning: bool


@dataclass
class HealthTracker:
    """Per-arm health histories under ``state_dir`` (one JSON file per arm)."""

    state_dir: Path
    estimator: TrendRul = field(default_factory=TrendRul)
    lead_days: float = 15.0  # conf/monitor.yaml health.lead_days
    floor: float = 0.2
    monotone: bool = False  # read each joint's history as wear that never heals (index_model.py)

    def _path(self, arm: str) -> Path:
        if not arm or any(c in arm for c in "/\\") or arm.startswith("."):
            raise InputError(f"arm name {arm!r} cannot name a health state file")
        return Path(self.state_dir) / f"{arm}.health.json"

    def history(self, arm: str) -> dict[str, Any]:
        """The arm's stored history (empty when none)."""
        path = self._path(arm)
        if not path.is_file():
            return {"version": STATE_VERSION, "arm": arm, "sessions": []}
        try:
            state = json.loads(path.read_text())
        except ValueError as exc:
            raise InputError(f"{path}: not a health state file ({exc})") from None
        if state.get("version") != STATE_VERSION or not isinstance(state.get("sessions"), list):
            raise InputError(f"{path}: not a health state file of version {STATE_VERSION}")
        return state

    def update(
        self,
        arm: str,
        day: float,
        health: SessionHealth,
        joints: Sequence[str] = JOINT_NAMES,
        channel: np.ndarray | None = None,
    ) -> list[JointHealth]:
        """Add one session's index (at operating ``day``) and return every joint's estimate
        (``joints``: the arm's, the index's order; ``channel [C, J]``: the session's channel
        readings, kept for the next sessions' index: :meth:`recent_channels`)."""
        state = self.history(arm)
        if list(state.get("joints", JOINT_NAMES)) != list(joints) and state["sessions"]:
            raise InputError(f"{arm}: a history of joints {state.get('joints', JOINT_NAMES)}, "
                             f"not {list(joints)}")  # fmt: skip
        state["joints"] = list(joints)
        last = state["sessions"][-1]["day"] if state["sessions"] else None
        if last is not None and day <= last:
            raise InputError(f"{arm}: session day {day} is not after the last one ({last})")
        session = {
            "day": float(day),
            "index": np.round(health.index, 6).tolist(),
            "low": np.round(health.low, 6).tolist(),
            "high": np.round(health.high, 6).tolist(),
            "windows": int(health.windows),
        }
        if channel is not None:  # JSON has no NaN: a channel not read is stored as null
            rounded = np.round(np.asarray(channel, float), 8)
            session["channel"] = np.where(np.isfinite(rounded), rounded, None).tolist()
        state["sessions"].append(session)
        atomic_write_json(self._path(arm), state)
        return self.assess(state)

    def recent_channels(self, arm: str, sessions: int) -> list[np.ndarray]:
        """The channel readings ``[C, J]`` of the arm's last ``sessions`` sessions, oldest
        first; fewer where a session in that stretch kept none (a gap breaks the run)."""
        out: list[np.ndarray] = []
        for session in reversed(self.history(arm)["sessions"][-sessions:] if sessions else []):
            if session.get("channel") is None:
                break
            out.insert(0, np.asarray(session["channel"], float))  # null reads back as NaN
        return out

    def assess(self, state: dict[str, Any]) -> list[JointHealth]:
        sessions = state["sessions"]
        if not sessions:
            return []
        days = np.array([s["day"] for s in sessions])
        index = np.array([s["index"] for s in sessions], float)  # [S, J]
        out = []
        for j, name in enumerate(state.get("joints", JOINT_NAMES)):
            seen = monotone_index(index[:, j]) if self.monotone else index[:, j]
            rul = self.estimator.estimate(days, seen)
            last = sessions[-1]
            out.append(
                JointHealth(
                    name,
                    float(seen[-1]),
                    last["low"][j],
                    last["high"][j],
                    rul,
                    rul.warns(self.lead_days, self.floor),
                )
            )
        return out


def health_fields(joints: list[JointHealth]) -> list[tuple[str, str]]:
    """``/diagnostics`` key/values: each joint's index with its band, RUL days and warning."""

    def days(v: float) -> str:
        return "inf" if not math.isfinite(v) else f"{v:.1f}"

    fields = []
    for h in joints:
        fields += [
            (f"health.{h.joint}", f"{h.index:.3f}"),
            (f"health.{h.joint}.band", f"{h.low:.3f}..{h.high:.3f}"),
            (f"rul_days.{h.joint}", days(h.rul.rul)),
            (f"rul_days.{h.joint}.band", f"{days(h.rul.low)}..{days(h.rul.high)}"),
            (f"wear_warning.{h.joint}", "true" if h.warning else "false"),
        ]
    return fields
