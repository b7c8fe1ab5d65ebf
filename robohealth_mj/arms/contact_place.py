"""Which link a push is on, from the joint torques it leaves: a force fit on the arm's kinematics.

Why a fit and not only the most distal joint loaded: a force on a link loads that link's joint
only through its lever about the joint's axis. A hand pressing square on a joint's round housing
pushes through that axis, so it loads the joints before it and not that one: the most distal
joint loaded is a lower bound on where the push is. The joints before it still say where: one
force ``F`` at a point ``p`` of a link gives the joint torques ``tau_j = (a_j x (p - c_j)) . F``
for the joints ``j`` that move the link (axis ``a_j`` through ``c_j``), zero beyond. Per link,
at each point of its collision surface, this fits a force inside the friction cone there
(non-negative weights on the cone's edges, as contact-particle filters do), so the force's line
meets the link near that point, with a mild cost on forces beyond a hand's. The best point is
scored by chi-square in units of each joint's noise; the link named is the most proximal one
whose best point explains the torques to within ``accept``.

numpy only: the streaming runtime runs it (:mod:`robohealth_mj.runtime.contact`). The arm's
chain and surface (:class:`ArmSurface`) come from its MuJoCo model when a commissioned model is
exported (:func:`robohealth_mj.sim.contact_surface.arm_surface`) and travel in that model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FRICTION = 0.5  # the friction cone's half-angle tangent
CONE_EDGES = 8
FORCE_SCALE_N = 150.0  # a hand's push: a force this size adds about 1 to chi-square
ACCEPT = 1.0  # chi-square a placement may leave (chosen on the twin: contact_where.md)
ITERATIONS = 150  # of the accelerated projected gradient that solves the cone fit
SHORTLIST = 24  # points per link fitted first


@dataclass(frozen=True)
class ArmSurface:
    """A serial arm's chain and collision surface, in each joint's body frame.

    ``offset_pos [J, 3]``, ``offset_rot [J, 3, 3]``: each joint's body in the one before (the
    first in the base); ``anchor [J, 3]``, ``axis [J, 3]``: the joint in its body; ``link [P]``:
    which joint's body each surface point is on, ``point [P, 3]``, ``normal [P, 3]`` (outward)
    in that body's frame."""

    offset_pos: np.ndarray
    offset_rot: np.ndarray
    anchor: np.ndarray
    axis: np.ndarray
    link: np.ndarray
    point: np.ndarray
    normal: np.ndarray

    def to_dict(self) -> dict[str, list]:
        return {k: np.round(v, 6).tolist() for k, v in self.__dict__.items()}

    def __post_init__(self) -> None:
        """A surface that does not fit its chain would fail mid-stream, at a contact: say so
        when it is built."""
        j, p = len(self.offset_pos), len(self.link)
        shapes = {"offset_pos": (j, 3), "offset_rot": (j, 3, 3), "anchor": (j, 3),
                  "axis": (j, 3), "point": (p, 3), "normal": (p, 3)}  # fmt: skip
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise ValueError(f"{name} has shape {getattr(self, name).shape}, expected {shape}")
        if self.link.ndim != 1 or not p or self.link.min() < 0 or self.link.max() >= j:
            raise ValueError(f"link must name joints 0..{j - 1} for each surface point")

    @classmethod
    def from_dict(cls, d: dict[str, list]) -> ArmSurface:
        return cls(**{k: np.asarray(d[k], np.int64 if k == "link" else np.float64)
                      for k in cls.__dataclass_fields__})  # fmt: skip

    def pose(self, q: np.ndarray) -> tuple[np.ndarray, ...]:
        """At joint angles ``q [J]``: each body's position ``[J, 3]`` and rotation ``[J, 3, 3]``
        in the base, each joint's axis and a point on it ``[J, 3]``."""
        pos, rot = np.zeros(3), np.eye(3)
        positions, rotations, axes, anchors = [], [], [], []
        for j, angle in enumerate(np.asarray(q, np.float64)):
            pos, rot = pos + rot @ self.offset_pos[j], rot @ self.offset_rot[j]
            anchor, axis = pos + rot @ self.anchor[j], rot @ self.axis[j]
            turn = _rotation(self.axis[j], angle)
            pos, rot = anchor - rot @ turn @ self.anchor[j], rot @ turn
            positions.append(pos)
            rotations.append(rot)
            axes.append(axis)
            anchors.append(anchor)
        return np.array(positions), np.array(rotations), np.array(axes), np.array(anchors)

    def lever(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """At ``q``: per surface point the map from a force to the joint torques ``[P, J, 3]``
        (zero rows for the joints beyond its link) and its outward normal ``[P, 3]``, both in
        the base frame."""
        positions, rotations, axes, anchors = self.pose(q)
        rot = rotations[self.link]
        where = positions[self.link] + np.einsum("pij,pj->pi", rot, self.point)
        normal = np.einsum("pij,pj->pi", rot, self.normal)
        arm = where[:, None, :] - anchors[None, :, :]  # [P, J, 3]
        lever = np.cross(axes[None, :, :], arm)  # tau_j = lever_j . F
        joints = np.arange(len(axes))
        lever[joints[None, :] > self.link[:, None]] = 0.0
        return lever, normal


@dataclass(frozen=True)
class Placement:
    """The best single push per link (chi-square ``[J]``, the force at its best point, N, base
    frame ``[J, 3]``), and the link named: the joint moving it, -1 when no push explains."""

    chi2: np.ndarray
    force_n: np.ndarray
    joint: int


def place(
    surface: ArmSurface, q: np.ndarray, torque_nm: np.ndarray, noise_nm: np.ndarray,
    accept: float = ACCEPT,
) -> Placement:  # fmt: skip
    """Place the push that gives the external joint torques ``torque_nm [J]`` at ``q [J]``. A
    holding drive answers a push with the opposite torque: this is minus the torque residual's
    change. ``noise_nm [J]`` weighs each joint's misfit.

    The cone fit runs first on each link's ``SHORTLIST`` points that a cheaper fit (any force
    direction, a lighter cost: never more than the cone fit's chi-square) rates best, then on
    any other point whose cheap bound still beats its link's best: the same answer as fitting
    every point, in a fraction of the time."""
    lever, normal = surface.lever(q)
    scale = 1.0 / np.asarray(noise_nm, np.float64)
    lever = lever * scale[None, :, None]  # [P, J, 3]
    target = np.asarray(torque_nm, np.float64) * scale
    bound = _free_chi2(lever, target)
    members = [np.flatnonzero(surface.link == j) for j in range(len(surface.axis))]  # per link
    chi2 = np.full(len(bound), np.inf)
    force = np.zeros((len(bound), 3))
    todo = np.concatenate([m[np.argsort(bound[m])][:SHORTLIST] for m in members])
    while len(todo):
        edges = cone(normal[todo])  # [T, 3, E]
        prior = np.broadcast_to(np.eye(CONE_EDGES) / FORCE_SCALE_N, (len(todo), CONE_EDGES, 8))
        system = np.concatenate([np.einsum("pjk,pke->pje", lever[todo], edges), prior], axis=1)
        weights, chi2[todo] = nonnegative_least_squares(
            system, np.concatenate([target, np.zeros(CONE_EDGES)])
        )
        force[todo] = np.einsum("pke,pe->pk", edges, weights)
        best = np.array([chi2[m].min() for m in members])
        todo = np.flatnonzero(np.isinf(chi2) & (bound < best[surface.link]))
    best_point = [m[np.argmin(chi2[m])] for m in members]
    fits = np.flatnonzero(chi2[best_point] <= accept)
    return Placement(chi2[best_point], force[best_point], int(fits[0]) if len(fits) else -1)


def _free_chi2(lever: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``[P]`` a lower bound on each point's cone fit: any force direction, and the force's cost
    at an eighth (8 unit edges' weights square-sum to at least an eighth of the force's)."""
    ridge = np.eye(3) / (CONE_EDGES * FORCE_SCALE_N**2)
    gram = np.einsum("pjk,pjl->pkl", lever, lever) + ridge
    force = np.linalg.solve(gram, np.einsum("pjk,j->pk", lever, target)[:, :, None])[:, :, 0]
    misfit = np.einsum("pjk,pk->pj", lever, force) - target
    return np.einsum("pj,pj->p", misfit, misfit) + np.einsum("pk,kl,pl->p", force, ridge, force)


def cone(normal: np.ndarray) -> np.ndarray:
    """``[P, 3, CONE_EDGES]`` the unit edges of the friction cone of a push into a surface of
    outward unit ``normal [P, 3]``."""
    t1, t2 = tangents(normal)
    angles = np.linspace(0.0, 2 * np.pi, CONE_EDGES, endpoint=False)
    across = t1[:, :, None] * np.cos(angles) + t2[:, :, None] * np.sin(angles)
    edges = -normal[:, :, None] + FRICTION * across
    return edges / np.linalg.norm(edges, axis=1, keepdims=True)


def tangents(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors across each unit ``normal [P, 3]``, square to it and to each other."""
    helper = np.where(np.abs(normal[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = np.cross(normal, helper)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return t1, np.cross(normal, t1)


def nonnegative_least_squares(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``min |a_p x - b|^2, x >= 0`` for every ``a_p`` of ``a [P, M, N]`` at once: the
    solutions ``[P, N]`` and the squared residuals ``[P]``. Accelerated projected gradient
    (FISTA) with the step from each problem's largest curvature; small problems (N = 8) converge
    within ``ITERATIONS`` to well under the chi-square's resolution here (tested against
    :func:`scipy.optimize.nnls`)."""
    gram = np.einsum("pmi,pmj->pij", a, a)
    pull = np.einsum("pmi,m->pi", a, b)
    step = 1.0 / np.linalg.eigvalsh(gram)[:, -1:]
    x = y = np.zeros(pull.shape)
    t = 1.0
    for _ in range(ITERATIONS):
        grad = np.einsum("pij,pj->pi", gram, y) - pull
        nxt = np.maximum(y - step * grad, 0.0)
        t_next = 0.5 * (1.0 + np.sqrt(1.0 + 4.0 * t * t))
        y = nxt + ((t - 1.0) / t_next) * (nxt - x)
        x, t = nxt, t_next
    residual = np.einsum("pmi,pi->pm", a, x) - b
    return x, np.einsum("pm,pm->p", residual, residual)


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the unit ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)
