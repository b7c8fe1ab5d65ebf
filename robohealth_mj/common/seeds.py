"""Named random streams: every random draw comes from one seed through a stream named here.

A stream is ``numpy.random.default_rng([seed, id, *index])``. Two streams with one id would draw
the same numbers from the same seed, and so would ``[seed, id]`` and ``[seed, id, 0]``: NumPy's
``SeedSequence`` pads a short key with zeros. So every id here is used by one stream only (a
test checks it, and that no draw bypasses this table). Ids that were in use before the table
kept their numbers, so recordings made before it stay byte for byte; the three that collided
(the cruise via poses with the fault schedule, the twin's replay with the physical faults, the
randomised fault parameters with the pick-and-place poses) moved to new ids, none of which a
default recording draws.
"""

from __future__ import annotations

import numpy as np

STREAMS: dict[str, int] = {
    "curriculum.order": 0,  # the segments' order per pass: [seed, 0, pass]
    "curriculum.segment": 1,  # a segment's draw per visit: [seed, 1, visit]
    "recording.sensors": 2,  # the sensor package's noise
    "curriculum.pick_place": 3,  # a pick-and-place segment's poses: [seed, 3, visit]
    "faults.schedule": 4,  # the faults' order per pass: [seed, 4, pass]
    "faults.physics": 5,  # the physical faults' draws
    "faults.readings": 6,  # the reading faults' draws
    "curriculum.cruise": 7,  # a cruise segment's via pose: [seed, 7, visit] (was 4)
    "twin.replay": 8,  # the logged program's order and speeds (was 5)
    "faults.parameters": 9,  # randomised fault parameters (was 3)
    "lives.draw": 11,  # a lives role's modes, paths and joints, from its seed
    "lives.path": 12,  # one life's wear path, from its seed
    "sim.variation": 18,  # an arm's drawn variation factors
    "graphs.placement": 22,  # a random sensor placement
}


def stream(name: str, seed: int, *index: int) -> np.random.Generator:
    """The generator of stream ``name`` for ``seed`` (and the pass or visit it is drawn for)."""
    return np.random.default_rng([int(seed), STREAMS[name], *(int(i) for i in index)])
