"""``bench contact``: what the contact watch costs a fleet tick.

Every stream holds a pose with a noisy residual, so every stream is watched: the worst case (a
moving arm is not). Per stream count, the median and p95 wall time of one watch update over all
streams, and its share of the 20 Hz tick (50 ms), measured in one run. The watch runs where the
model carries contact thresholds (a commissioned model); a fleet of uncommissioned models pays
nothing. Then what placing one contact on a link costs
(:func:`robohealth_mj.arms.contact_place.place`, run when a contact is confirmed and again as it
grows): the tick of the stream it is on pays it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robohealth_mj import schema
from robohealth_mj.arms.contact_place import place
from robohealth_mj.benchmarks.common import latency_ms
from robohealth_mj.runtime.contact import ContactBank, ContactPolicy
from robohealth_mj.sim.contact_surface import arm_surface

TICK_MS = 50.0
_RESIDUAL = schema.feature_index("effort_residual")


def resting_fleet(n: int, arm: str, rng: np.random.Generator) -> Callable[[], None]:
    """One tick of ``n`` streams that hold a pose, through a fresh watch, as a callable."""
    bank = ContactBank(ContactPolicy(), np.full(schema.N_JOINTS, 1.0), arm, n)
    slots = np.arange(n)
    x = np.zeros((n, schema.N_NODES, schema.N_FEATURES), np.float32)

    def tick() -> None:
        x[:, : schema.N_JOINTS, _RESIDUAL] = rng.normal(0.0, 0.05, (n, schema.N_JOINTS))
        bank.update(slots, x)

    return tick


def bench_contact(streams: list[int], arm: str = "ur10e", calls: int = 50) -> list[dict]:
    """One row per stream count: ``streams``, ``median_ms``, ``p95_ms``, ``tick_share``."""
    rng = np.random.default_rng(0)
    print("| streams at rest | update median ms | p95 ms | share of a 50 ms tick |")
    print("|---|---|---|---|")
    rows = []
    for n in streams:
        tick = resting_fleet(n, arm, rng)
        for _ in range(ContactPolicy().level_ticks):  # every stream settled and watched
            tick()
        median, p95 = latency_ms(tick, calls=calls, warmup=0)
        rows.append({"streams": n, "median_ms": median, "p95_ms": p95,
                     "tick_share": median / TICK_MS})  # fmt: skip
        print(f"| {n} | {median:.2f} | {p95:.2f} | {median / TICK_MS:.3f} |", flush=True)
    surface = arm_surface(arm)
    j = schema.N_JOINTS
    noise = rng.uniform(0.5, 10.0, j)
    pushes = [(rng.uniform(-3.0, 3.0, j), noise * rng.normal(0.0, 10.0, j)) for _ in range(calls)]
    calls_left = iter(pushes)

    def one() -> None:
        q, torque = next(calls_left)
        place(surface, q, torque, noise)

    median, p95 = latency_ms(one, calls=calls, warmup=0)
    print(f"\n| placing a contact on a link ({arm}, {len(surface.link)} surface points) "
          "| median ms | p95 ms | share of a 50 ms tick |")  # fmt: skip
    print("|---|---|---|---|")
    print(f"| one placement, random poses and torques | {median:.2f} | {p95:.2f} "
          f"| {median / TICK_MS:.3f} |")  # fmt: skip
    rows.append({"placing_median_ms": median, "placing_p95_ms": p95})
    return rows
