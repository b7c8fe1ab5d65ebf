"""The twin file: an arm's identified drive parameters, as the simulator reads them.

YAML with the arm it is of, per joint the drive parameters that replace the simulator's
(``drive_overrides``: rotor inertia, viscous and Coulomb friction), the torque constants, the
measured torque's noise per tick (``effort_noise_nm``, what the simulated effort reads with; null
keeps the sensor package's), the logs it was fitted on and the fit's residuals.
``sim.twin=FILE`` (with ``arm=`` the same arm) makes every simulation run on it.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import yaml

from robohealth_mj.common.atomic import atomic_write_text
from robohealth_mj.common.errors import InputError
from robohealth_mj.schema import JOINT_NAMES

PARAMETERS = ("armature", "damping", "frictionloss")  # what identification fits per joint
TWIN_MARK = "twin_digest.txt"  # beside a recording kept for reuse: the twin it was recorded on


def write_twin(path: Path, content: dict) -> None:
    atomic_write_text(path, yaml.safe_dump(content, sort_keys=False))


def _load(path: Path, arm: str) -> dict:
    try:
        raw = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise InputError(f"sim.twin: {path}: {exc.strerror}") from None
    except yaml.YAMLError as exc:
        raise InputError(f"sim.twin: {path}: not YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(raw, dict) or "drive_overrides" not in raw:
        raise InputError(f"{path}: key 'drive_overrides': missing (not a twin file?)")
    if raw.get("arm") != arm:
        raise InputError(f"{path}: key 'arm': the twin is of {raw.get('arm')!r} and the "
                         f"simulation's arm is {arm!r}: pass arm={raw.get('arm')}")  # fmt: skip
    return raw


def read_twin_noise(path: Path | str, arm: str) -> np.ndarray | None:
    """The measured torque's noise per tick ``[6]`` (N*m) of twin file ``path``; None where it
    states none (a twin identified from logs without a hold)."""
    path = Path(path)
    noise = _load(path, arm).get("effort_noise_nm")
    if noise is None:
        return None
    if (not isinstance(noise, list) or len(noise) != len(JOINT_NAMES)
            or not all(isinstance(v, (int, float)) and v >= 0 for v in noise)):  # fmt: skip
        raise InputError(f"{path}: key 'effort_noise_nm': {len(JOINT_NAMES)} numbers >= 0 or "
                         f"null, got {noise!r}")  # fmt: skip
    return np.asarray(noise, dtype=float)


def read_twin(path: Path | str, arm: str) -> dict[str, dict[str, float]]:
    """The drive overrides of twin file ``path``, which must be of ``arm``; one line otherwise."""
    path = Path(path)
    overrides = _load(path, arm)["drive_overrides"]
    out = {}
    for joint in JOINT_NAMES:
        params = (overrides or {}).get(joint)
        if not isinstance(params, dict):
            raise InputError(f"{path}: key 'drive_overrides.{joint}': missing")
        out[joint] = {}
        for name in PARAMETERS:
            value = params.get(name)
            if not isinstance(value, (int, float)) or not value >= 0:
                raise InputError(f"{path}: key 'drive_overrides.{joint}.{name}': a number >= 0, "
                                 f"got {value!r}")  # fmt: skip
            out[joint][name] = float(value)
    return out


def twin_digest(path: Path | str) -> str:
    """Twelve hex digits of what twin file ``path`` sets in the physics (drives and noise)."""
    path = Path(path)
    try:
        content = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError):
        raise InputError(f"sim.twin: {path}: not a readable twin file") from None
    physics = {k: (content or {}).get(k) for k in ("drive_overrides", "effort_noise_nm")}
    return hashlib.sha256(json.dumps(physics, sort_keys=True).encode()).hexdigest()[:12]


def recorded_on(out: Path, done: Path, twin: Path | str) -> bool:
    """Whether folder ``out`` already holds a recording (its file ``done``) made on ``twin``, for
    the research scripts that record once and reuse. A recording marked with another twin (one
    identified again: other logs, another estimator) is refused in one line rather than reused;
    an unmarked one (made before recordings were marked) is taken as it is."""
    if not done.is_file():
        return False
    mark = out / TWIN_MARK
    if mark.is_file() and mark.read_text().strip() != twin_digest(twin):
        raise InputError(f"{out}: recorded on another twin than {twin}; move it aside to record "
                         "on this one")  # fmt: skip
    return True


def mark_recorded(out: Path, twin: Path | str) -> None:
    """Marks the recording in ``out`` as made on ``twin`` (see :func:`recorded_on`)."""
    atomic_write_text(out / TWIN_MARK, twin_digest(twin) + "\n")
