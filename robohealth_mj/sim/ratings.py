"""The arm's rated joint torques, read from the UR5e parameter file without building a model.

Light on purpose (no MuJoCo import): the on-line evaluation uses them to tell whether a faulted
joint carried load during an episode.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import yaml

from robohealth_mj.common.resources import asset_dir
from robohealth_mj.schema import JOINT_NAMES

PARAMETERS = asset_dir() / "ur5e" / "ur5e_parameters.yaml"


@lru_cache(maxsize=1)
def rated_torque_nm(path: Path | str = PARAMETERS) -> np.ndarray:
    """Rated peak torque (N m) per joint, in the schema's joint order."""
    params = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    drives = params["drives"]
    sizes = {link["joint"]["name"]: link["joint"]["size"] for link in params["links"]}
    return np.array([drives[sizes[j]]["torque_limit"] for j in JOINT_NAMES], np.float64)
