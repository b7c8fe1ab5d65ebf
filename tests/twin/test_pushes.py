"""The hindsight push finder the real pushed logs are judged with: where a joint's residual
leaves its level by a share of its rating, and the most distal joint so loaded."""

from __future__ import annotations

import numpy as np

from robohealth_mj.twin.pushes import most_distal_loaded, pushes

RATED = np.array([330.0, 330.0, 150.0, 56.0, 56.0, 56.0])


def test_a_push_is_found_with_the_most_distal_joint_it_loads_and_short_blips_are_not():
    residual = np.zeros((400, 6))
    residual[100:112, :3] = [40.0, 30.0, 12.0]  # a push on the forearm: base to elbow loaded
    residual[118:122, :3] = [40.0, 30.0, 12.0]  # 0.3 s later: the same push
    residual[250:253, 4] = 10.0  # three ticks: no push
    off, found = pushes(residual, RATED, 0.05)
    assert found == [(100, 121)]
    assert most_distal_loaded(off[100:122], 0.05) == 2
    assert most_distal_loaded(off[100:122], 0.1) == 0  # at 10 % only the base is loaded enough
