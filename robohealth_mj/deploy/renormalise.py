"""An unseen arm's healthy running z-scored as the training arms' healthy running was, place by
place: the normalisation refitted at commissioning.

A model read on an arm it never trained on sees each place of the graph as that arm runs it. A
maker's conventions show there: the Gen3's roll axes point down, so its sensor packages read
gravity of the other sign from its training arms' (983 of their healthy spreads at the base,
``studies/arms/results/healthy_offsets.md``), and its programs hold other poses and loads.
Commissioning has the arm's healthy minutes; this refits each node and channel's mean and std so
that they map the arm's healthy running onto the training arms' healthy running (``shift``: the
offset only; ``moments``: offset and spread; ``sensors``: the offsets of the sensor packages'
channels alone, leaving the joint states with what differs for real, the arm's poses and loads).
With ``moments`` a fault departs from the healthy running in units of this arm's own healthy
spread. Which one a model gains from is measured in ``studies/arms`` (networks: ``shift``; trees:
none).
"""

from __future__ import annotations

import numpy as np

from robohealth_mj import schema

MATCHES = ("none", "sensors", "shift", "moments")
FLAT = 1e-6  # a channel this still (a type flag, an absent place, a masked channel) is not refitted


def healthy_moments(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and std ``[N, F]`` of node features ``nodes [T, N, F]`` (healthy running)."""
    x = nodes.astype(np.float64)
    return x.mean(axis=0), x.std(axis=0)


def match_healthy(
    mean: np.ndarray,
    std: np.ndarray,
    reference: tuple[np.ndarray, np.ndarray],
    arm: tuple[np.ndarray, np.ndarray],
    match: str,
) -> tuple[np.ndarray, np.ndarray]:
    """The normalisation ``mean, std [N, F]`` refitted so that the arm's healthy moments
    (``arm``: mean, std ``[N, F]``) z-score to what the training arms' healthy moments
    (``reference``) did under the training normalisation. Channels flat on either side keep
    their training normalisation."""
    if match not in MATCHES:
        raise ValueError(f"match: one of {', '.join(MATCHES)}, got {match!r}")
    if match == "none":
        return mean, std
    (mu_ref, sd_ref), (mu_arm, sd_arm) = reference, arm
    live = (sd_ref > FLAT) & (sd_arm > FLAT)
    if match == "sensors":
        live[:, : schema.SENSOR_CHANNELS.start] = False
    ratio = np.ones_like(sd_ref)
    if match == "moments":
        ratio[live] = sd_arm[live] / sd_ref[live]
    # (mu_arm - mean') / std' == (mu_ref - mean) / std, with std' = ratio * std
    matched_mean = np.where(live, mu_arm - ratio * (mu_ref - mean), mean)
    return matched_mean.astype(np.float32), (ratio * std).astype(np.float32)
