"""The monitor's per-sensor path reads the bytes off the wire through byte templates; whatever
arrives, it must assemble exactly what the message path (every message decoded into the
binding's objects) assembles: the same samples, the same problems, the same counts."""

from __future__ import annotations

import copy
import itertools

import numpy as np
import pytest

pytest.importorskip("cyclonedds", reason="the ROS 2 bridge needs cyclonedds: pip install '.[ros2]'")

from robohealth_mj.bags.messages import STAMP_LABEL, MessageFactory
from robohealth_mj.data.read import read_samples
from robohealth_mj.ros2.assembly import ArmAssembler, Assembled
from robohealth_mj.ros2.cdr import MessageView, decode, undecodable
from robohealth_mj.ros2.idl import TYPES, IdlStore
from robohealth_mj.ros2.node import arm_topics, layout_topics
from robohealth_mj.schema import FaultLabel

ARM = "arm3"


def _both(items: list[tuple[str, type, bytes]], poll_every: int = 15, **options) -> tuple:
    """``(topic, kind, bytes)`` through the message path and the byte path, a poll boundary
    every ``poll_every`` messages; each path's samples, problems, duplicates and late."""
    topics = arm_topics(ARM)
    outcomes = []
    for serialized in (False, True):
        assembler, total = ArmAssembler(ARM, topics, **options), Assembled()
        for n, (topic, kind, data) in enumerate(items, 1):
            out = Assembled()
            if serialized:
                assembler.add_serialized(topic, kind, [data], out)
            else:
                try:
                    assembler.add_all(topic, [decode(kind, data)], out)
                except Exception as exc:  # as the monitor's decode_all reports it
                    out.problems.append(f"topic '{topic}': {undecodable(kind, exc)}")
            if n % poll_every == 0 or n == len(items):
                out.extend(assembler.settle())
            total.extend(out)
        outcomes.append(total)
    return outcomes


def _same(a: Assembled, b: Assembled) -> None:
    assert a.problems == b.problems
    assert (a.duplicates, a.late) == (b.duplicates, b.late)
    assert len(a.samples) == len(b.samples)
    for p, q in zip(a.samples, b.samples, strict=True):
        assert (p.recording_run_id, p.sample_index, p.t, p.fault, p.segment) == (
            q.recording_run_id, q.sample_index, q.t, q.fault, q.segment)  # fmt: skip
        assert p.x.dtype == q.x.dtype and p.x.tobytes() == q.x.tobytes()


def _ticks(corpus, n: int, around_a_change: bool = True) -> list[list[tuple[str, object]]]:
    """``n`` ticks' messages, around the held-out session's first change of fault (or, not
    ``around_a_change``, ``n`` ticks whose every layout stays the same: one fault, stamps and
    sample indices of as many digits)."""
    every = list(itertools.islice(read_samples(corpus / "heldout" / "graphs.jsonl"), 2000))
    change = next(k for k in range(1, len(every)) if every[k].fault != every[k - 1].fault)
    start = max(0, change - n // 2)
    if not around_a_change:
        start = next(k for k in range(40, len(every))
                     if len({(s.fault, len(str(s.sample_index)), len(str(round(s.t * 1e9))))
                             for s in every[k : k + n]}) == 1)  # fmt: skip
    samples = every[start : start + n]
    factory = MessageFactory(IdlStore())
    return [list(factory.sample_messages(s, arm_topics(ARM))) for s in samples]


def _wire(ticks) -> list[tuple[str, type, bytes]]:
    kinds = {t: TYPES[k] for t, k in layout_topics(arm_topics(ARM), "per_sensor").items()}
    return [(t, kinds[t], m.serialize()) for tick in ticks for t, m in tick]


def test_samples_read_through_templates_equal_the_message_path_s(learnable_corpus):
    ticks = _ticks(learnable_corpus, 40)
    a, b = _both(_wire(ticks))
    assert a.problems == [] and len(a.samples) == 40
    _same(a, b)
    classes = {s.fault.fault_class for s in b.samples}
    assert len(classes) > 1  # the truth's template changed with the fault


def test_every_layout_change_and_bad_message_gives_what_the_message_path_gives(
    learnable_corpus,
):
    ticks = _ticks(learnable_corpus, 30)
    js = ticks[3][0][1]  # joint states in another order: a new template, the same features
    order = [5, 3, 1, 0, 2, 4]
    js.name = [js.name[k] for k in order]
    for field in ("position", "velocity", "effort"):
        setattr(js, field, [getattr(js, field)[k] for k in order])
    ticks[5][2][1].header.frame_id = "another_frame"  # an IMU's frame id changes
    ticks[7][2][1].linear_acceleration.x = float("nan")  # named by the full reading
    ticks[9][0][1].position = ticks[9][0][1].position[:5]  # a wrong length
    ticks[11][14][1].status[0].values[1].value = "wrist_3"  # the truth's joint changes
    ticks[13].append(copy.deepcopy(ticks[13][4]))  # a re-delivery: a duplicate
    changed = copy.deepcopy(ticks[15][1])
    changed[1].effort = [v + 1.0 for v in changed[1].effort]
    ticks[15].append(changed)  # a second, different message at a used stamp
    items = _wire(ticks)
    at = next(k for k, (t, _, _) in enumerate(items) if t.endswith("/imu") and k > 17 * 15)
    topic, kind, data = items[at]
    items[at] = (topic, kind, data[:-9])  # a truncated buffer: undecodable
    at = next(k for k, (t, _, _) in enumerate(items) if t.endswith("/joint_states") and k > 19 * 15)
    topic, kind, data = items[at]
    name = data.index(b"elbow")
    items[at] = (topic, kind, data[:name] + b"E" + data[name + 1 :])  # same length, new name
    at = next(k for k, (t, _, _) in enumerate(items) if t.endswith("/vibration") and k > 21 * 15)
    topic, kind, _ = items[at]
    xcdr2 = [m for tick in ticks for _, m in tick][at].serialize(use_version_2=True)
    items[at] = (topic, kind, xcdr2)  # not this layout's encoding: the binding reads it
    a, b = _both(items)
    _same(a, b)
    assert a.duplicates == 1 and len(a.problems) >= 6
    assert any("NaN or Inf" in p for p in a.problems)
    assert any("undecodable Imu" in p for p in a.problems)
    assert any("joint 'elbow' missing" in p for p in a.problems)


def test_arrays_without_a_stamp_and_a_growing_sample_index_assemble_alike(learnable_corpus):
    ticks = _ticks(learnable_corpus, 12)
    for tick in ticks:
        for topic, msg in tick:  # one joint's arrays carry no stamp: paired by arrival
            if topic.endswith("wrist_2/vibration"):
                msg.layout.dim = [d for d in msg.layout.dim if not d.label.startswith(STAMP_LABEL)]
    for k, tick in enumerate(ticks):  # the truth's sample index passes 99 -> 100
        index = next(v for v in tick[14][1].status[0].values if v.key == "sample_index")
        index.value = str(95 + k)
    a, b = _both(_wire(ticks), poll_every=7)
    assert a.problems == [] and [s.sample_index for s in a.samples] == list(range(95, 107))
    _same(a, b)


def test_a_message_kept_as_bytes_is_read_through_its_template(learnable_corpus):
    """What the templates keep is the message's bytes and stamp; reading it in full gives the
    message the binding decodes (a template gone stale would give another one)."""
    items = _wire(_ticks(learnable_corpus, 3, around_a_change=False))
    assembler = ArmAssembler(ARM, arm_topics(ARM))
    kept = []
    for topic, kind, data in items:
        template = assembler.templates.get(topic)
        view = template.view(data) if template is not None else None
        assembler.add_serialized(topic, kind, [data], Assembled())
        if view is not None:
            kept.append((kind, data, view))
    assert len(kept) == 2 * 15  # after the first tick, every topic's message matched
    for kind, data, view in kept:
        assert isinstance(view, MessageView) and view.raw is data
        assert view.message() == decode(kind, data)
    truth = [v for _, _, v in kept if v.template.truth is not None]
    assert truth and all(isinstance(v.template.truth[0], FaultLabel) for v in truth)
    first = int(next(v.value for v in decode(*items[14][1:]).status[0].values
                     if v.key == "sample_index"))  # fmt: skip
    np.testing.assert_array_equal([v.index for v in truth], [first + 1, first + 2])


def test_the_aggregated_layout_reads_through_its_template_alike(learnable_corpus):
    topics = arm_topics(ARM)
    every = list(itertools.islice(read_samples(learnable_corpus / "heldout" / "graphs.jsonl"), 60))
    factory = MessageFactory(IdlStore())
    kinds = {t: TYPES[k] for t, k in layout_topics(topics, "aggregated").items()}
    ticks = [[(topics.aggregated, factory.aggregated(s)), (topics.fault_state,
              factory.fault_state(s))] for s in every[20:50]]  # fmt: skip
    ticks[4][0][1].data[17] = float("nan")
    ticks[6][0][1].data = ticks[6][0][1].data[:-1]
    items = [(t, kinds[t], m.serialize()) for tick in ticks for t, m in tick]
    a, b = _both(items, poll_every=4, aggregated=topics.aggregated)
    _same(a, b)
    assert len(a.samples) == 28 and len(a.problems) == 2
