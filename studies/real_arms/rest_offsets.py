"""The twin at rest: the torque residual a joint keeps after the arm stops, on the real UR10e and
on its twin, with MuJoCo's default dry friction and with the friction made to stick.

A real gear sticks: after a move, the drive holds whatever torque it stopped with, and the
residual (measured minus the controller's model torque) keeps an offset for as long as the arm
rests. MuJoCo's dry friction is a soft constraint that gives way below its limit, so the servo
pulls a resting joint onto its target and the simulated residual returns to about zero. A model
trained on such rests learns a tighter rest than the real arm's.

    python studies/real_arms/rest_offsets.py > studies/real_arms/results/rest_offsets.md

Real: the ten logs of the arm holding a pose (``validation_data/*-p<k>.csv``). Simulated: one
healthy session of holds (family ``hold``: one move from rest to a new pose, the pose held) on the
identified twin (``outputs/real_arms/twin/twin.yaml``), recorded once per friction setting into
``outputs/real_arms/rest/``. A rest is a run of at least ``MIN_TICKS`` ticks in which no joint
turns faster than ``STILL_RAD_S``; its offset is the mean residual per joint over the rest, its
spread the standard deviation. Units: N m, as logged and recorded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robohealth_mj import schema
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.common.steps import run_step
from robohealth_mj.runtime.sources import replay_stream
from robohealth_mj.sim.twin_file import mark_recorded, recorded_on

ROOT = Path("outputs/real_arms")
HOLDS = sorted((ROOT / "logs" / "validation_data").glob("*-p[0-9]*.csv"))
TWIN = ROOT / "twin" / "twin.yaml"
MOUNT_M = 0.8  # as campaign.py: the twin on its pedestal
# the friction settings compared: label -> record overrides (the last is campaign.py's STICTION)
SETTINGS = {
    "twin, MuJoCo's default friction": [],
    "twin, sticking friction (`sim.friction_solref=[0.002,1]`)": ["sim.friction_solref=[0.002,1]"],
}
STILL_RAD_S = 0.02
MIN_TICKS = 20  # 1 s at 20 Hz
SIM_SECONDS = 180.0
VEL = schema.feature_index("vel")
RESIDUAL = schema.feature_index("effort_residual")


def rests(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Per rest of the recording or log at ``path``: offsets ``[R, 6]`` and spreads ``[R, 6]``."""
    x = np.stack([s.x for _, s, _ in replay_stream(str(path))])
    still = np.abs(x[:, : schema.N_JOINTS, VEL]).max(axis=1) < STILL_RAD_S
    ticks = np.flatnonzero(still)
    runs = [
        r for r in np.split(ticks, np.flatnonzero(np.diff(ticks) != 1) + 1) if len(r) >= MIN_TICKS
    ]
    residual = x[:, : schema.N_JOINTS, RESIDUAL]
    offsets = [residual[r].mean(axis=0) for r in runs]
    spreads = [residual[r].std(axis=0) for r in runs]
    shape = (-1, schema.N_JOINTS)
    return np.array(offsets).reshape(shape), np.array(spreads).reshape(shape)


def simulated(name: str, overrides: list[str]) -> Path:
    """The healthy hold session on the twin with ``overrides`` (recorded once)."""
    out = ROOT / "rest" / name
    graphs = out / "graphs.jsonl"
    if not recorded_on(out, graphs, TWIN):
        run_step("robohealth_mj.record", "arm=ur10e", f"sim.twin={TWIN}",
                 f"sim.mount_height_m={MOUNT_M}", "curriculum.families=[hold]", "faults=none",
                 f"session.duration_s={SIM_SECONDS}", "seed=3", f"session.out_dir={out}",
                 "session.progress=false", *overrides, quiet=True)  # fmt: skip
        mark_recorded(out, TWIN)
    return graphs


def row(label: str, offsets: np.ndarray, spreads: np.ndarray) -> str:
    cells = [f"{a:.2f} / {b:.2f} / {c:.2f}" for a, b, c in zip(
        np.median(np.abs(offsets), axis=0), np.quantile(np.abs(offsets), 0.9, axis=0),
        np.median(spreads, axis=0), strict=True)]  # fmt: skip
    return f"| {label} | {len(offsets)} | " + " | ".join(cells) + " |"


def main() -> None:
    if not HOLDS or not TWIN.is_file():
        raise SystemExit("no hold logs or twin: run studies/real_arms/campaign.py first")
    print("## The residual at rest (N m): |offset| median / p90 / spread median\n")
    print("| source | rests | " + " | ".join(schema.JOINT_NAMES) + " |")
    print("|---|---|" + "---|" * schema.N_JOINTS)
    real = [rests(p) for p in HOLDS]
    print(row(f"real UR10e, {len(HOLDS)} hold logs", np.concatenate([o for o, _ in real]),
              np.concatenate([s for _, s in real])))  # fmt: skip
    for k, (label, overrides) in enumerate(SETTINGS.items()):
        print(row(label, *rests(simulated(f"setting{k}", overrides))))
    print(f"\nA rest: {MIN_TICKS} ticks or more with every joint under {STILL_RAD_S} rad/s; "
          f"simulated: {SIM_SECONDS:.0f} s of holds (seed 3), no faults. Command: "
          "`python studies/real_arms/rest_offsets.py`.")  # fmt: skip


if __name__ == "__main__":
    with one_line_errors("rest_offsets"):
        main()
