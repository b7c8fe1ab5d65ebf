"""Shared fixtures: configs composed the way the entry points compose them, on tiny sizes."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering; must precede importing mujoco

import pytest

from robohealth_mj.config import compose_config
from robohealth_mj.sim.model import build_model


@pytest.fixture(scope="session")
def model():
    return build_model()


@pytest.fixture
def record_cfg():
    """``conf/record.yaml`` composed with overrides; progress bars off."""

    def make(*overrides: str):
        return compose_config("record", ["session.progress=false", *overrides])

    return make
