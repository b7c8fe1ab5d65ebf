"""What the monitor's own work costs, alone (no DDS): decoding and assembling one per-sensor
message, the message path (every message decoded into the binding's objects) against the byte
path (templates, one gather a tick) on the same serialised ticks; a runtime step per sample at
each batch size; one diagnosis's encoding.

    python studies/ros2/monitor_costs.py --data DIR --model M.onnx [--ticks 400] [--rounds 3]

Both paths must give the same samples (checked here too; ``tests/ros2/test_templates.py`` holds
it on every layout change and on bad messages).
"""

from __future__ import annotations

import argparse
import itertools
import time

from robohealth_mj.bags.messages import MessageFactory
from robohealth_mj.data.arrays import resolve_recordings
from robohealth_mj.data.read import read_samples
from robohealth_mj.ros2.assembly import ArmAssembler, Assembled
from robohealth_mj.ros2.cdr import decode, encode_diagnostic_array
from robohealth_mj.ros2.idl import TYPES, IdlStore
from robohealth_mj.ros2.node import arm_topics, layout_topics
from robohealth_mj.runtime.runtime import ModelRuntime


def assemble(ticks: list, serialized: bool) -> tuple[float, list]:
    topics = arm_topics("arm1")
    assembler, samples = ArmAssembler("arm1", topics), []
    started = time.perf_counter()
    for tick in ticks:
        out = Assembled()
        for topic, kind, data in tick:
            if serialized:
                assembler.add_serialized(topic, kind, [data], out)
            else:
                assembler.add_all(topic, [decode(kind, data)], out)
        out.extend(assembler.settle())
        samples += out.samples
    return time.perf_counter() - started, samples


def step_cost(model: str, samples: list, batch: int, arms: int = 50, ticks: int = 80) -> float:
    """Microseconds a sample of ``ModelRuntime.tick`` when each step diagnoses ``batch`` arms
    (after the windows fill)."""
    runtime, names = ModelRuntime(model), [f"arm{k}" for k in range(arms)]
    seconds, counted = 0.0, 0
    for tick in range(ticks):
        base = samples[tick % len(samples)]
        for start in range(0, arms, batch):
            for arm in names[start : start + batch]:
                runtime.submit(arm, base.__class__("b", tick, tick / 20, base.x, base.fault,
                                                   base.segment))  # fmt: skip
            started = time.perf_counter()
            runtime.tick()
            if tick >= ticks // 2:
                seconds += time.perf_counter() - started
                counted += len(names[start : start + batch])
    return seconds / counted * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True, help="a recording to serialise")
    parser.add_argument("--model", required=True, help="an exported model.onnx")
    parser.add_argument("--ticks", type=int, default=400)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    recording = resolve_recordings([args.data])[0]
    samples = list(itertools.islice(read_samples(recording), args.ticks))
    factory, topics = MessageFactory(IdlStore()), arm_topics("arm1")
    kinds = {t: TYPES[k] for t, k in layout_topics(topics, "per_sensor").items()}
    ticks = []
    for k, s in enumerate(samples):  # stamps of one digit count: the templates' steady state
        s = s.__class__("bench", k, 1000.0 + k / 20, s.x, s.fault, s.segment)
        ticks.append([(t, kinds[t], m.serialize()) for t, m in factory.sample_messages(s, topics)])
    messages = sum(len(t) for t in ticks)
    print(f"{len(ticks)} ticks, {messages} messages; us a message (best of {args.rounds})")
    best = {}
    for _ in range(args.rounds):
        for serialized in (False, True):
            seconds, got = assemble(ticks, serialized)
            best[serialized] = min(best.get(serialized, seconds), seconds)
            if serialized:
                _, reference = assemble(ticks, False)
                same = all(a.x.tobytes() == b.x.tobytes() and a.fault == b.fault
                           and a.sample_index == b.sample_index for a, b in
                           zip(got, reference, strict=True))  # fmt: skip
                assert same, "the byte path assembled other samples"
    message_path, byte_path = (best[k] / messages * 1e6 for k in (False, True))
    print(f"  decode + assemble, message path: {message_path:.1f} us")
    ratio = message_path / byte_path
    print(f"  decode + assemble, byte path:    {byte_path:.1f} us ({ratio:.1f}x)")
    values = {"fault_class": "friction", "joint": "elbow", "confidence": "0.9731",
              "alarm": "raised", "alarm_class": "", "alarm_joint": "", "valid": "true",
              "sample_index": "12345", **{f"p.{c}": "0.1234" for c in range(7)},
              **{f"score.{j}": "0.1234" for j in range(6)}}  # fmt: skip
    status = [(1, "health_diagnosis", "friction @ elbow (no alarm)", "model", values)]
    n = 5000
    started = time.perf_counter()
    for _ in range(n):
        encode_diagnostic_array(1_700_000_000_123_456_789, "", status)
    print(f"  one diagnosis encoded as bytes: {(time.perf_counter() - started) / n * 1e6:.1f} us")
    for batch in (1, 5, 10, 25, 50):
        cost = step_cost(args.model, samples, batch)
        print(f"  a runtime step diagnosing {batch:>2} arms: {cost:.0f} us a sample")


if __name__ == "__main__":
    main()
