"""Fault modes, scenarios and their parameters (with optional per-session randomisation)."""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.schema import FAULT_CLASSES, JOINT_NAMES, FaultLabel

MODES: tuple[str, ...] = FAULT_CLASSES[1:]
MECHANICAL: tuple[str, ...] = ("backlash", "friction", "jam", "struct_weaken")
SENSOR: tuple[str, ...] = ("sensor_drift", "sensor_noise")
FAULT_MODELS = ("physics", "analytic", "hybrid")


@dataclass(frozen=True)
class Scenario:
    """One cell of the joint x fault x severity space."""

    fault_class: str
    joint: int  # the joint's index along the arm's chain
    severity: float
    joint_name: str | None = None  # the arm's name for it (None: the UR joint of that index)

    def __post_init__(self) -> None:
        if self.fault_class not in MODES:
            raise InputError(f"unknown fault class {self.fault_class!r}; known: {list(MODES)}")
        if self.joint < 0 or (self.joint_name is None and self.joint >= len(JOINT_NAMES)):
            raise InputError(f"fault joint index {self.joint} out of range")
        if not 0.0 <= self.severity <= 1.0:
            raise InputError(f"fault severity {self.severity} outside [0, 1]")

    @property
    def label(self) -> FaultLabel:
        name = JOINT_NAMES[self.joint] if self.joint_name is None else self.joint_name
        return FaultLabel(self.fault_class, name, float(self.severity), True)


class FaultParameters:
    """Nominal fault parameters per mode, optionally redrawn per session.

    With randomisation on, every numeric parameter is multiplied by a factor drawn uniformly from
    ``[1 - spread, 1 + spread]`` with the session seed (thesis §4.7: the model must learn fault
    families, not one generator's waveforms). The drawn values go into the manifest.
    """

    def __init__(
        self,
        physics: dict[str, dict[str, Any]],
        analytic: dict[str, dict[str, Any]],
        randomise: bool = False,
        spread: float = 0.4,
        seed: int = 0,
    ) -> None:
        if not 0.0 <= spread < 1.0:
            raise InputError(f"faults.randomise_spread must be in [0, 1), got {spread}")
        self.randomised = bool(randomise)
        physics, analytic = copy.deepcopy(dict(physics)), copy.deepcopy(dict(analytic))
        if self.randomised:
            rng = stream("faults.parameters", seed)
            for table in (physics, analytic):
                for mode in sorted(table):
                    for key in sorted(table[mode]):
                        factor = rng.uniform(1.0 - spread, 1.0 + spread)
                        table[mode][key] = _scale(table[mode][key], factor)
        self.physics, self.analytic = physics, analytic

    def as_dict(self) -> dict[str, Any]:
        return {"randomised": self.randomised, "physics": self.physics, "analytic": self.analytic}


def _scale(value: Any, factor: float) -> Any:
    if isinstance(value, list | tuple):
        return [float(v) * factor for v in value]
    return float(value) * factor
