"""Byte templates of one topic's messages, and samples gathered from the bytes they point at.

A publisher's consecutive messages on one topic differ only in their stamp and their numbers: the
same frame id, joint names, array lengths and labels, at the same places. Once one message of a
topic has been read in full (:func:`robohealth_mj.ros2.cdr.read`, which checks it as the binding
would), its bytes outside the stamp and the blocks of doubles are the topic's template. A later
message of the same length whose bytes there are the same is the same layout with other numbers:
only its stamp is read on arrival, and when its tick completes, one gather over the tick's joined
bytes puts every number where the sample's features want it. A message that differs anywhere
outside those parts is read in full again (and becomes the template if it reads).

``tests/ros2/test_templates.py`` holds the samples equal to those of the full reading, on every
layout change and on damaged messages.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robohealth_mj.bags.joints import joint_order
from robohealth_mj.bags.messages import message_values_layout, truth_from_status
from robohealth_mj.bags.topics import VIBRATION_FIELDS
from robohealth_mj.ros2.cdr import (
    ArrayView,
    DiagnosticsView,
    ImuView,
    JointStateView,
    MessageView,
    stamp_ns_at,
)
from robohealth_mj.schema import N_FEATURES, N_JOINTS, N_NODES, STATE_FEATURES, FaultLabel

_IMU_ACCELERATION = np.arange(25, 28)  # linear acceleration among an IMU message's 37 doubles
_DOUBLE_BYTES = np.arange(8)
_NO_OFFSETS = np.zeros(0, np.intp)


class Template:
    """One topic's message layout: its length, the bytes that must repeat, where its stamp is,
    and the byte offsets of the doubles a sample takes from it (in the sample's order)."""

    __slots__ = ("blocks", "cls", "fixed", "index_at", "label_stamp", "length", "offsets",
                 "stamp_at", "truth")  # fmt: skip

    def __init__(
        self, view: MessageView, offsets: np.ndarray, index_at: tuple[int, int] | None = None
    ) -> None:
        """``index_at``: the ground truth's sample index, the one value of a ``fault_state``
        that changes every tick (its class, joint, severity and segment change only when the
        fault does: then the layout differs and the message is read in full)."""
        raw = view.raw
        moving = sorted([*([view.stamp_at] if view.stamp_at else []),
                         *((start, start + 8 * n) for start, n in view.blocks if n),
                         *([index_at] if index_at else [])])  # fmt: skip
        fixed, at = [], 0
        for start, end in moving:
            if start > at:
                fixed.append((at, start, raw[at:start]))
            at = end
        if at < len(raw):
            fixed.append((at, len(raw), raw[at:]))
        self.cls, self.length, self.fixed = type(view), len(raw), tuple(fixed)
        self.stamp_at, self.blocks, self.offsets = view.stamp_at, view.blocks, offsets
        self.label_stamp = isinstance(view, ArrayView)  # digits in a label, not sec + nanosec
        self.index_at = index_at
        self.truth: tuple[FaultLabel, str, str] | None = None  # label, segment's JSON, run id

    def view(self, buf: bytes) -> MessageView | None:
        """``buf`` as a message of this layout (only its stamp read), or ``None`` when it is
        not one."""
        if len(buf) != self.length:
            return None
        for start, end, expected in self.fixed:
            if buf[start:end] != expected:
                return None
        stamp_at = self.stamp_at
        if stamp_at is None:
            stamp = None
        elif self.label_stamp:
            try:
                stamp = int(buf[stamp_at[0] : stamp_at[1]])
            except ValueError:
                return None  # read in full: the stamp is then what that reading says
        else:
            stamp = stamp_ns_at(buf, stamp_at[0])
        view = self.cls.__new__(self.cls)
        if self.index_at is not None:
            try:
                view.index = int(buf[self.index_at[0] : self.index_at[1]])
            except ValueError:
                return None
        view.raw, view.stamp_ns, view.template = buf, stamp, self
        view.stamp_at, view.blocks = stamp_at, self.blocks
        return view


def template_of(view: MessageView, role: str, joints: Sequence[str]) -> Template | None:
    """The template a sample can be gathered through for a message of ``role``
    (``joint_states``, ``joint_errors``, ``imu``, ``vibration``), or ``None`` where the message
    would not assemble (wrong joints, wrong lengths: the full reading then says why)."""
    if isinstance(view, JointStateView) and role in ("joint_states", "joint_errors"):
        try:
            order = joint_order(view.name, joints)
        except ValueError:
            return None
        index = np.arange(len(joints)) if order is None else np.asarray(order)
        fields = (0, 1, 2) if role == "joint_states" else (0, 2)  # position, velocity, effort
        if any(view.blocks[f][1] != len(view.name) for f in fields):
            return None
        columns = [view.blocks[f][0] + 8 * index for f in fields]
        return Template(view, np.stack(columns, axis=-1))  # [joints, fields]
    if isinstance(view, ImuView) and role == "imu":
        return Template(view, view.blocks[0][0] + 8 * _IMU_ACCELERATION)
    if isinstance(view, DiagnosticsView) and role == "truth":
        return _truth_template(view)
    if isinstance(view, ArrayView) and role == "aggregated":
        start, n = view.blocks[0]
        return Template(view, start + 8 * np.arange(n)) if n == N_NODES * N_FEATURES else None
    if isinstance(view, ArrayView) and role == "vibration":
        start, n = view.blocks[0]
        if n != len(VIBRATION_FIELDS):
            return None
        return Template(view, start + 8 * np.arange(n))
    return None


def _truth_template(view: DiagnosticsView) -> Template | None:
    """A ``fault_state``'s template, with its truth read once (``None`` where it does not read:
    the full reading then says why)."""

    def refuse(_key: str, message: str) -> ValueError:
        return ValueError(message)

    try:
        label, view.index, _, run_id = truth_from_status(view, refuse)
    except ValueError:
        return None
    values = {kv.key: kv.value for kv in view.status[0].values}
    template = Template(view, _NO_OFFSETS, view.values_at[0]["sample_index"])
    template.truth = (label, values["segment"], run_id)
    return template


class SampleGather:
    """A tick's features from its messages' bytes, through their templates: the messages are
    joined, and one gather reads every double the sample needs (per combination of templates,
    the byte index is built once). ``layout``: ``per_sensor`` (joint states, tracking error,
    six IMUs, six vibration arrays), ``joints`` (the first two) or ``aggregated`` (one array
    holding the features as they are)."""

    def __init__(self, layout: str) -> None:
        self.layout = layout
        if layout == "aggregated":
            base = np.zeros((N_NODES, N_FEATURES), np.float32)
            dest = src = np.arange(base.size)
        else:
            base, dest, src = message_values_layout()
            keep = src < (src.size if layout == "per_sensor" else N_JOINTS * len(STATE_FEATURES))
            dest, src = dest[keep], src[keep]
        self.base, self.dest, self.src = base, dest, src
        self._index: dict[tuple[Template, ...], np.ndarray] = {}

    def features(self, messages: list[MessageView]) -> np.ndarray:
        """``x [N_NODES, N_FEATURES]`` (float32) of one tick's messages, each with its
        template, in the layout's order."""
        key = tuple(m.template for m in messages)  # held by the key: no id reused
        index = self._index.get(key)
        if index is None:
            index = self._index[key] = self._byte_index([m.template for m in messages])
        values = np.frombuffer(b"".join([m.raw for m in messages]), np.uint8)[index].view("<f8")
        x = self.base.copy()
        x.flat[self.dest] = values[self.src]
        return x

    def _byte_index(self, templates: list[Template]) -> np.ndarray:
        if len(self._index) > 64:  # templates come and go only when a publisher changes
            self._index.clear()
        starts = np.cumsum([0, *(t.length for t in templates)])
        at = [t.offsets + s for t, s in zip(templates, starts, strict=False)]
        if self.layout == "aggregated":
            offsets = at[0]
        else:
            state = np.concatenate(at[:2], axis=-1)  # [6, 5]: joint states' 3, tracking error's 2
            parts = [state.ravel()]
            if self.layout == "per_sensor":
                imus, vibrations = np.stack(at[2:8]), np.stack(at[8:14])
                parts.append(np.concatenate([imus, vibrations], axis=-1).ravel())
            offsets = np.concatenate(parts)
        return (offsets[:, None] + _DOUBLE_BYTES).ravel()
