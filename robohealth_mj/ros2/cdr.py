"""Fast decoding of the fixed message layouts a monitor takes most (XCDR1, little endian).

The binding's own decoding walks every field through Python objects of its type machinery; at a
hundred arms of the per-sensor layout (30,000 messages a second) that is most of the monitor's
core. These decoders read the same bytes with ``struct`` and NumPy in one pass per message and
build the binding's own classes, so everything downstream (assembly, duplicate detection by
equality) is unchanged. A message they cannot read as one of these layouts (another
representation, a truncated or malformed buffer) goes to the binding's decoding, which decides:
the fast path never accepts what the binding would not, and ``tests/ros2/test_cdr.py`` checks
that both give the same object, or both refuse, on every type and on damaged buffers.

The same readers also give :class:`MessageView` s: what a sample needs of a message and where
its changing parts lie in the bytes, the input of the byte templates
(:mod:`robohealth_mj.ros2.templates`) through which the monitor reads the bag layouts.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from robohealth_mj.bags.messages import STAMP_LABEL, label_stamp_ns
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


_NO_DOUBLES = np.zeros(0)


def _doubles(buf: bytes, pos: int, n: int) -> tuple[np.ndarray, int]:
    if not n:
        return _NO_DOUBLES, pos
    pos = (pos + 3) & ~3
    pos += (pos - 4) & 4  # 8-byte aligned in the payload
    end = pos + 8 * n
    if end > len(buf):
        raise _Malformed("truncated")
    return np.frombuffer(buf, "<f8", n, pos), end


def _double_sequence(buf: bytes, pos: int) -> tuple[np.ndarray, int]:
    n, pos = _count(buf, pos, 8)
    return _doubles(buf, pos, n)


def _stamp_frame(buf: bytes) -> tuple[int, int, str, int]:
    """A header's stamp (sec, nanosec) and frame id, and where the message goes on."""
    if len(buf) < 12 or buf[:2] != _CDR_LE:
        raise _Malformed("not XCDR1 little endian")
    sec, nanosec = _STAMP(buf, 4)
    frame_id, pos = _text(buf, 12)
    return sec, nanosec, frame_id, pos


def _header(buf: bytes) -> tuple[Header, int]:
    sec, nanosec, frame_id, pos = _stamp_frame(buf)
    return Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=frame_id), pos


def _joint_state_fields(buf: bytes) -> tuple:
    """(sec, nanosec, frame id, names, position, velocity, effort, where the three blocks of
    doubles start)."""
    sec, nanosec, frame_id, pos = _stamp_frame(buf)
    n, pos = _count(buf, pos, 5)
    names = []
    for _ in range(n):
        name, pos = _text(buf, pos)
        names.append(name)
    position, pos = _double_sequence(buf, pos)
    p_start = pos - 8 * len(position)
    velocity, pos = _double_sequence(buf, pos)
    v_start = pos - 8 * len(velocity)
    effort, pos = _double_sequence(buf, pos)
    starts = (p_start, v_start, pos - 8 * len(effort))
    return sec, nanosec, frame_id, names, position, velocity, effort, starts


def _joint_state(buf: bytes) -> JointState:
    sec, nanosec, frame_id, names, position, velocity, effort, _ = _joint_state_fields(buf)
    return JointState(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=frame_id),
        name=names,
        position=position.tolist(),
        velocity=velocity.tolist(),
        effort=effort.tolist(),
    )


def _imu_fields(buf: bytes) -> tuple[int, int, str, np.ndarray, int]:
    """(sec, nanosec, frame id, the 37 doubles: quaternion, 9, vector, 9, vector, 9; where
    they start)."""
    sec, nanosec, frame_id, pos = _stamp_frame(buf)
    v, end = _doubles(buf, pos, 37)
    return sec, nanosec, frame_id, v, end - 8 * 37


def _imu(buf: bytes) -> Imu:
    sec, nanosec, frame_id, v, _ = _imu_fields(buf)
    header = Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=frame_id)
    v = v.tolist()
    return Imu(
        header=header,
        orientation=Quaternion(x=v[0], y=v[1], z=v[2], w=v[3]),
        orientation_covariance=v[4:13],
        angular_velocity=Vector3(x=v[13], y=v[14], z=v[15]),
        angular_velocity_covariance=v[16:25],
        linear_acceleration=Vector3(x=v[25], y=v[26], z=v[27]),
        linear_acceleration_covariance=v[28:37],
    )


def _float64_multi_array_fields(buf: bytes) -> tuple[list[tuple], int, np.ndarray, int]:
    """(dims as (label, size, stride, where the label's text ends), data offset, data, where
    the data start)."""
    if len(buf) < 4 or buf[:2] != _CDR_LE:
        raise _Malformed("not XCDR1 little endian")
    n, pos = _count(buf, 4, 13)
    dims = []
    for _ in range(n):
        label, pos = _text(buf, pos)
        end = pos - 1  # the NUL
        pos = (pos + 3) & ~3
        if pos + 8 > len(buf):
            raise _Malformed("truncated")
        dims.append((label, *_DIMENSION(buf, pos), end))
        pos += 8
    offset, pos = _u32(buf, pos)
    data, end = _double_sequence(buf, pos)
    return dims, offset, data, end - 8 * len(data)


def _float64_multi_array(buf: bytes) -> Float64MultiArray:
    dims, offset, data, _ = _float64_multi_array_fields(buf)
    dim = [MultiArrayDimension(label=a, size=b, stride=c) for a, b, c, _ in dims]
    return Float64MultiArray(
        layout=MultiArrayLayout(dim=dim, data_offset=offset), data=data.tolist()
    )


def _diagnostic_array_fields(buf: bytes) -> tuple[Header, list[DiagnosticStatus], list[dict]]:
    """(header, statuses, per status where each key's value text is: ``{key: (start, end)}``)."""
    header, pos = _header(buf)
    n, pos = _count(buf, pos, 17)
    status, values_at = [], []
    for _ in range(n):
        if pos >= len(buf):
            raise _Malformed("truncated")
        level = buf[pos]
        name, pos = _text(buf, pos + 1)
        message, pos = _text(buf, pos)
        hardware_id, pos = _text(buf, pos)
        m, pos = _count(buf, pos, 10)
        values, at = [], {}
        for _ in range(m):
            key, pos = _text(buf, pos)
            value, pos = _text(buf, pos)
            values.append(KeyValue(key=key, value=value))
            at[key] = (pos - 1 - len(value.encode()), pos - 1)
        status.append(DiagnosticStatus(level=level, name=name, message=message,
                                       hardware_id=hardware_id, values=values))  # fmt: skip
        values_at.append(at)
    return header, status, values_at


def _diagnostic_array(buf: bytes) -> DiagnosticArray:
    header, status, _ = _diagnostic_array_fields(buf)
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
    message = _fast(DECODERS, kind, data)
    return message if message is not None else kind.deserialize(data)


def _fast(readers: dict[type, Callable[[bytes], Any]], kind: type, data: bytes) -> Any:
    """``readers``' reading of ``data`` as a ``kind``; ``None`` where it has none for ``kind``
    or the bytes are not that layout (then the binding decides)."""
    reader = readers.get(kind)
    if reader is not None:
        try:
            return reader(data)
        except (_Malformed, struct.error, UnicodeDecodeError, ValueError):
            pass
    return None


class MessageView:
    """What a sample needs of one message, read from its bytes without the message's objects
    (the per-sensor layout's 14 messages a tick of joint states, IMUs and vibration arrays).
    It answers the attributes assembly reads as the message would, and says where in its bytes
    the parts that change from message to message are (``stamp_at``: the stamp's bytes;
    ``blocks``: each block of doubles, ``(start, count)``), which is what a byte template of
    the topic's messages needs (:mod:`robohealth_mj.ros2.templates`). Two are equal when their
    bytes are, or else when the binding's decoding of both is (a duplicate's test)."""

    __slots__ = ("blocks", "raw", "stamp_at", "stamp_ns", "template")
    kind: type  # the message class it stands for

    def __init__(self, raw: bytes, stamp_ns: int | None, stamp_at: tuple[int, int] | None,
                 blocks: tuple[tuple[int, int], ...], template: Any = None) -> None:  # fmt: skip
        """``template``: the topic's byte template this message matched (then only the stamp
        was read; the rest is read where the template says)."""
        self.raw, self.stamp_ns, self.stamp_at, self.blocks = raw, stamp_ns, stamp_at, blocks
        self.template = template

    def message(self) -> Any:
        return decode(self.kind, self.raw)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, MessageView):
            return self.raw == other.raw or self.message() == other.message()
        return self.message() == other

    __hash__ = None  # type: ignore[assignment]


class JointStateView(MessageView):
    """Blocks: position, velocity, effort."""

    __slots__ = ("effort", "name", "position", "velocity")
    kind = JointState


class Acceleration(NamedTuple):
    x: float
    y: float
    z: float


class ImuView(MessageView):
    """One block: the 37 doubles (orientation, its covariance, angular velocity, its
    covariance, linear acceleration at 25-27, its covariance)."""

    __slots__ = ("linear_acceleration",)
    kind = Imu


class ArrayView(MessageView):
    """A vibration array: its data (one block) and the stamp its layout carries (``None``:
    none; ``stamp_at``: the label's digits)."""

    __slots__ = ("data",)
    kind = Float64MultiArray


class DiagnosticsView(MessageView):
    """A ``DiagnosticArray`` (the ground truth's ``fault_state``): its statuses as the message's
    own objects, where each status's values' text is (``values_at``: ``{key: (start, end)}``),
    and, when read through a template, the ``sample_index`` value alone (``index``)."""

    __slots__ = ("index", "status", "values_at")
    kind = DiagnosticArray


def _stamp(sec: int, nanosec: int) -> int:
    return sec * 1_000_000_000 + nanosec


def stamp_ns_at(buf: bytes, at: int = 4) -> int:
    """The stamp (ns) of the header whose ``sec, nanosec`` start at ``at`` in ``buf``."""
    sec, nanosec = _STAMP(buf, at)
    return sec * 1_000_000_000 + nanosec


_HEADER_STAMP = (4, 12)  # sec, nanosec: the first field of a header


def _joint_state_view(buf: bytes) -> JointStateView:
    sec, nanosec, _, names, position, velocity, effort, starts = _joint_state_fields(buf)
    blocks = tuple(zip(starts, (len(position), len(velocity), len(effort)), strict=True))
    view = JointStateView(buf, _stamp(sec, nanosec), _HEADER_STAMP, blocks)
    view.name, view.position, view.velocity, view.effort = names, position, velocity, effort
    return view


def _imu_view(buf: bytes) -> ImuView:
    sec, nanosec, _, v, start = _imu_fields(buf)
    view = ImuView(buf, _stamp(sec, nanosec), _HEADER_STAMP, ((start, 37),))
    view.linear_acceleration = Acceleration(*v[25:28].tolist())
    return view


def _array_view(buf: bytes) -> ArrayView:
    dims, _, data, start = _float64_multi_array_fields(buf)
    stamp = stamp_at = None
    for label, _, _, end in dims:  # as bags.messages.array_stamp_ns reads the message
        if label.startswith(STAMP_LABEL):
            stamp = label_stamp_ns(label)
            if stamp is not None:
                stamp_at = (end - len(label.encode()) + len(STAMP_LABEL), end)
            break
    view = ArrayView(buf, stamp, stamp_at, ((start, len(data)),))
    view.data = data
    return view


def _diagnostics_view(buf: bytes) -> DiagnosticsView:
    header, status, values_at = _diagnostic_array_fields(buf)
    stamp = _stamp(header.stamp.sec, header.stamp.nanosec)
    view = DiagnosticsView(buf, stamp, _HEADER_STAMP, ())
    view.status, view.values_at = status, values_at
    return view


VIEWS: dict[type, Callable[[bytes], MessageView]] = {
    JointState: _joint_state_view,
    Imu: _imu_view,
    Float64MultiArray: _array_view,
    DiagnosticArray: _diagnostics_view,
}


def read(kind: type, data: bytes) -> Any:
    """One serialised message as a :class:`MessageView` where ``kind`` has one and the bytes
    read as its layout, else as :func:`decode` gives it (the same acceptance as ``decode``)."""
    view = _fast(VIEWS, kind, data)
    return view if view is not None else decode(kind, data)


_PAD = (b"", b"\0", b"\0\0", b"\0\0\0")
_U32_BYTES = struct.Struct("<I").pack
_STAMP_BYTES = struct.Struct("<iI").pack
_KEYS: dict[tuple[str, int], bytes] = {}  # a key's bytes at each alignment (keys repeat)


def _text_bytes(value: str, at: int) -> bytes:
    """A string written at payload offset ``at``: padding to 4, its length with the NUL, its
    bytes and the NUL (XCDR1)."""
    data = value.encode()
    return _PAD[-at % 4] + _U32_BYTES(len(data) + 1) + data + b"\0"


def _key_bytes(key: str, at: int) -> bytes:
    piece = _KEYS.get((key, at % 4))
    if piece is None:
        if len(_KEYS) > 4096:  # keys are a status's fixed names; this bounds any other use
            _KEYS.clear()
        piece = _KEYS[key, at % 4] = _text_bytes(key, at % 4)
    return piece


def encode_diagnostic_array(stamp_ns: int, frame_id: str, statuses: list[tuple]) -> bytes:
    """A ``DiagnosticArray`` as a writer puts it on the wire (XCDR1 little endian, aligned
    relative to the payload and padded to 4 as the binding writes it), from ``(level, name,
    message, hardware_id, {key: value})`` per status: what the binding's serialisation of the
    same message gives (a test holds them equal), without building the message's objects."""
    out = [b"\x00\x01\x00\x00", _STAMP_BYTES(stamp_ns // 10**9, stamp_ns % 10**9)]
    at = 8  # payload offset
    piece = _text_bytes(frame_id, at)
    out.append(piece)
    at += len(piece)
    piece = _PAD[-at % 4] + _U32_BYTES(len(statuses))
    out.append(piece)
    at += len(piece)
    for level, name, message, hardware_id, values in statuses:
        out.append(bytes((level,)))
        at += 1
        for text in (name, message, hardware_id):
            piece = _text_bytes(text, at)
            out.append(piece)
            at += len(piece)
        piece = _PAD[-at % 4] + _U32_BYTES(len(values))
        out.append(piece)
        at += len(piece)
        for key, value in values.items():
            piece = _key_bytes(key, at)
            out.append(piece)
            at += len(piece)
            piece = _text_bytes(value, at)
            out.append(piece)
            at += len(piece)
    out.append(_PAD[-at % 4])
    return b"".join(out)


def take_raw(reader: Any, limit: int) -> list[bytes]:
    """Up to ``limit`` serialised messages from a DDS reader (the DDS take alone); instance-state
    notices (no data: a writer went away) are skipped."""
    take, mask = _TAKE or _take()
    got = take(reader._ref, mask, limit)
    if isinstance(got, int):
        from cyclonedds.core import DDSException

        raise DDSException(got, f"Occurred while taking data in {reader!r}")
    return [data for data, info in got if info.valid_data]


_TAKE: tuple[Callable, int] | None = None  # the binding's raw take and its any-state mask


def _take() -> tuple[Callable, int]:
    """Imported once, at the first take (a monitor takes tens of thousands of times a second;
    the import statement and the mask's enum arithmetic cost as much as a take)."""
    global _TAKE
    from cyclonedds._clayer import ddspy_take
    from cyclonedds.core import InstanceState, SampleState, ViewState

    from robohealth_mj.ros2.bus import binding_major

    mask = int(SampleState.Any | ViewState.Any | InstanceState.Any)
    if binding_major() < 11:  # the secured binding's (0.10) take has no mask: it takes any
        _TAKE = (lambda ref, _mask, limit: ddspy_take(ref, limit)), mask
    else:
        _TAKE = ddspy_take, mask
    return _TAKE


def decode_all(
    kind: type, taken: list[bytes], decoder: Callable[[type, bytes], Any] = decode
) -> tuple[list[Any], list[str]]:
    """The messages of :func:`take_raw`, decoded by ``decoder`` (:func:`decode`, or :func:`read`
    for views), and why any could not be (one line each; the caller marks the arm)."""
    messages, problems = [], []
    for data in taken:
        try:
            messages.append(decoder(kind, data))
        except Exception as exc:  # a buffer no decoder reads is that arm's bad input
            problems.append(undecodable(kind, exc))
    return messages, problems


def undecodable(kind: type, exc: Exception) -> str:
    """Why a buffer is not a ``kind``, in one line."""
    return f"undecodable {kind.__name__} ({type(exc).__name__}: {exc})"
