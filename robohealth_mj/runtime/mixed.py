"""A mixed fleet: arms of several kinds (a UR5e's six joints, an FR3's seven) in one process.

One model reads one arm graph, so a mixed fleet is one :class:`FleetRuntime` per model, each
batching its own arms' rows: a stream is registered with the model that reads its arm, and a
tick's rows are handed to each member as one array of its own graph's shape. Nothing is shared
between members but the process (and the fleet step's cost per stream stays that of the member's
model on its node count). Built on the fleet runtime, not beside it: every check, window, alarm
and evidence rule is the member's.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.runtime.fleet import FleetRuntime, TickResult


@dataclass(frozen=True)
class Rows:
    """One member's rows of a tick: ``slots [R]``, ``sample_index [R]``, ``t [R]`` and
    ``x [R, 2J, F]`` on that member's arm graph."""

    slots: np.ndarray
    sample_index: np.ndarray
    t: np.ndarray
    x: np.ndarray


class MixedFleet:
    """Members by name (``{"ur5e": "ur5e.onnx", "fr3": "fr3.onnx"}``), each a fleet runtime of
    its own model; ``options`` go to every member (threads, shards, alarm, evidence ...)."""

    def __init__(self, models: Mapping[str, str | Path], **options) -> None:
        if not models:
            raise InputError("a mixed fleet needs at least one model")
        self.members = {
            name: FleetRuntime(str(path), strict=True, **options) for name, path in models.items()
        }

    def member(self, name: str) -> FleetRuntime:
        try:
            return self.members[name]
        except KeyError:
            known = ", ".join(self.members)
            raise InputError(f"no fleet member {name!r}; members: {known}") from None

    def register(self, name: str, stream_ids: Sequence[str]) -> np.ndarray:
        """Slots of ``stream_ids`` in member ``name`` (the model that reads their arm)."""
        return self.member(name).register(stream_ids)

    def step(self, rows: Mapping[str, Rows]) -> dict[str, TickResult]:
        """One tick: each member's rows through that member's step."""
        return {
            name: self.member(name).step(r.slots, r.sample_index, r.t, r.x)
            for name, r in rows.items()
        }

    def close(self) -> None:
        for fleet in self.members.values():
            fleet.close()
