"""Rigid-body quantities of the arm that checks and the controller rely on."""

from __future__ import annotations

import copy
from functools import lru_cache

import mujoco
import numpy as np

from robohealth_mj.arms.description import DEFAULT_ARM
from robohealth_mj.sim.model import ArmIndex, build_model


@lru_cache(maxsize=8)
def nominal_model(arm: str) -> tuple[mujoco.MjModel, ArmIndex]:
    """The arm's compiled nominal model, built once (callers edit a ``copy.copy`` of it)."""
    model = build_model(arm)
    return model, ArmIndex.of(model)


def gravity_torques(q: np.ndarray, payload_kg: float = 0.0, arm: str = DEFAULT_ARM) -> np.ndarray:
    """Joint torques (N m, UR sign convention) that hold the arm still at pose ``q``.

    The payload is a point mass of ``payload_kg`` at the tool flange.
    """
    q = np.asarray(q, dtype=float)
    model, index = nominal_model(arm)
    if q.shape != index.actuator.shape:
        raise ValueError(f"q must have shape {index.actuator.shape} on the {arm}, got {q.shape}")
    if payload_kg < 0:
        raise ValueError(f"payload_kg must be >= 0, got {payload_kg}")
    local = copy.copy(model)  # the cached nominal model is never edited
    local.body_mass[index.payload_body] = payload_kg
    data = mujoco.MjData(local)
    index.set_link_pose(data, q)
    mujoco.mj_forward(local, data)
    return data.qfrc_bias[index.motor_dof].copy()
