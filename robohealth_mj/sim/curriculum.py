"""The trajectory curriculum (thesis §2.3.2): sweeps, coordinated pairs and whole-arm motion;
and, for probing programs unlike those, pick-and-place and palletising cycles as taught on a
pendant (point-to-point moves with dwells, family ``pick_place``); and holds (family ``hold``: one
move from rest to a new pose, then the arm holds it, as a real arm spends much of its day); and
cruising moves (family ``cruise``: long joint moves as a UR controller runs them, every joint
accelerating, holding a constant speed and braking together, the way real point-to-point programs
move). The last three are not in the default families.

Speed scales multiply the base excitation frequency; payload scales multiply a nominal payload.
Segments are shuffled per pass by the session seed. Each segment starts at the previous segment's
rest pose and ends at rest at its own centre pose, so the reference is smooth (C2) across segments.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np

from robohealth_mj.arms.description import DEFAULT_ARM, ArmDescription, load_arm
from robohealth_mj.common.errors import InputError
from robohealth_mj.common.seeds import stream
from robohealth_mj.schema import JOINT_NAMES

FAMILIES = ("single_joint", "joint_pair", "whole_arm", "pick_place", "hold", "cruise")
WAVEFORMS = ("sine", "triangle", "compound")
SWEEPS = ("single_joint", "joint_pair", "whole_arm")  # the families that sweep about a centre
TASKS = ("pick_place", "palletise")  # the pick_place family's programs
LEG_S = 0.8  # the shortest point-to-point move at speed scale 1, s
JOINT_SPEED = 1.0  # rad/s: the fastest joint's peak speed in a move at speed scale 1 (a UR5e's)
LIFT_RAD = (0.0, -0.25, 0.35, -0.1, 0.0, 0.0)  # from a pick or place pose to above it
# Family cruise, after a real UR10e's point-to-point program
# (studies/real_arms/results/moves.md): the
# leading joint reaches 0.70 rad/s in 0.72 s, cruises 1.0-5.6 s, brakes alike, and the next move
# starts 0.04-0.06 s after the last one stops. The ramp here, 0.67 s, was read off the log's row
# count before its dropped rows were noticed: 7 % steeper than the arm's, kept because every
# cruise corpus measured so far was recorded with it.
CRUISE_SPEED = 0.7  # rad/s, the leading joint's cruise at speed scale 1
CRUISE_RAMP_S = 0.67  # s, from rest to cruise (and back), at every speed scale
CRUISE_DWELL_S = 0.1  # s, between the two moves of a segment
CRUISE_STROKE_RAD = (1.5, 0.3, 0.5, 1.0, 1.2, 2.0)  # the via pose: centre + U(-1, 1) x this
CRUISE_REPEATS = 3  # default segments per speed and payload (each visit draws its own via pose)


def _raw_waveform(name: str, phi: np.ndarray) -> np.ndarray:
    if name == "sine":
        return np.sin(phi)
    if name == "triangle":  # a triangle with rounded turns, so acceleration stays bounded
        return (2.0 / np.pi) * np.arcsin(0.92 * np.sin(phi))
    if name == "compound":
        return np.sin(phi) + 0.35 * np.sin(2.0 * phi + np.pi / 4)
    raise InputError(f"unknown waveform {name!r}; known: {WAVEFORMS}")


@cache
def _slope_norm(name: str) -> float:
    """Largest |dw/dphi| of a raw waveform, so every normalised waveform has unit peak slope."""
    phi = np.linspace(0.0, 2.0 * np.pi, 20001)
    return float(np.max(np.abs(np.gradient(_raw_waveform(name, phi), phi))))


def waveform(name: str, phi: np.ndarray) -> np.ndarray:
    """Periodic waveform with w(0) = 0 and peak slope 1 (peak speed = amplitude * 2 pi f)."""
    return _raw_waveform(name, phi) / _slope_norm(name)


@cache
def _excursion(name: str, phase: float) -> float:
    """Largest ``|w(theta + phase) - w(phase)|`` over a period: how far a sweep started at
    ``phase`` swings from its centre, per unit amplitude (a sine at a quarter-period offset
    swings 2 one way, not 1 either way)."""
    theta = np.linspace(0.0, 2.0 * np.pi, 4001)
    return float(np.max(np.abs(waveform(name, theta + phase) - waveform(name, np.array(phase)))))


def smoothstep(u: np.ndarray) -> np.ndarray:
    """The quintic from 0 to 1 on [0, 1] with zero slope and curvature at both ends."""
    u = np.clip(u, 0.0, 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def _smoothstep_integral(u: np.ndarray) -> np.ndarray:
    """The integral of ``smoothstep`` from 0 to ``u`` (0.5 at 1)."""
    u = np.clip(u, 0.0, 1.0)
    return u**4 * (2.5 + u * (-3.0 + u))


def cruise_profile(u: np.ndarray, ramp: float) -> np.ndarray:
    """Progress from 0 to 1 over normalised time ``u`` in [0, 1]: speed rises along a smoothstep
    for the first ``ramp`` of the move (at most 0.5), holds constant, and falls alike; an S-curve
    version of a controller's trapezoidal profile, C2 so the reference stays smooth."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    top = 1.0 / (1.0 - ramp)  # the cruise speed that covers the distance in unit time

    def rising(x: np.ndarray) -> np.ndarray:
        return top * np.where(
            x < ramp, ramp * _smoothstep_integral(x / ramp), 0.5 * ramp + x - ramp
        )

    return np.where(u <= 0.5, rising(u), 1.0 - rising(1.0 - u))


def cruise_timing(distance: np.ndarray, speed: float) -> tuple[float, float]:
    """A synchronised joint move's duration (s) and ramp share: each joint's time at ``speed``
    with ``CRUISE_RAMP_S`` ramps (a short move never reaches ``speed``: the same acceleration, no
    cruise), and every joint follows the slowest one's profile, so all start and stop together."""
    distance = np.abs(np.asarray(distance, dtype=float))
    cruising = distance >= speed * CRUISE_RAMP_S
    # short moves: peak speed sqrt(d v / t_r), reached after d / peak, braking as long
    short = 2.0 * np.sqrt(distance * CRUISE_RAMP_S / speed)
    duration = np.where(cruising, CRUISE_RAMP_S + distance / speed, short)
    lead = int(np.argmax(duration))
    total = float(duration[lead])
    if total <= 0.0:
        return 0.0, 0.5
    return total, (CRUISE_RAMP_S / total if cruising[lead] else 0.5)


@dataclass(frozen=True)
class Segment:
    """One curriculum entry (its ``index`` is its place in the unshuffled enumeration)."""

    index: int
    family: str
    waveform: str
    joints: tuple[int, ...]
    speed_scale: float
    payload_scale: float


@dataclass(frozen=True)
class ScheduledSegment:
    """A segment as visited in a session: where it starts, where it comes to rest, when."""

    visit: int
    segment: Segment
    start_pose: np.ndarray
    center: np.ndarray
    t_start: float


class Curriculum:
    """Enumerates the curriculum and serves the session's reference trajectory."""

    def __init__(
        self,
        speed_scales: Sequence[float],
        payload_scales: Sequence[float],
        payload_fraction: float,
        base_frequency_hz: float,
        segment_s: float,
        blend_s: float,
        amplitude_rad: Sequence[float],
        pair_amplitude_factor: float,
        whole_arm_amplitude_factor: float,
        center_jitter_rad: Sequence[float],
        home: Sequence[float],
        payload_ramp_s: float = 1.0,
        families: Sequence[str] = FAMILIES,
        seed: int = 0,
        reference_speed_rad_s: float = np.pi,
        rated_payload_kg: float | None = None,
        speed_limit_rad_s: Sequence[float] | None = None,
        cruise_repeats: int = CRUISE_REPEATS,
        arm: ArmDescription | None = None,
    ) -> None:
        """``payload_fraction`` of the arm's rated payload is the nominal payload the payload
        scales multiply; ``amplitude_rad`` is for a joint whose speed limit is
        ``reference_speed_rad_s``, and each joint's scales with its own limit over that, so every
        arm moves at the same fraction of its limits (arm defaults: the UR5e's).

        The per-joint values (``amplitude_rad``, ``center_jitter_rad``, ``home``) are the UR's
        six; on an ``arm`` of other joints each joint takes its UR counterpart's
        (``arm.ur_counterparts()``) and the arm's own home, unless J values are given. Where a
        joint's range is limited, its sweep and jitter shrink to fit 90 % of it."""
        if not speed_scales or not payload_scales:
            raise InputError("curriculum needs at least one speed scale and one payload scale")
        if segment_s < 2.0 * blend_s:
            raise InputError(f"segment_s ({segment_s}) must be >= 2 * blend_s ({blend_s})")
        description = load_arm(DEFAULT_ARM) if arm is None else arm
        self.n_joints = description.n_joints
        self._counterparts = description.ur_counterpart_index()
        amplitude_rad = self._per_joint("amplitude_rad", amplitude_rad)
        center_jitter_rad = self._per_joint("center_jitter_rad", center_jitter_rad)
        own_home = description.joint_keys != JOINT_NAMES and len(home) != self.n_joints
        home = description.home_pose() if own_home else self._per_joint("home", home)
        self.speed_scales = [float(s) for s in speed_scales]
        self.payload_scales = [float(p) for p in payload_scales]
        rated = description.payload_kg if rated_payload_kg is None else float(rated_payload_kg)
        limits = description.speed_limit if speed_limit_rad_s is None else speed_limit_rad_s
        if not 0.0 < payload_fraction <= 1.0:
            raise InputError(f"curriculum.payload_fraction: in (0, 1], got {payload_fraction}")
        if len(limits) != self.n_joints or not reference_speed_rad_s > 0:
            raise InputError("curriculum: speed limits need one positive value per joint")
        self.nominal_payload_kg = float(payload_fraction) * rated
        self.speed_ratio = np.asarray(limits, dtype=float) / float(reference_speed_rad_s)
        self.base_frequency_hz = float(base_frequency_hz)
        self.segment_s = float(segment_s)
        self.blend_s = float(blend_s)
        self.amplitude = np.asarray(amplitude_rad, dtype=float)  # scaled below, once limits known
        self.pair_factor = float(pair_amplitude_factor)
        self.whole_factor = float(whole_arm_amplitude_factor)
        self.jitter = np.asarray(center_jitter_rad, dtype=float)
        self.home = np.asarray(home, dtype=float)
        if not 0.0 <= payload_ramp_s <= blend_s:
            raise InputError(f"payload_ramp_s ({payload_ramp_s}) must be in [0, blend_s]")
        self.payload_ramp_s = float(payload_ramp_s)
        self.amplitude = self.amplitude * self.speed_ratio
        self.lift = self._per_joint("lift", LIFT_RAD)  # pick and place: above the part
        self.stroke = self._per_joint("stroke", CRUISE_STROKE_RAD)  # cruise: the via pose's reach
        unknown = sorted(set(families) - set(FAMILIES))
        if unknown or not families:
            raise InputError(f"curriculum.families must be a non-empty subset of {FAMILIES}")
        self.families = tuple(families)
        if int(cruise_repeats) < 1:
            raise InputError(f"curriculum.cruise_repeats must be at least 1, got {cruise_repeats}")
        self.cruise_repeats = int(cruise_repeats)
        self.seed = int(seed)
        self.segments = self._enumerate()
        self._fit_ranges(description.position_limit)
        self._cache: dict[int, ScheduledSegment] = {}

    def _per_joint(self, name: str, values: Sequence[float]) -> np.ndarray:
        """``values`` for this arm's joints: J of them as given, the UR's six by counterpart."""
        vec = np.asarray(values, dtype=float)
        if len(vec) == self.n_joints:
            return vec
        if len(vec) == len(JOINT_NAMES):
            return vec[self._counterparts]
        raise InputError(
            f"curriculum.{name} needs {self.n_joints} values (or the UR's six), got {len(vec)}"
        )

    def _fit_ranges(self, position_limit: np.ndarray) -> None:
        """Shrink each limited joint's sweep and jitter so that its farthest swing from the home
        (the jitter plus the largest excursion of any sweep it takes part in) fits 90 % of the
        room between the home and its nearer limit (a UR's +-360 deg joints keep theirs)."""
        reach = np.zeros(self.n_joints)  # per unit amplitude
        for segment in self.segments:
            if segment.family not in SWEEPS:
                continue  # pick_place, hold and cruise move between poses
            factor, phase = self._family_factor(segment.family), self._phase(segment)
            for j in segment.joints:
                reach[j] = max(reach[j], factor * _excursion(segment.waveform, float(phase[j])))
        need = reach * self.amplitude + self.jitter
        low, high = position_limit[:, 0], position_limit[:, 1]
        room = 0.9 * np.minimum(self.home - low, high - self.home)
        room = np.where(np.isfinite(room), room, np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            factor = np.where(need > room, room / need, 1.0)
        self.amplitude = self.amplitude * factor
        self.jitter = self.jitter * factor

    def _enumerate(self) -> list[Segment]:
        speeds, payloads = self.speed_scales, self.payload_scales
        out: list[Segment] = []
        for joint, speed, payload in itertools.product(range(self.n_joints), speeds, payloads):
            out.append(Segment(len(out), "single_joint", "sine", (joint,), speed, payload))
        pairs = list(itertools.combinations(range(self.n_joints), 2))
        for (p, pair), (s, speed) in itertools.product(enumerate(pairs), enumerate(speeds)):
            payload = payloads[(p + s) % len(payloads)]
            out.append(Segment(len(out), "joint_pair", "sine", pair, speed, payload))
        for wave, speed, payload in itertools.product(WAVEFORMS, speeds, payloads):
            out.append(
                Segment(len(out), "whole_arm", wave, tuple(range(self.n_joints)), speed, payload)
            )
        for task, speed, payload in itertools.product(TASKS, speeds, payloads):
            out.append(
                Segment(len(out), "pick_place", task, tuple(range(self.n_joints)), speed, payload)
            )
        for speed, payload in itertools.product(speeds, payloads):
            out.append(
                Segment(len(out), "hold", "rest", tuple(range(self.n_joints)), speed, payload)
            )
        for _, speed, payload in itertools.product(range(self.cruise_repeats), speeds, payloads):
            out.append(
                Segment(len(out), "cruise", "movej", tuple(range(self.n_joints)), speed, payload)
            )
        return [s for s in out if s.family in self.families]

    def __len__(self) -> int:
        return len(self.segments)

    def _order(self, pass_index: int) -> np.ndarray:
        return stream("curriculum.order", self.seed, pass_index).permutation(len(self.segments))

    def scheduled(self, visit: int) -> ScheduledSegment:
        """The ``visit``-th segment of the session (passes reshuffle; random access is cheap)."""
        if visit not in self._cache:
            n = len(self.segments)
            segment = self.segments[int(self._order(visit // n)[visit % n])]
            rng = stream("curriculum.segment", self.seed, visit)
            center = self.home + rng.uniform(-1.0, 1.0, self.n_joints) * self.jitter
            start = self.home if visit == 0 else self.scheduled(visit - 1).center
            self._cache[visit] = ScheduledSegment(
                visit, segment, start, center, visit * self.segment_s
            )
            self._cache.pop(visit - 2, None)
        return self._cache[visit]

    def visit_at(self, t: float) -> int:
        return int(np.floor(t / self.segment_s + 1e-9))

    def payload_kg(self, visit: int) -> float:
        return self.nominal_payload_kg * self.scheduled(visit).segment.payload_scale

    def waypoints(self, visit: int) -> np.ndarray:
        """A pick_place segment's poses ``[K, J]``, from its start to its centre: over the pick,
        down, up, over the place (a palletising layer's next cell), down, up, centre."""
        sched = self.scheduled(visit)
        rng = stream("curriculum.pick_place", self.seed, visit)
        pick = sched.center + rng.uniform(-0.4, 0.4, self.n_joints) * self.amplitude
        if sched.segment.waveform == "palletise":  # cells of a 3 x 2 layer, in turn
            cell = visit % 6
            offset = np.zeros(self.n_joints)  # the base turns to the cell, the shoulder reaches
            offset[:2] = 0.5 + 0.2 * (cell % 3), 0.1 * (cell // 3)
            place = self.home + offset
        else:
            place = sched.center + rng.uniform(-0.4, 0.4, self.n_joints) * self.amplitude
        lift = self.lift
        return np.stack(
            [sched.start_pose, pick + lift, pick, pick + lift, place + lift, place, place + lift,
             sched.center]
        )  # fmt: skip

    def _point_to_point(self, visit: int, tau: np.ndarray) -> np.ndarray:
        """Quintic moves between the waypoints with equal dwells between them (a taught program:
        each move starts and stops at rest, so the reference stays C2)."""
        poses = self.waypoints(visit)
        speed = self.scheduled(visit).segment.speed_scale
        # a quintic's peak speed is 1.875 x distance / duration (each joint's own share of it)
        span = (np.abs(np.diff(poses, axis=0)) / self.speed_ratio).max(axis=1)
        legs = np.maximum(LEG_S, 1.875 * span / JOINT_SPEED) / speed
        legs *= min(1.0, 0.9 * self.segment_s / legs.sum())  # a program fits its segment
        dwell = (self.segment_s - legs.sum()) / (len(legs) + 1)
        out = np.repeat(poses[:1], len(tau), axis=0)
        t0 = dwell
        for k, leg in enumerate(legs):
            u = smoothstep((tau[:, 0] - t0) / leg)[:, None]
            out = out + (poses[k + 1] - poses[k]) * u
            t0 += leg + dwell
        return out

    def via_pose(self, visit: int) -> np.ndarray:
        """A cruise segment's turning pose ``[J]``: its centre plus a seeded draw within
        ``CRUISE_STROKE_RAD``, so the two moves (start to via, via to centre) are long; drawn in
        towards the midpoint of start and centre until both moves fit 95 % of the segment."""
        sched = self.scheduled(visit)
        rng = stream("curriculum.cruise", self.seed, visit)
        via = sched.center + rng.uniform(-1.0, 1.0, self.n_joints) * self._per_joint(
            "stroke", CRUISE_STROKE_RAD
        )
        middle = 0.5 * (sched.start_pose + sched.center)
        while sum(d for d, _ in self._cruise_timings(visit, via)) > self._cruise_room():
            via = middle + 0.9 * (via - middle)
        return via

    def _cruise_room(self) -> float:
        return 0.95 * self.segment_s - CRUISE_DWELL_S

    def _cruise_timings(self, visit: int, via: np.ndarray) -> list[tuple[float, float]]:
        sched = self.scheduled(visit)
        speed = CRUISE_SPEED * sched.segment.speed_scale
        return [
            cruise_timing(via - sched.start_pose, speed),
            cruise_timing(sched.center - via, speed),
        ]

    def _cruise(self, visit: int, tau: np.ndarray) -> np.ndarray:
        """Two synchronised joint moves at the segment's cruise speed, start to via to centre,
        ``CRUISE_DWELL_S`` apart, then at rest."""
        sched = self.scheduled(visit)
        via = self.via_pose(visit)
        poses = np.stack([sched.start_pose, via, sched.center])
        out = np.repeat(poses[:1], len(tau), axis=0)
        t0 = 0.0
        for k, (duration, ramp) in enumerate(self._cruise_timings(visit, via)):
            if duration > 0.0:
                u = cruise_profile((tau[:, 0] - t0) / duration, ramp)[:, None]
                out = out + (poses[k + 1] - poses[k]) * u
            t0 += duration + CRUISE_DWELL_S
        return out

    def _family_factor(self, family: str) -> float:
        """A sweeping family's amplitude, as a fraction of a single joint's sweep."""
        return {"single_joint": 1.0, "joint_pair": self.pair_factor,
                "whole_arm": self.whole_factor}[family]  # fmt: skip

    def _amplitude(self, segment: Segment) -> np.ndarray:
        amp = np.zeros(self.n_joints)
        if segment.family in SWEEPS:  # pick_place's motion is its waypoints
            idx = list(segment.joints)
            amp[idx] = self.amplitude[idx] * self._family_factor(segment.family)
        return amp

    def _phase(self, segment: Segment) -> np.ndarray:
        phase = np.zeros(self.n_joints)
        if segment.family == "joint_pair":
            phase[segment.joints[1]] = np.pi / 2
        elif segment.family == "whole_arm":
            phase[:] = np.arange(self.n_joints) * np.pi / 3
        return phase

    def position(self, visit: int, t: np.ndarray) -> np.ndarray:
        """Reference link angles ``[len(t), J]`` at session times ``t`` within one visit."""
        sched = self.scheduled(visit)
        seg = sched.segment
        tau = np.asarray(t, dtype=float)[:, None] - sched.t_start
        if seg.family == "pick_place":
            return self._point_to_point(visit, tau)
        if seg.family == "cruise":
            return self._cruise(visit, tau)
        if seg.family == "hold":  # one move, blend_s long at speed scale 1, then the pose held
            move = smoothstep(tau * seg.speed_scale / self.blend_s)
            return sched.start_pose + (sched.center - sched.start_pose) * move
        blend = smoothstep(tau / self.blend_s)
        envelope = blend * smoothstep((self.segment_s - tau) / self.blend_s)
        omega = 2.0 * np.pi * self.base_frequency_hz * seg.speed_scale
        # Subtracting each joint's value at its phase offset keeps the motion zero at rest, so the
        # envelope alone shapes the start and the stop.
        phase = self._phase(seg)
        shape = waveform(seg.waveform, omega * tau + phase) - waveform(seg.waveform, phase)
        moving = self._amplitude(seg) * envelope * shape
        return sched.start_pose + (sched.center - sched.start_pose) * blend + moving

    def reference(
        self, visit: int, t: np.ndarray, h: float = 1e-3
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration ``[len(t), 6]`` by central differences."""
        t = np.asarray(t, dtype=float)
        q_minus, q, q_plus = (self.position(visit, t + d) for d in (-h, 0.0, h))
        return q, (q_plus - q_minus) / (2 * h), (q_plus - 2 * q + q_minus) / (h * h)
