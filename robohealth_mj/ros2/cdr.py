"""Fast decoding of the fixed message layouts a monitor takes most (XCDR1, little endian).

The binding's own decoding walks every field through Python objects of its type machinery; at a
hundred arms of the per-sensor layout (30,000 messages a second) that is most of the monitor's
core. These decoders read the same bytes with ``struct`` and NumPy in one pass per message and
build the binding's own classes, so everything downstream (assembly, duplicate detection by
equality) is unchanged. A message they cannot read as one of these layouts (another
representation, a truncated or malformed buffer) goes to the binding's decoding, which decides:
the fast path never accepts what the binding would not, and ``tests/ros2/test_cdr.py`` checks
that both give the same object, or both refuse, on every type and on damaged buffers.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

import numpy as np

from robohealth_mj.ros2.idl import (
    DiagnosticArray,
    DiagnosticStatus,
    Float64MultiArray,
    Header,
    Imu,
    JointState,
    KeyValue,
    MultiArrayDimension,
    MultiArrayLayout,
    Quaternion,
    Time,
    Vector3,
)

_CDR_LE = b"\x00\x01"  # the encapsulation identifier of plain (XCDR1) little-endian CDR
_U32 = struct.Struct("<I").unpack_from
_STAMP = struct.Struct("<iI").unpack_from  # a header's stamp: sec, nanosec
_DIMENSION = struct.Struct("<II").unpack_from


class _Malformed(Exception):
    """The buffer is not this layout: the binding's decoding decides."""


# Offsets are absolute (the 4-byte encapsulation header first): 4-byte alignment is the same
# absolute or relative to the payload, 8-byte alignment is relative to the payload (offset 4).


def _u32(buf: bytes, pos: int) -> tuple[int, int]:
    pos = (pos + 3) & ~3
    if pos + 4 > len(buf):
        raise _Malformed("truncated")
    return _U32(buf, pos)[0], pos + 4


def _text(buf: bytes, pos: int) -> tuple[str, int]:
    """A string: its length with the NUL, then its bytes and the NUL."""
    n, pos = _u32(buf, pos)
    end = pos + n
    if n == 0 or end > len(buf) or buf[end - 1] != 0:
        raise _Malformed("string without its terminating NUL")
    return buf[pos : end - 1].decode(), end


def _count(buf: bytes, pos: int, least: int) -> tuple[int, int]:
    """A sequence's length, refused when the rest of the buffer cannot hold it."""
    n, pos = _u32(buf, pos)
    if n * least > len(buf) - pos:
        raise _Malformed("sequence longer than the buffer")
    return n, pos


def _doubles(buf: bytes, pos: int, n: int) -> tuple[list[float], int]:
    if not n:
        return [], pos
    pos = (pos + 3) & ~3
    pos += (pos - 4) & 4  # 8-byte aligned in the payload
    end = pos + 8 * n
    if end > len(buf):
        raise _Malformed("truncated")
    return np.frombuffer(buf, "<f8", n, pos).tolist(), end


def _double_sequence(buf: bytes, pos: int) -> tuple[list[float], int]:
    n, pos = _count(buf, pos, 8)
    return _doubles(buf, pos, n)


def _header(buf: bytes) -> tuple[Header, int]:
    if len(buf) < 12 or buf[:2] != _CDR_LE:
        raise _Malformed("not XCDR1 little endian")
    sec, nanosec = _STAMP(buf, 4)
    frame_id, pos = _text(buf, 12)
    return Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=frame_id), pos


def _joint_state(buf: bytes) -> JointState:
    header, pos = _header(buf)
    n, pos = _count(buf, pos, 5)
    names = []
    for _ in range(n):
        name, pos = _text(buf, pos)
        names.append(name)
    position, pos = _double_sequence(buf, pos)
    velocity, pos = _double_sequence(buf, pos)
    effort, pos = _double_sequence(buf, pos)
    return JointState(
        header=header, name=names, position=position, velocity=velocity, effort=effort
    )


def _imu(buf: bytes) -> Imu:
    header, pos = _header(buf)
    v, _ = _doubles(buf, pos, 37)  # quaternion, 9, vector, 9, vector, 9: one block of doubles
    return Imu(
        header=header,
        orientation=Quaternion(x=v[0], y=v[1], z=v[2], w=v[3]),
        orientation_covariance=v[4:13],
        angular_velocity=Vector3(x=v[13], y=v[14], z=v[15]),
        angular_velocity_covariance=v[16:25],
        linear_acceleration=Vector3(x=v[25], y=v[26], z=v[27]),
        linear_acceleration_covariance=v[28:37],
    )


def _float64_multi_array(buf: bytes) -> Float64MultiArray:
    if len(buf) < 4 or buf[:2] != _CDR_LE:
        raise _Malformed("not XCDR1 little endian")
    n, pos = _count(buf, 4, 13)
    dims = []
    for _ in range(n):
        label, pos = _text(buf, pos)
        pos = (pos + 3) & ~3
        if pos + 8 > len(buf):
            raise _Malformed("truncated")
        size, stride = _DIMENSION(buf, pos)
        dims.append(MultiArrayDimension(label=label, size=size, stride=stride))
        pos += 8
    offset, pos = _u32(buf, pos)
    data, _ = _double_sequence(buf, pos)
    return Float64MultiArray(layout=MultiArrayLayout(dim=dims, data_offset=offset), data=data)


def _diagnostic_array(buf: bytes) -> DiagnosticArray:
    header, pos = _header(buf)
    n, pos = _count(buf, pos, 17)
    status = []
    for _ in range(n):
        if pos >= len(buf):
            raise _Malformed("truncated")
        level = buf[pos]
        name, pos = _text(buf, pos + 1)
        message, pos = _text(buf, pos)
        hardware_id, pos = _text(buf, pos)
        m, pos = _count(buf, pos, 10)
        values = []
        for _ in range(m):
            key, pos = _text(buf, pos)
            value, pos = _text(buf, pos)
            values.append(KeyValue(key=key, value=value))
        status.append(DiagnosticStatus(level=level, name=name, message=message,
                                       hardware_id=hardware_id, values=values))  # fmt: skip
    return DiagnosticArray(header=header, status=status)


DECODERS: dict[type, Callable[[bytes], Any]] = {
    JointState: _joint_state,
    Imu: _imu,
    Float64MultiArray: _float64_multi_array,
    DiagnosticArray: _diagnostic_array,
}


def decode(kind: type, data: bytes) -> Any:
    """One serialised message (encapsulation header included) as an instance of ``kind``: by
    the fast layout where ``kind`` has one and the bytes read as it, else by the binding."""
    decoder = DECODERS.get(kind)
    if decoder is not None:
        try:
            return decoder(data)
        except (_Malformed, struct.error, UnicodeDecodeError, ValueError):
            pass
    return kind.deserialize(data)


class _Writer:
    """XCDR1 little-endian bytes, aligned relative to the payload as the binding writes them."""

    def __init__(self) -> None:
        self.out = bytearray(b"\x00\x01\x00\x00")

    def _align(self, n: int) -> None:
        self.out += b"\0" * (-(len(self.out) - 4) % n)

    def u32(self, v: int) -> None:
        self._align(4)
        self.out += struct.pack("<I", v)

    def text(self, v: str) -> None:
        data = v.encode()
        self.u32(len(data) + 1)
        self.out += data
        self.out += b"\0"

    def done(self) -> bytes:
        self._align(4)  # as the binding pads what it writes
        return bytes(self.out)


def encode_diagnostic_array(stamp_ns: int, frame_id: str, statuses: list[tuple]) -> bytes:
    """A ``DiagnosticArray`` as a writer puts it on the wire, from ``(level, name, message,
    hardware_id, {key: value})`` per status: what the binding's serialisation of the same message
    gives (a test holds them equal), without building the message's objects."""
    w = _Writer()
    w.out += struct.pack("<iI", stamp_ns // 10**9, stamp_ns % 10**9)
    w.text(frame_id)
    w.u32(len(statuses))
    for level, name, message, hardware_id, values in statuses:
        w.out.append(level)
        w.text(name)
        w.text(message)
        w.text(hardware_id)
        w.u32(len(values))
        for key, value in values.items():
            w.text(key)
            w.text(value)
    return w.done()


def take_raw(reader: Any, limit: int) -> list[bytes]:
    """Up to ``limit`` serialised messages from a DDS reader (the DDS take alone); instance-state
    notices (no data: a writer went away) are skipped."""
    from cyclonedds._clayer import ddspy_take
    from cyclonedds.core import DDSException, InstanceState, SampleState, ViewState

    got = ddspy_take(reader._ref, SampleState.Any | ViewState.Any | InstanceState.Any, limit)
    if isinstance(got, int):
        raise DDSException(got, f"Occurred while taking data in {reader!r}")
    return [data for data, info in got if info.valid_data]


def decode_all(kind: type, taken: list[bytes]) -> tuple[list[Any], list[str]]:
    """The messages of :func:`take_raw`, decoded by :func:`decode`, and why any could not be
    (one line each; the caller marks the arm)."""
    messages, problems = [], []
    for data in taken:
        try:
            messages.append(decode(kind, data))
        except Exception as exc:  # a buffer no decoder reads is that arm's bad input
            problems.append(f"undecodable {kind.__name__} ({type(exc).__name__}: {exc})")
    return messages, problems
