"""Where the configs and assets that ship inside the package are, found through
``importlib.resources`` so that an installed wheel works from any directory (never a path
relative to the source tree)."""

from __future__ import annotations

import os
from functools import cache
from importlib.resources import files
from pathlib import Path

CONF_PACKAGE = "robohealth_mj.conf"
ASSETS_PACKAGE = "robohealth_mj.assets"
HYDRA_CONF = f"pkg://{CONF_PACKAGE}"  # ``@hydra.main(config_path=...)`` of every Hydra entry point


@cache
def conf_dir() -> Path:
    """The packaged ``conf/`` folder."""
    return Path(str(files(CONF_PACKAGE)))


def asset_dir() -> Path:
    """The packaged ``assets/`` folder, or ``$ROBOHEALTH_ASSETS`` where a user points elsewhere."""
    override = os.environ.get("ROBOHEALTH_ASSETS")
    return Path(override) if override else Path(str(files(ASSETS_PACKAGE)))


READY_PACKAGE = "robohealth_mj.ready_models"


def ready_dir() -> Path:
    """The packaged ready models (``ready_models/``: exported models, their cards, a sample)."""
    return Path(str(files(READY_PACKAGE)))


def is_arm_file(name: str) -> bool:
    """Whether ``name`` names a user's arm file (a URDF) rather than an arm of ``assets/``; such
    an arm's name is the file's absolute path, so it reads back the same from every file and
    directory it is named in."""
    return str(name).endswith(".urdf")
