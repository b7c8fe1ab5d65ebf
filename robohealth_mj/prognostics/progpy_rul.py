"""RUL by ProgPy: a degradation state ``[index, rate]`` tracked by a particle filter over the
sessions and propagated by Monte Carlo to the threshold (NASA's ProgPy, ``progpy`` on PyPI).

The model: the index grows at ``rate`` per day, the rate itself wanders (process noise), the
index is observed with noise; the event is the index reaching the threshold. Unlike the trend line
it weighs the whole history through the filter and lets the rate change (accelerating wear).
ProgPy is a research-side extra (``pip install robohealth_mj[prognostics]``): the torch-free
monitor uses :class:`~robohealth_mj.prognostics.rul.TrendRul` and does not import this module.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robohealth_mj.prognostics.rul import RulEstimate


def _model_class():
    from progpy import LinearModel

    class WearModel(LinearModel):
        """dh/dt = r, dr/dt = 0 (+ noise); z = h; event state 1 - h / threshold."""

        inputs: list[str] = []  # noqa: RUF012
        states = ["h", "r"]  # noqa: RUF012
        outputs = ["z"]  # noqa: RUF012
        events = ["failure"]  # noqa: RUF012
        A = np.array([[0.0, 1.0], [0.0, 0.0]])
        C = np.array([[1.0, 0.0]])
        F = None
        default_parameters = {"threshold": 0.8, "x0": {"h": 0.0, "r": 0.0}}  # noqa: RUF012

        def event_state(self, x):
            return {"failure": 1.0 - x["h"] / self.parameters["threshold"]}

        def threshold_met(self, x):
            return {"failure": x["h"] >= self.parameters["threshold"]}

    return WearModel


@dataclass(frozen=True)
class ProgpyRul:
    threshold: float = 0.8
    particles: int = 200
    samples: int = 100
    index_noise: float = 0.03  # the observation noise of the session index
    rate_noise: float = 0.004  # how much the rate may change per day
    horizon_days: float = 120.0
    min_sessions: int = 3
    seed: int = 0

    def estimate(self, days: np.ndarray, index: np.ndarray) -> RulEstimate:
        from progpy.predictors import MonteCarlo
        from progpy.state_estimators import ParticleFilter
        from progpy.uncertain_data import MultivariateNormalDist

        d = np.asarray(days, float)
        h = np.asarray(index, float)
        if len(d) < self.min_sessions:
            return RulEstimate(
                math.inf, math.inf, math.inf, float(h[-1]) if len(h) else math.nan, 0.0, False
            )
        np.random.seed(self.seed)  # ProgPy draws from NumPy's global generator
        model = _model_class()(
            threshold=self.threshold,
            process_noise={"h": 1e-4, "r": self.rate_noise},
            measurement_noise={"z": self.index_noise},
        )
        x0 = MultivariateNormalDist(
            ["h", "r"], [float(h[0]), 0.0], np.diag([self.index_noise**2, 0.02**2])
        )
        pf = ParticleFilter(
            model,
            x0,
            num_particles=self.particles,
            t0=float(d[0]),
            dt=1.0,
            measurement_noise={"z": self.index_noise},
        )
        for t, z in zip(d[1:], h[1:], strict=True):
            pf.estimate(float(t), {}, {"z": float(z)})
        x = pf.x
        mean = x.mean
        mc = MonteCarlo(model)
        result = mc.predict(
            x, dt=1.0, horizon=self.horizon_days, n_samples=self.samples, t0=float(d[-1])
        )
        toe = (
            np.array(
                [
                    s["failure"] if s["failure"] is not None else math.inf
                    for s in result.time_of_event
                ],
                float,
            )
            - d[-1]
        )
        rates = np.array([s["r"] for s in x.sample(self.samples)])
        rising = float(np.quantile(rates, 0.05)) > 0
        low, mid, high = np.quantile(np.where(np.isfinite(toe), toe, 1e9), [0.05, 0.5, 0.95])
        as_days = [math.inf if v >= 1e8 else max(float(v), 0.0) for v in (mid, low, high)]
        return RulEstimate(*as_days, float(mean["h"]), float(mean["r"]), rising)
