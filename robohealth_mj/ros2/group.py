"""Monitors that cover for each other: a group on one bus sharing the arms by rendezvous hashing.

Each monitor heartbeats on ``/robohealth/monitor_group`` (a ``DiagnosticStatus`` naming the
member; ROS tools can echo it) and counts as a member while it is heard from within
``timeout_s``. There is no coordinator: every member computes the same owner for an arm from the
same member list, the member with the highest hash of (member, arm) (rendezvous or
highest-random-weight hashing), so a member leaving moves only its own arms, each to the member
that ranks second for it, and a member joining takes only the arms it now ranks first for.

A member that joins says ``joining`` while it listens and makes its readers, then ``active``:
from then on it diagnoses its share, and the member that had each of those arms keeps it until
the joiner has been active for ``handover_s`` (its window has filled by then). The handover is
counted from the first ``active`` beat, not the first beat: a joiner's readers must be on the
bus before the owner stops reading, or the ticks between are lost (counted from the first beat,
a handover shorter than the joiner's listening left the two racing). So a join loses no sample
and two monitors diagnose one arm only during the handover. A member that stops cleanly says so
(``leaving``) and its arms move at once; one that is killed moves them once it has been silent
``timeout_s``.
What the taker starts from: a fresh window (decisions resume once it has filled) and fresh alarm
state (an alarm up on the dead monitor is raised again after its persistence), because neither
travels between processes.

A heartbeat counts from when it was sent, not when it was read: a monitor that stalls past the
timeout reads the beats queued meanwhile all at once, and a member that died during the stall
must not look alive for another timeout. The sender's clock need not agree with ours: each beat's
age (our wall clock less its source timestamp) is taken against the smallest age that member's
beats showed over the last ``SKEW_WINDOW_S`` (its clock offset plus the bus's delay), so only
the lateness beyond that counts. The window is long so that a stall shorter than it is judged
right; the price is that a member whose clock steps forward by more than the timeout looks gone
to the others for up to that long, and its arms are watched twice meanwhile (none is lost).
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from hashlib import blake2b
from typing import Any

from robohealth_mj.common.errors import InputError

GROUP_TOPIC = "/robohealth/monitor_group"
JOINING, ACTIVE, LEAVING = "joining", "active", "leaving"
SKEW_WINDOW_S = 30.0  # a member's clock offset is the least beat age seen within this long


def rank(member: str, arm: str) -> int:
    """The member's weight for the arm: the same on every machine and Python (not ``hash``)."""
    digest = blake2b(f"{member}\0{arm}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "big")


def owner(arm: str, members: Iterable[str]) -> str:
    """The member that watches ``arm``: the highest :func:`rank` (ties: the larger name), so the
    order the members are listed in does not matter."""
    return max(members, key=lambda m: (rank(m, arm), m))


def share(arms: Sequence[str], members: Iterable[str], me: str) -> list[str]:
    """``me``'s arms among ``members``, in ``arms``' order."""
    members = set(members) | {me}
    return [a for a in arms if owner(a, members) == me]


@dataclass(frozen=True)
class GroupConfig:
    member: str  # this monitor's name in the group: stable, so a restart gets its share back
    heartbeat_s: float = 0.2  # how often it says it is alive
    timeout_s: float = 0.8  # silent this long: gone (its arms move)
    handover_s: float = 3.0  # a joiner's arms stay with their owner this long (its window fills)


def group_config(cfg: Any) -> GroupConfig | None:
    """``ros2.group`` as a :class:`GroupConfig` (None when off); bad values in one line."""
    if cfg is None or not cfg.get("enable", False):
        return None
    member = cfg.get("member") or f"{socket.gethostname()}-{os.getpid()}"
    values = {}
    for key in ("heartbeat_s", "timeout_s", "handover_s"):
        value = cfg.get(key, getattr(GroupConfig, key))
        try:
            values[key] = float(value)
        except (TypeError, ValueError):
            values[key] = -1.0
        if not values[key] > 0:
            raise InputError(f"ros2.group.{key}: {value!r} is not a positive number of seconds")
    if values["timeout_s"] <= 2 * values["heartbeat_s"]:
        raise InputError(
            f"ros2.group.timeout_s: {values['timeout_s']} must exceed two heartbeats "
            f"(ros2.group.heartbeat_s={values['heartbeat_s']}), or a late one drops a member"
        )
    return GroupConfig(member=str(member), **values)


class MonitorGroup:
    """This monitor's view of the group: who is alive, and which arms are its to watch."""

    def __init__(self, bus: Any, config: GroupConfig, arms: Sequence[str]) -> None:
        from robohealth_mj.ros2.idl import TYPES

        self.config, self.arms = config, list(arms)
        self.me = config.member
        self._status = TYPES["diagnostic_msgs/msg/DiagnosticStatus"]
        self._writer = bus.writer(GROUP_TOPIC, self._status)
        self._reader = bus.reader(GROUP_TOPIC, self._status)
        self._heard: dict[str, float] = {}  # member -> when last heard (monotonic)
        self._first: dict[str, float] = {}  # member -> when first heard active this time round
        self._offset: dict[str, tuple[float, float]] = {}  # member -> (least beat age, since)
        self._next_beat = 0.0
        self._watching: list[str] = []
        self._members: tuple[list[str], list[str]] | None = None  # (live, settled) last shared
        self._state = JOINING  # until the first update() after discover(): the readers exist

    def _beat(self, now: float, state: str | None = None) -> None:
        self._writer.write(self._status(level=0, name=self.me, message=state or self._state,
                                         hardware_id=socket.gethostname(), values=[]))  # fmt: skip
        self._next_beat = now + self.config.heartbeat_s

    def _listen(self, now: float) -> None:
        for msg in self._reader.take(N=256):
            if msg.name == self.me:
                continue
            if msg.message == LEAVING:
                self._heard.pop(msg.name, None)
                self._first.pop(msg.name, None)
                continue
            if msg.message == JOINING:  # live, its handover not begun (again, if it restarted
                self._first.pop(msg.name, None)  # faster than the timeout)
            else:
                self._first.setdefault(msg.name, now)
            sent = now - self._lateness(msg.name, msg, now)
            self._heard[msg.name] = max(self._heard.get(msg.name, sent), sent)

    def _lateness(self, member: str, msg: Any, now: float) -> float:
        """How much later than its member's usual this beat was read (s, >= 0); 0 when the
        sample carries no source timestamp."""
        info = getattr(msg, "sample_info", None)
        if info is None or not getattr(info, "source_timestamp", 0):
            return 0.0
        age = (time.time_ns() - info.source_timestamp) / 1e9
        least, since = self._offset.get(member, (age, now))
        if age <= least or now - since > SKEW_WINDOW_S:  # a new least, or the old one expired
            least, since = age, now
        self._offset[member] = (least, since)
        return max(0.0, age - least)

    def members(self, now: float | None = None) -> list[str]:
        """The live members, this one included, sorted."""
        now = time.monotonic() if now is None else now
        return sorted({self.me} | {m for m, t in self._heard.items()
                                   if now - t <= self.config.timeout_s})  # fmt: skip

    def discover(self) -> list[str]:
        """Heartbeat and listen for one ``timeout_s`` before taking any arm (a monitor that
        took every arm until it heard the others would make every arm change hands at start);
        those already there count as settled. Returns this monitor's first share; it says
        ``active`` (and the handover of that share begins) at the first :meth:`update`, once
        the caller has made the share's readers."""
        start = time.monotonic()
        while (now := time.monotonic()) - start < self.config.timeout_s:
            if now >= self._next_beat:
                self._beat(now)
            self._listen(now)
            time.sleep(min(0.02, self.config.heartbeat_s / 4))
        for member in self._first:
            self._first[member] = -float("inf")
        return self._shares(time.monotonic())

    def update(self, now: float | None = None) -> list[str]:
        """Heartbeat when due, hear the others, and return the arms to watch now: those this
        monitor owns among the live members, and those it owned before a joiner came that the
        joiner has not held for ``handover_s`` yet."""
        now = time.monotonic() if now is None else now
        if now >= self._next_beat or self._state == JOINING:
            self._state = ACTIVE
            self._beat(now)
        self._listen(now)
        return self._shares(now)

    def _shares(self, now: float) -> list[str]:
        live = self.members(now)
        for gone in set(self._first) - set(live):  # silent past the timeout: back later, it joins
            del self._first[gone]
        handover = self.config.handover_s
        settled = [m for m in live if m == self.me or now - self._first.get(m, now) >= handover]
        if (live, settled) != self._members:  # the hashes only when the members change: this
            self._members = (live, settled)  # runs every poll, 0.65 ms at 150 arms and 3 members
            mine = set(share(self.arms, live, self.me))
            kept = set(share(self.arms, settled, self.me))
            self._watching = [a for a in self.arms if a in mine or a in kept]
        return self._watching

    def leave(self) -> None:
        """Say this monitor is going, so the others take its arms at once."""
        self._beat(time.monotonic(), LEAVING)
