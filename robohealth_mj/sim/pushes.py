"""Pushes on the arm's links: an external force, as a hand or an obstacle gives, applied at a
point of a link for a while. Not a fault: no label marks it; the manifest lists it. It is what
the contact watch (:mod:`robohealth_mj.runtime.contact`) is tested on with known truth: the real
logs of a pushed arm say neither when nor where.

A push's force rises and falls over ``RAMP_S`` (smoothstep), as a hand's does, so the drives do
not ring as they would at a step. Force and point are in the link's own frame (its joint turns
about the frame's z axis through its origin), so a push keeps its meaning whatever the pose; they
are turned into the world frame at the start of each simulated chunk (a pushed arm that holds a
pose barely moves within one).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from robohealth_mj.common.errors import InputError
from robohealth_mj.schema import JOINT_NAMES

RAMP_S = 0.1


@dataclass(frozen=True)
class Push:
    """``force_n`` (N) on ``link`` (a body of the arm: ``shoulder_link`` ... ``wrist_3_link``,
    ``payload``) at ``point_m`` (m; None: the link's centre of mass), both in the link's frame,
    from ``at_s`` for ``for_s`` seconds of session time."""

    at_s: float
    for_s: float
    link: str
    force_n: tuple[float, ...]
    point_m: tuple[float, ...] | None = None


def read_pushes(entries: Sequence[dict], model: mujoco.MjModel) -> list[Push]:
    """The ``session.pushes`` entries as pushes; one line naming the entry and key otherwise."""
    out = []
    for k, entry in enumerate(entries):
        where = f"session.pushes[{k}]"
        try:
            point = entry.get("point_m")
            push = Push(float(entry["at_s"]), float(entry["for_s"]), str(entry["link"]),
                        tuple(float(f) for f in entry["force_n"]),
                        None if point is None else tuple(float(v) for v in point))  # fmt: skip
        except KeyError as exc:
            raise InputError(f"{where}: key {exc} missing (at_s, for_s, link, force_n)") from None
        except (AttributeError, TypeError, ValueError) as exc:
            raise InputError(f"{where}: {exc}") from None
        if len(push.force_n) != 3 or len(push.point_m or (0, 0, 0)) != 3:
            raise InputError(f"{where}: force_n and point_m are [x, y, z]")
        if push.for_s <= 0 or push.at_s < 0:
            raise InputError(f"{where}: needs at_s >= 0 and for_s > 0")
        if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, push.link) < 2:  # world, base
            links = [model.body(b).name for b in range(2, model.nbody)]
            raise InputError(f"{where}: link {push.link!r} is not one of {links}")
        out.append(push)
    return out


def joint_moving(model: mujoco.MjModel, link: str) -> str:
    """The joint that moves ``link``, the joint nearest a force on it (its parent's for a body
    without a joint of its own, such as the payload)."""
    body = model.body(link).id
    while body > 0:
        for name in JOINT_NAMES:
            if model.joint(f"{name}_joint").bodyid[0] == body:
                return name
        body = int(model.body_parentid[body])
    raise InputError(f"link {link!r} is moved by no joint of the arm")


def applied_forces(
    model: mujoco.MjModel, data: mujoco.MjData, pushes: Sequence[Push], step_times: np.ndarray
) -> np.ndarray:
    """``xfrc_applied`` for every physics step ``[S, nbody * 6]``: per body the force and the
    torque about its centre of mass, world frame, in the pose ``data`` holds."""
    out = np.zeros((len(step_times), model.nbody, 6))
    for push in pushes:
        t = step_times - push.at_s
        rise = np.clip(t / RAMP_S, 0.0, 1.0)
        fall = np.clip((push.for_s - t) / RAMP_S, 0.0, 1.0)
        gain = (rise * rise * (3 - 2 * rise)) * (fall * fall * (3 - 2 * fall))
        if not gain.any():
            continue
        body = model.body(push.link).id
        turn = data.xmat[body].reshape(3, 3)
        force = turn @ np.asarray(push.force_n)
        point = data.xipos[body] if push.point_m is None else (
            data.xpos[body] + turn @ np.asarray(push.point_m))  # fmt: skip
        wrench = np.concatenate([force, np.cross(point - data.xipos[body], force)])
        out[:, body] += gain[:, None] * wrench
    return out.reshape(len(step_times), -1)
