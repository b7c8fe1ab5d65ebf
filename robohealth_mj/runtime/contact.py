"""The contact watch: a push or a collision on an arm that holds a pose, from its torque residual.

Why a second detector beside the model: a push is no fault class, and a still joint shows no
fault (``observability=motion`` hides the model's calls there), yet a still arm is where an
external force is plainest. Holding a pose, the controller's own model torque (``effort -
effort_residual``) stays constant, so any change of the residual is a torque the model does not
know of: a force on a link (it loads that link's joint and every joint before it, none after:
the joint nearest the force is the most distal one loaded).

Per stream, per tick (vectorised over streams, no torch):

- *Quiet*: the controller's model torque within ``command_share`` of each joint's rated torque
  of its value when the quiet began, and every joint slower than ``still_rad_s``. A commanded
  move changes the model torque a tick or two before the joints pass any speed threshold (the
  real UR10e's logs), which keeps the friction breakaway at a move's start out of the watch; a
  push leaves the model torque where it was, but may move a compliant joint (the speed bound is
  loose for that: 0.3 rad/s).
- *Level*: each joint's residual, the median over the quiet's ticks from ``level_ticks`` to
  ``recent_ticks`` before now; the watch starts once the quiet has lasted ``settle_ticks``. A
  static-friction offset a push leaves behind becomes the level as it fills half that span.
  With ``exclude_contact`` the ticks over a threshold are left out of it (a long push does not
  become its own level), until every tick of the span was: what lasts that long is a new rest.
- *Contact*: a joint's residual more than its threshold off the level for ``confirm`` ticks in a
  row. The joint named: where the model carries the arm's chain and surface, the link a single
  push explains (:func:`robohealth_mj.arms.contact_place.place`: a push square on a joint's round
  housing does not load that joint, so the most distal joint loaded can fall short of it),
  placed when the contact is confirmed and again whenever its torques have grown half as large
  again; otherwise, or where no single push explains them, the most distal joint over its
  threshold.

The thresholds are the arm's, in N·m: commissioning replays its healthy running through the same
watch and takes ``margin`` times each joint's largest quiet deviation
(:func:`commission_thresholds`); the exported model carries them (``contact_threshold_nm``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.contact_place import ArmSurface, place
from robohealth_mj.arms.ratings import rated_torque_nm
from robohealth_mj.common.errors import InputError

_POS = schema.feature_index("pos")
_VEL = schema.feature_index("vel")
_EFFORT = schema.feature_index("effort")
_RESIDUAL = schema.feature_index("effort_residual")
REPLACE_GROWTH = 1.5  # a contact is placed again when its torques have grown this much


@dataclass(frozen=True)
class ContactPolicy:
    """How the watch reads a stream (ticks at the stream's rate; the defaults are for 20 Hz and
    were chosen on the real UR10e's program logs and first pushed log and on its twin pushed:
    ``studies/real_arms/results/contact.md``)."""

    enabled: bool = True
    still_rad_s: float = 0.3
    command_share: float = 0.005  # of each joint's rated torque
    settle_ticks: int = 25
    level_ticks: int = 60
    recent_ticks: int = 20
    confirm: int = 4
    exclude_contact: bool = False  # leave the ticks over a threshold out of the level

    def __post_init__(self) -> None:
        if not 0 < self.recent_ticks < self.settle_ticks <= self.level_ticks:
            raise ValueError(
                "contact needs 0 < recent_ticks < settle_ticks <= level_ticks, got "
                f"{self.recent_ticks}, {self.settle_ticks}, {self.level_ticks}"
            )
        if self.confirm < 1:
            raise ValueError(f"contact confirm must be at least 1 tick, got {self.confirm}")
        if self.still_rad_s <= 0 or self.command_share <= 0:
            raise ValueError("contact still_rad_s and command_share must be positive")


@dataclass(frozen=True)
class Placing:
    """What places a contact on a link: the arm's chain and surface, and each joint's noise
    (N·m; its largest quiet deviation on the healthy running), the chi-square's unit."""

    surface: ArmSurface
    noise_nm: np.ndarray

    def to_dict(self) -> dict:
        return {"surface": self.surface.to_dict(), "noise_nm": np.round(self.noise_nm, 4).tolist()}

    def __post_init__(self) -> None:
        if self.noise_nm.shape != (len(self.surface.axis),) or not (self.noise_nm > 0).all():
            raise ValueError(f"noise_nm must be one positive value per joint, got {self.noise_nm}")

    @classmethod
    def from_dict(cls, d: dict) -> Placing:
        return cls(ArmSurface.from_dict(d["surface"]), np.asarray(d["noise_nm"], np.float64))


def contact_metadata(meta: dict, source: str) -> tuple[np.ndarray, Placing | None] | None:
    """The thresholds ``[J]`` and placing an exported model carries (None: no contact watch;
    the placing None for models commissioned before 2026-11-27); an :class:`InputError` naming
    ``source`` and the key for a value that cannot be read, before any stream is watched."""
    if "contact_threshold_nm" not in meta:
        return None
    key = "contact_threshold_nm"
    try:
        threshold = np.asarray(json.loads(meta[key]), np.float64)
        joints = len(meta.get("joints") or schema.JOINT_NAMES)  # one per joint of the arm
        if threshold.shape != (joints,) or not (threshold > 0).all():
            raise ValueError(f"expected {joints} positive values, got {threshold.tolist()}")
        key = "contact_placing"
        placing = Placing.from_dict(json.loads(meta[key])) if meta.get(key) else None
    except (ValueError, KeyError, TypeError) as exc:  # JSON's decode error is a ValueError
        raise InputError(f"{source}: metadata '{key}' cannot be read: {exc}") from None
    return threshold, placing


class ContactBank:
    """The watch's state for every stream slot: a ring of recent residuals, the quiet's length
    and its model torque, the run of ticks over threshold, the contact's placement."""

    def __init__(
        self,
        policy: ContactPolicy,
        threshold_nm: np.ndarray,
        arm: str,
        capacity: int,
        placing: Placing | None = None,
    ) -> None:
        self.policy = policy
        self.placing = placing
        self.threshold = np.asarray(threshold_nm, np.float64).ravel()  # [J], the arm's joints
        self.joints = J = len(self.threshold)
        self.command_nm = policy.command_share * rated_torque_nm(arm)
        self.ring = np.zeros((capacity, policy.level_ticks, J), np.float32)
        self.skip = np.zeros((capacity, policy.level_ticks), bool)  # tick was over a threshold
        self.written = np.zeros(capacity, np.int64)  # ticks written into the ring
        self.quiet = np.zeros(capacity, np.int64)  # length of the current quiet
        self.held = np.zeros((capacity, J), np.float32)  # model torque when the quiet began
        self.over = np.zeros(capacity, np.int64)  # ticks over threshold in a row
        self.placed = np.full(capacity, -1, np.int64)  # the link the contact was placed on
        self.placed_size = np.zeros(capacity)  # the size of the torques it was placed with

    def ensure(self, capacity: int) -> None:
        for name in ("ring", "skip", "written", "quiet", "held", "over", "placed", "placed_size"):
            old = getattr(self, name)
            if capacity > len(old):
                new = np.full((capacity, *old.shape[1:]), -1 if name == "placed" else 0, old.dtype)
                new[: len(old)] = old
                setattr(self, name, new)

    def reset(self, slots: np.ndarray) -> None:
        """Forget these slots (a new stream, or a gap in one)."""
        self.written[slots], self.quiet[slots], self.over[slots] = 0, 0, 0
        self.placed[slots] = -1

    def deviation(self, slots: np.ndarray, x: np.ndarray) -> np.ndarray:
        """One raw snapshot per slot (distinct) ``x [B, 2J, F]`` -> how far each joint's residual
        is off its level ``[B, J]`` in N·m, NaN where the stream is not watched (moving, or not
        settled)."""
        return np.abs(self.offset(slots, x))

    def offset(self, slots: np.ndarray, x: np.ndarray) -> np.ndarray:
        """As :meth:`deviation`, with its sign: each joint's residual minus its level."""
        p, J = self.policy, self.joints
        vel, residual = x[:, :J, _VEL], x[:, :J, _RESIDUAL]
        model = x[:, :J, _EFFORT] - residual
        fresh = self.quiet[slots] == 0
        held = np.where(fresh[:, None], model, self.held[slots])
        quiet = (np.abs(vel) < p.still_rad_s).all(axis=1) & (
            np.abs(model - held) < self.command_nm
        ).all(axis=1)
        length = np.where(quiet, self.quiet[slots] + 1, 0)
        self.quiet[slots] = length
        self.held[slots] = np.where(quiet[:, None], held, model)
        at = self.written[slots] % p.level_ticks
        self.ring[slots, at], self.skip[slots, at] = residual, False
        self.written[slots] += 1
        off = np.full(residual.shape, np.nan)
        watched = np.flatnonzero(length >= p.settle_ticks)
        if not len(watched):
            return off
        s = slots[watched]
        ages = np.arange(p.recent_ticks, p.level_ticks)  # ticks before now
        rows = (self.written[s][:, None] - 1 - ages[None, :]) % p.level_ticks  # [W, A]
        flat = s[:, None] * p.level_ticks + rows  # one gather from the flattened ring
        past = self.ring.reshape(-1, J)[flat]  # [W, A, J]
        before = ages[None, :] >= length[watched][:, None]  # before the quiet began
        # with exclude_contact, ticks over a threshold are left out, unless that leaves none
        skipped = self.skip.reshape(-1)[flat] & p.exclude_contact
        left_out = before | (skipped & ~(before | skipped).all(axis=1, keepdims=True))
        past[left_out] = np.nan
        off[watched] = residual[watched] - _median(past).astype(np.float64)
        return off

    def update(self, slots: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One tick per slot -> ``(contact [B] bool, joint named [B], -1 when none)``."""
        off = np.nan_to_num(self.offset(slots, x), nan=0.0)
        over = np.abs(off) > self.threshold  # [B, J]
        hit = over.any(axis=1)
        self.skip[slots, (self.written[slots] - 1) % self.policy.level_ticks] = hit
        run = np.where(hit, self.over[slots] + 1, 0)
        self.over[slots] = run
        contact = run >= self.policy.confirm
        distal = self.joints - 1 - np.argmax(over[:, ::-1], axis=1)
        named = np.where(contact, distal, -1)
        if self.placing is not None:
            named = self._place(slots, x, off, contact, named)
        return contact, named

    def _place(
        self, slots: np.ndarray, x: np.ndarray, off: np.ndarray, contact: np.ndarray,
        distal: np.ndarray,
    ) -> np.ndarray:  # fmt: skip
        """The joints named where contacts are placed on links: placed on confirmation, and
        again once the torques have grown by ``REPLACE_GROWTH``; the most distal joint over its
        threshold where no single push explains them."""
        self.placed[slots[~contact]] = -1
        on = np.flatnonzero(contact)
        if not len(on):  # the usual tick: nothing to place
            return distal
        p = self.placing
        size = np.linalg.norm(off[on] / p.noise_nm, axis=1)
        again = (self.over[slots[on]] == self.policy.confirm) | (
            size >= REPLACE_GROWTH * self.placed_size[slots[on]]
        )
        joints = self.joints
        for b, grown in zip(on[again], size[again], strict=True):  # a contact's first tick, or
            where = place(p.surface, x[b, :joints, _POS], -off[b], p.noise_nm)  # a growing one
            self.placed[slots[b]], self.placed_size[slots[b]] = where.joint, grown
        placed = self.placed[slots]
        return np.where(contact & (placed >= 0), placed, distal)


def _median(values: np.ndarray) -> np.ndarray:
    """The median over axis 1 of ``[W, A, J]``, NaN left out (at least one value each): one
    sort for every stream, where ``np.nanmedian`` loops over them in Python, along a contiguous
    last axis (``[W, J, A]``), which sorts in about half the time of the middle one."""
    by_joint = np.ascontiguousarray(values.transpose(0, 2, 1))  # [W, J, A]
    count = (~np.isnan(by_joint)).sum(axis=2, keepdims=True)  # [W, J, 1]
    ordered = np.sort(by_joint, axis=2)  # NaN sorts last
    low = np.take_along_axis(ordered, (count - 1) // 2, axis=2)
    high = np.take_along_axis(ordered, count // 2, axis=2)
    return 0.5 * (low + high)[:, :, 0]


def quiet_deviations(
    runs: list[np.ndarray], arm: str, policy: ContactPolicy | None = None
) -> np.ndarray:
    """Each joint's largest quiet deviation ``[J]`` (N·m) over ``runs``, each a run of raw
    snapshots ``[T, 2J, F]`` in time order; NaN for a joint never watched."""
    policy = policy or ContactPolicy()
    J = runs[0].shape[1] // 2 if runs else schema.N_JOINTS
    worst = np.full(J, np.nan)
    for run in runs:
        bank = ContactBank(policy, np.full(J, np.inf), arm, 1)
        slot = np.zeros(1, np.int64)
        for tick in run:
            worst = np.fmax(worst, bank.deviation(slot, tick[None])[0])
    return worst


def commission_thresholds(
    runs: list[np.ndarray], arm: str, margin: float, policy: ContactPolicy | None = None
) -> tuple[np.ndarray | None, str]:
    """The contact thresholds (N·m) for an arm from its healthy running, and what was found.
    None where the running holds no quiet long enough to watch every joint."""
    policy = policy or ContactPolicy()
    worst = quiet_deviations(runs, arm, policy)
    if np.isnan(worst).any():
        return None, (
            f"no quiet of {policy.settle_ticks} ticks or more in the healthy running: "
            "the contact watch is left off"
        )
    return margin * worst, f"{margin} x the largest quiet deviation per joint"
