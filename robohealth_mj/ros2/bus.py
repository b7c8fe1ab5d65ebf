"""One DDS participant following ROS 2's conventions: names, QoS profiles, domain and interface.

- Topic names (``ros2/design``, "Topic and Service name mapping to DDS"): a ROS topic ``/a/b`` is
  the DDS topic ``rt/a/b``.
- QoS (``rmw/qos_profiles.h``): the default profile (reliable, volatile, keep last 10) for what we
  publish; the sensor-data profile (best effort, volatile, keep last 5) is what we subscribe with
  by default, because a best-effort reader matches both reliable and best-effort writers.
- Fast DDS 3 peers (recent ROS 2's default middleware) advertise type information that Cyclone
  rejects unless told to ignore it for their vendor id (``Compatibility/IgnoreTypeInformation``).
  Measured against rclpy on Fast DDS (``studies/ros2/type_information.sh``): without it no
  message passes either way, with it every one does, so it is on by default; it concerns only
  that vendor id, so Cyclone peers are unaffected.
- ``CYCLONEDDS_URI``, the way a ROS 2 user configures Cyclone (interfaces, peers, shared memory),
  is honoured: Cyclone reads a comma-separated list of XML and files with later entries
  overriding earlier ones, so the domain gets this project's settings followed by the user's.
"""

from __future__ import annotations

import ctypes
import os
import time
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from typing import Any
from xml.sax.saxutils import escape

from robohealth_mj.common.errors import InputError
from robohealth_mj.ros2.security import Security

EPROSIMA_VENDOR_ID = "1.15"  # Fast DDS's RTPS vendor id, as Cyclone writes it


@dataclass(frozen=True)
class BusConfig:
    domain_id: int = 0  # ROS_DOMAIN_ID
    interface: str | None = None  # an address or interface name; None: Cyclone's choice
    ignore_type_information: bool = True  # Fast DDS 3 peers: without it nothing passes
    reliable_subscriptions: bool = False  # default: best effort (matches every writer)
    depth: int = 10  # history depth of readers and writers
    security: Security | None = None  # SROS2: the enclave this participant joins as

    def xml(self) -> str:
        """Cyclone DDS's configuration for this participant's domain. The type-information
        setting exists from Cyclone 11 on; the secured binding (0.10, ``make setup-sros2``)
        refuses a configuration that names it, and leaves it out."""
        general = discovery = ""
        if self.interface:
            attr = "address" if self.interface[0].isdigit() else "name"
            loopback = self.interface.startswith("127.") or self.interface == "lo"
            general = (
                f'<General><Interfaces><NetworkInterface {attr}="{escape(self.interface)}"/>'
                f"</Interfaces>{'<AllowMulticast>false</AllowMulticast>' if loopback else ''}"
                "</General>"
            )
            if loopback:  # no multicast on loopback: unicast discovery of local participants
                discovery = (
                    "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
                    "<MaxAutoParticipantIndex>200</MaxAutoParticipantIndex>"
                    '<Peers><Peer address="127.0.0.1"/></Peers></Discovery>'
                )
        compat = (
            f"<Compatibility><IgnoreTypeInformation>{EPROSIMA_VENDOR_ID}"
            "</IgnoreTypeInformation></Compatibility>"
            if self.ignore_type_information and binding_major() >= 11
            else ""
        )
        return f'<CycloneDDS><Domain id="any">{general}{discovery}{compat}</Domain></CycloneDDS>'


@cache
def binding_major() -> int:
    """The installed Cyclone DDS binding's major version (11 for PyPI's wheel)."""
    from importlib.metadata import version

    return int(version("cyclonedds").split(".")[0])


def domain_config(config: BusConfig, environ: Mapping[str, str] = os.environ) -> str:
    """The domain's configuration: ours, then ``CYCLONEDDS_URI``'s where set (the user's wins
    where both say something). Cyclone ignores the variable once a domain is given a config."""
    user = environ.get("CYCLONEDDS_URI", "").strip()
    return f"{config.xml()},{user}" if user else config.xml()


def dds_topic(ros_name: str) -> str:
    """``/a/b`` -> ``rt/a/b``."""
    return "rt/" + ros_name.lstrip("/")


_DOMAINS: dict[int, tuple[str, Any]] = {}  # Cyclone allows one configured domain per id


def _domain(config: BusConfig) -> Any:
    from cyclonedds.domain import Domain

    xml = domain_config(config)
    known = _DOMAINS.get(config.domain_id)
    if known is None:
        known = _DOMAINS[config.domain_id] = (xml, Domain(config.domain_id, xml))
    elif known[0] != xml:
        raise ValueError(
            f"domain {config.domain_id} is already configured otherwise in this process"
        )
    return known[1]


class _MatchedStatus(ctypes.Structure):
    """``dds_publication_matched_status_t``."""

    _fields_ = [("total_count", ctypes.c_uint32), ("total_count_change", ctypes.c_int32),
                ("current_count", ctypes.c_uint32), ("current_count_change", ctypes.c_int32),
                ("last_subscription_handle", ctypes.c_uint64)]  # fmt: skip


@cache
def _ddsc() -> ctypes.CDLL:
    from robohealth_mj.ros2.security import binding_library

    return ctypes.CDLL(str(binding_library()))


class Bus:
    """A participant on one domain with the topics, readers and writers made through it."""

    def __init__(self, config: BusConfig) -> None:
        from cyclonedds.core import DDSException, Policy, Qos
        from cyclonedds.domain import DomainParticipant

        self.config = config
        self._domain = _domain(config)
        qos = None
        if (security := config.security) is not None:
            qos = Qos(*(Policy.Property(k, v) for k, v in security.properties().items()))
        try:
            self.participant = DomainParticipant(config.domain_id, qos=qos)
        except DDSException as exc:
            if security is None:
                raise
            raise InputError(
                f"ros2.security: DDS Security refused enclave {security.enclave} "
                f"({security.folder}): its certificate, key or signed files do not verify "
                f"against the keystore's CA, or it is not allowed on domain {config.domain_id} "
                f"(DDS error {exc.code})"
            ) from None
        self._topics: dict[str, Any] = {}

    def _refused(self, exc: Exception, what: str) -> Exception:
        """A reader, writer or topic the enclave's permissions do not grant: one line naming
        them; any other error as it was."""
        from cyclonedds.core import DDSException

        security = self.config.security
        if (
            security is None
            or getattr(exc, "code", None) != DDSException.DDS_RETCODE_NOT_ALLOWED_BY_SECURITY
        ):
            return exc
        return InputError(
            f"ros2.security: enclave {security.enclave} may not {what} (its permissions: "
            f"{security.folder / 'permissions.xml'})"
        )

    def _topic(self, name: str, cls: type) -> Any:
        from cyclonedds.core import DDSException
        from cyclonedds.topic import Topic

        key = dds_topic(name)
        if key not in self._topics:
            try:
                self._topics[key] = Topic(self.participant, key, cls)
            except DDSException as exc:
                raise self._refused(exc, f"use topic {name!r}") from None
        elif self._topics[key].data_type is not cls:
            raise ValueError(f"topic {name!r} is {self._topics[key].data_type.__name__} here")
        return self._topics[key]

    def _qos(self, reliable: bool) -> Any:
        from cyclonedds.core import Policy, Qos
        from cyclonedds.util import duration

        depth = self.config.depth
        if reliable:
            return Qos(
                Policy.Reliability.Reliable(duration(milliseconds=100)),
                Policy.History.KeepLast(depth),
                Policy.Durability.Volatile,
            )
        return Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(depth),
                   Policy.Durability.Volatile)  # fmt: skip

    def writer(self, name: str, cls: type) -> Any:
        """A writer with ROS 2's default profile (reliable)."""
        from cyclonedds.core import DDSException
        from cyclonedds.pub import DataWriter

        topic = self._topic(name, cls)
        try:
            return DataWriter(self.participant, topic, self._qos(reliable=True))
        except DDSException as exc:
            raise self._refused(exc, f"publish {name!r}") from None

    def reader(self, name: str, cls: type) -> Any:
        """A reader, best effort unless ``reliable_subscriptions``."""
        from cyclonedds.core import DDSException
        from cyclonedds.sub import DataReader

        topic = self._topic(name, cls)
        try:
            return DataReader(
                self.participant, topic, self._qos(self.config.reliable_subscriptions)
            )
        except DDSException as exc:
            raise self._refused(exc, f"subscribe to {name!r}") from None

    @staticmethod
    def serialize(writer: Any, msg: Any) -> bytes:
        """``msg`` as ``writer`` puts it on the wire (its CDR version, padded to 4 bytes), for
        :meth:`write_serialized`: a message many writers share is serialised once."""
        data = msg.serialize(use_version_2=writer._use_version_2)
        return data.ljust((len(data) + 3) & ~3, b"\0")

    @staticmethod
    def write_serialized(writer: Any, data: bytes) -> None:
        """Write bytes from :meth:`serialize` (the binding's ``write`` without serialising)."""
        from cyclonedds._clayer import ddspy_write
        from cyclonedds.core import DDSException

        ret = ddspy_write(writer._ref, data)
        if ret < 0:
            raise DDSException(ret, f"Occurred while writing sample in {writer!r}")

    @staticmethod
    def matched_readers(writer: Any) -> int:
        """How many readers ``writer`` is matched with now (on a secured graph: authenticated,
        permitted and with keys exchanged). From the C library: the 0.10 binding has no
        Python call for it."""
        status = _MatchedStatus()
        ret = _ddsc().dds_get_publication_matched_status(writer._ref, ctypes.byref(status))
        if ret < 0:
            from cyclonedds.core import DDSException

            raise DDSException(ret, f"Occurred while reading the matched status of {writer!r}")
        return int(status.current_count)

    @staticmethod
    def delete(entity: Any) -> None:
        """Delete a reader, writer, condition or waitset now (with what it holds). The binding
        keeps every entity in a class-wide table until its own deletion runs, so dropping the
        last reference is not enough."""
        entity.__del__()

    def close(self, now: bool = False) -> None:
        """Let the participant go (and with it every reader, writer and topic). ``now``: delete
        it at once, even while other references remain. A refusal's traceback holds the bus, so
        waiting for the last reference left the participant to the interpreter's exit, where it
        raced the security plugins' threads (a segfault after the one-line error, one run in
        eight with a secured peer on the domain)."""
        if now and self.participant is not None:
            self.delete(self.participant)
        self._topics.clear()
        self.participant = None
        self._domain = None

    def __enter__(self) -> Bus:
        return self

    def __exit__(self, exc_type: type | None, *_exc: object) -> None:
        self.close(now=exc_type is not None)  # on an error, at once (see close)


class ReadySet:
    """Which of many readers hold data, in one call: a DDS waitset of one read condition per
    reader. A monitor of hundreds of readers (15 a per-sensor arm) then takes only from those
    that have something, and waits in DDS, not in a sleep, until one has."""

    def __init__(self, bus: Bus, readers: list[Any]) -> None:
        import ctypes

        from cyclonedds.core import (
            DDSException,
            InstanceState,
            ReadCondition,
            SampleState,
            ViewState,
            WaitSet,
        )

        self._waitset = WaitSet(bus.participant)
        mask = SampleState.NotRead | ViewState.Any | InstanceState.Any
        self._conditions = [ReadCondition(r, mask) for r in readers]
        for k, condition in enumerate(self._conditions):
            # the attach argument is what the wait reports: k + 1 (a 0 would read as None)
            ret = self._waitset._waitset_attach(self._waitset._ref, condition._ref, k + 1)
            if ret < 0:
                raise DDSException(ret, f"Occurred when attaching reader {k} to a waitset")
        self._triggered = (ctypes.c_void_p * max(1, len(readers)))()
        self._out = ctypes.cast(self._triggered, ctypes.POINTER(ctypes.c_void_p))

    def wait(self, timeout_s: float = 0.0) -> list[int]:
        """The indices (in ``readers``' order) of the readers holding unread data, waiting up
        to ``timeout_s`` for one when none does."""
        from cyclonedds.core import DDSException

        n = len(self._conditions)
        if not n:  # no readers (a monitor whose arms all went to others): nothing to wait on
            if timeout_s > 0:
                time.sleep(timeout_s)
            return []
        got = self._waitset._waitset_wait(self._waitset._ref, self._out, n, int(timeout_s * 1e9))
        if got < 0:
            raise DDSException(got, "Occurred while waiting for readers")
        return sorted(self._triggered[i] - 1 for i in range(min(got, n)))

    def close(self) -> None:
        """Delete the waitset and its read conditions (the readers stay)."""
        for entity in (self._waitset, *self._conditions):
            Bus.delete(entity)
        self._conditions = []
