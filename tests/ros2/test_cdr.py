"""The monitor's fast decoding of the fixed message layouts equals the binding's own decoding:
the same object for every message type a sample travels in, and on damaged buffers (truncated,
bytes flipped, another encapsulation, trailing bytes) either the same object or the same refusal.
Skipped, with the reason, where cyclonedds is absent."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("cyclonedds", reason="the ROS 2 bridge needs cyclonedds: pip install '.[ros2]'")

from robohealth_mj.bags.messages import MessageFactory
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.ros2.cdr import DECODERS, decode, decode_all, encode_diagnostic_array
from robohealth_mj.ros2.idl import (
    DiagnosticArray,
    DiagnosticStatus,
    Float64MultiArray,
    Header,
    IdlStore,
    JointState,
    KeyValue,
    MultiArrayDimension,
    MultiArrayLayout,
    Time,
)
from robohealth_mj.schema import FaultLabel, GraphSample


def _messages() -> list:
    """Every message type of one sample in the per-sensor and aggregated layouts, with values
    that reach the layouts' corners (empty sequences, non-ASCII text, NaN, odd lengths)."""
    rng = np.random.default_rng(0)
    x = rng.normal(size=(12, 15)).astype(np.float32)
    sample = GraphSample("arm1", 7, 12.345678, x, FaultLabel("friction", "elbow", 0.6, True), {})
    factory, topics = MessageFactory(IdlStore()), BagTopics.load()
    messages = [m for _, m in factory.sample_messages(sample, topics)]
    messages.append(factory.aggregated(sample))
    messages += [
        JointState(name=[], position=[], velocity=[], effort=[]),
        JointState(name=["é", "joint"], position=[float("nan"), 1.0], velocity=[2.0], effort=[]),
        Float64MultiArray(
            layout=MultiArrayLayout(dim=[MultiArrayDimension("a", 3, 3)], data_offset=1),
            data=[1.0, -0.0, 1e300],
        ),
        DiagnosticArray(
            status=[
                DiagnosticStatus(level=2, name="n", message="", values=[KeyValue("k", "v" * 5)]),
                DiagnosticStatus(level=3, hardware_id="arm2"),
            ]
        ),
    ]
    return messages


def _outcome(kind: type, data: bytes):
    try:
        return "ok", kind.deserialize(data)
    except Exception as exc:  # the binding's refusal, whatever it raises
        return "refused", type(exc)


def _fast(kind: type, data: bytes):
    try:
        return "ok", decode(kind, data)
    except Exception as exc:
        return "refused", type(exc)


def _same(a, b) -> bool:
    """Equal outcomes; messages compared by their bytes (NaN != NaN as a float)."""
    if a[0] != b[0]:
        return False
    return a[1] == b[1] if a[0] == "refused" else a[1].serialize() == b[1].serialize()


def test_the_fast_decoding_gives_the_binding_s_object_on_every_layout():
    messages = _messages()
    assert {type(m) for m in messages} == set(DECODERS)
    for m in messages:
        data = m.serialize()
        assert decode(type(m), data).serialize() == data
        assert _same(_fast(type(m), data), _outcome(type(m), data)), type(m).__name__


def test_damaged_buffers_decode_or_fail_as_the_binding_does():
    rng = np.random.default_rng(1)
    checked = 0
    for m in _messages():
        kind, data = type(m), m.serialize()
        damaged = [data[:n] for n in range(0, len(data), 3)]  # every truncation
        damaged += [b"\x00\x03" + data[2:], data + b"\x00" * 8]  # big endian; trailing bytes
        for _ in range(40):  # flipped bytes: lengths, counts, text, NUL terminators
            flipped = bytearray(data)
            for at in rng.integers(4, len(data), size=2).tolist():
                flipped[at] = int(rng.integers(0, 256))
            damaged.append(bytes(flipped))
        for buf in damaged:
            assert _same(_fast(kind, buf), _outcome(kind, buf)), (kind.__name__, buf.hex())
            checked += 1
    assert checked > 500


def test_diagnoses_encoded_as_bytes_equal_the_binding_s_serialisation():
    """The monitor writes each /health_diagnosis as bytes it encodes itself; they are the
    binding's serialisation of the same message (padded to 4 bytes, as the binding writes)."""
    statuses = [
        [(2, "health_diagnosis", "ALARM jam @ elbow (raised)", "model-1",
          {"fault_class": "jam", "p.none": "0.0001", "score.elbow": "0.9731"})],
        [(0, "", "", "", {})],
        [(1, "é", "ümlaut ✓", "x" * 7, {"": "", "k": "v" * 13}), (3, "b", "c", "d", {})],
    ]  # fmt: skip
    for stamp, status in zip((0, 1_700_000_000_123_456_789, 999_999_999), statuses, strict=True):
        message = DiagnosticArray(
            header=Header(stamp=Time(sec=stamp // 10**9, nanosec=stamp % 10**9), frame_id=""),
            status=[DiagnosticStatus(level=lv, name=n, message=m, hardware_id=h,
                                     values=[KeyValue(k, v) for k, v in kv.items()])
                    for lv, n, m, h, kv in status],
        )  # fmt: skip
        data = message.serialize()
        assert encode_diagnostic_array(stamp, "", status) == data.ljust(
            -(-len(data) // 4) * 4, b"\0"
        )


def test_a_buffer_no_decoder_reads_is_a_problem_line_and_the_others_decode():
    good = JointState(name=["a"], position=[1.0], velocity=[2.0], effort=[3.0])
    data = good.serialize()
    messages, problems = decode_all(JointState, [data, data[:9], data])
    assert messages == [good, good]
    assert len(problems) == 1 and problems[0].startswith("undecodable JointState (")
