"""Write the ready models the wheel ships (``ready_models/``): each run's exported model, a model
card from its own evaluation files, and the sample log, a minute of the held-out session as a UR
controller's RTDE log, around a fault whose truth the card states.

    python studies/ready_models/make_ready.py outputs/ready outputs/corpus/standard
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np

from robohealth_mj.common.atomic import atomic_write_text
from robohealth_mj.data.arrays import load_recordings
from robohealth_mj.logs.rtde_writer import write_rtde_csv
from robohealth_mj.runtime.metadata import read_metadata
from robohealth_mj.runtime.ready import SAMPLE_FILE
from robohealth_mj.schema import FAULT_CLASSES, JOINT_NAMES

READY = Path(__file__).resolve().parents[2] / "ready_models"
SAMPLE_S = 60.0  # the sample's length: 20 s healthy, then the fault's onset
TICK_S = 0.05

# What each ready model reads and who it is for; the run's own files give every figure.
PROFILES = {
    "full": (
        "the full sensor package: per joint the controller's channels and an IMU-and-"
        "vibration package (the simulator's, or a retrofit that matches it)",
        "a recording of this project (graphs.jsonl), a bag of its per-sensor topics, or "
        "the live bus with ros2.layout=per_sensor",
    ),
    "stock": (
        "the channels a UR controller reports over RTDE: actual and target position, "
        "velocity, actual and target current (the torque residual), no sensor package",
        "a UR controller log (RTDE CSV, the ur_rtde column map) or any log a column map "
        "reads; file=sample is one",
    ),
    "ur_driver": (
        "what the UR ROS 2 driver publishes at its defaults: /joint_states (position, "
        "velocity, effort) and the trajectory controller's tracking error; no torque "
        "model, so no torque residual",
        "a live UR arm through its ROS 2 driver (source=ros2 ros2.layout=ur_driver), "
        "or a bag of those topics",
    ),
}


USE = {  # the one command that runs each on what it reads
    "full": "python -m robohealth_mj.monitor model=full file=graphs.jsonl",
    "stock": "python -m robohealth_mj.monitor model=stock file=sample   # or file=YOUR_LOG.csv",
    "ur_driver": "python -m robohealth_mj.monitor model=ur_driver source=ros2 "
    "ros2.layout=ur_driver",
}


def _metrics(run: Path, name: str) -> dict:
    return json.loads((run / f"eval_{name}.json").read_text())["metrics"]


def _card(name: str, run: Path, meta: dict) -> str:
    reads, feeds = PROFILES[name]
    held, probe = _metrics(run, "heldout"), _metrics(run, "probe")
    row = "| {} | {:.3f} | {:.3f} | {:.3f} |"
    labels = meta.get("label_set", meta["classes"])  # what the profile's channels can see
    classes = ", ".join(json.loads(labels) if isinstance(labels, str) else labels)
    return "\n".join(
        [
            f"# Ready model `{name}` ({meta['variant']}, W = {meta['window']})",
            "",
            f"**Reads** {reads}. **Feed it** {feeds}.",
            f"**Calls** {classes}, and the joint of a fault.",
            "",
            "## Data and arm",
            "Trained on the standard simulated corpus (`python -m robohealth_mj.corpus`: 12 "
            "sessions "
            "of the speed x payload curriculum, every fault mode at three severities on every "
            f"joint), on the nominal {meta['arm']} from UR's published description, seed 42; "
            "selected on a validation split of whole runs.",
            "",
            "## Figures (windows of sessions it never saw)",
            "| set | accuracy | macro-F1 | localisation |",
            "|---|---|---|---|",
            row.format(
                "held-out session (seed 900)",
                held["accuracy"],
                held["macro_f1"],
                held["localisation_accuracy"],
            ),
            row.format(
                "high-payload probe (seed 901, 2.2x)",
                probe["accuracy"],
                probe["macro_f1"],
                probe["localisation_accuracy"],
            ),
            "",
            "Simulated data: on a real arm expect lower figures until the model is commissioned "
            "on that arm (below); studies/real_arms/README.md measures what a real UR10e does.",
            "",
            "## Operating point",
            "The monitor's defaults (`conf/monitor.yaml`): an alarm after 10 ticks in a row voting "
            "for one fault with class probability >= 0.9, cleared after 10 healthy ticks; ticks at "
            "20 Hz, windows of 1.6 s.",
            "",
            "## Use it",
            "```",
            USE[name],
            "```",
            "",
            "## Commission it on your arm",
            "A model reads an arm's channels relative to the healthy behaviour it was trained on; "
            "ten minutes of your arm's healthy running move that baseline to your arm. "
            "Commissioning refits from the checkpoint and the training data, which the wheel does "
            "not carry: re-make them with `bash studies/ready_models/run.sh` (a clone, about 40 "
            "minutes on 2 cores), then",
            "```",
            f"python -m robohealth_mj.commission model=outputs/ready/{name}/best.ckpt "
            "healthy=YOUR_HEALTHY_LOG.csv",
            "```",
            "and monitor with the `model.onnx` it writes (docs/deployment.md).",
            "",
            "## Made by",
            "`bash studies/ready_models/run.sh` (the recipe: corpus, training, export, this card). "
            f"Model id `{meta['model_id']}`.",
            "",
        ]
    )


def _sample(corpus: Path) -> str:
    """A minute of the held-out session from 20 s before a fault's onset, as a UR RTDE log; the
    faults it holds, as the recording's labels give them (the log itself carries none)."""
    rec = load_recordings([corpus / "heldout_seed900" / "graphs.jsonl"])
    first = np.flatnonzero(rec.run == 0)
    friction = rec.active[first] & (rec.fault_class[first] == FAULT_CLASSES.index("friction"))
    start = max(int(np.flatnonzero(friction)[0]) - int(20.0 / TICK_S), 0)
    picked = first[start : start + int(SAMPLE_S / TICK_S)]
    t = TICK_S * (rec.sample_index[picked] - rec.sample_index[picked[0]])
    write_rtde_csv(rec.x[picked], t, READY / SAMPLE_FILE)
    episodes, k = [], 0
    while k < len(picked):
        if not rec.active[picked[k]]:
            k += 1
            continue
        end = k
        while end + 1 < len(picked) and rec.active[picked[end + 1]]:
            end += 1
        i = picked[k]
        episodes.append(f"{FAULT_CLASSES[rec.fault_class[i]]} at the "
                        f"{JOINT_NAMES[rec.fault_joint[i]]} (severity {rec.severity[i]:.2f}) "
                        f"{t[k]:.0f}-{t[end] + TICK_S:.0f} s")  # fmt: skip
        k = end + 1
    return (f"- `{SAMPLE_FILE}`: {SAMPLE_S:g} s of the held-out session (seed 900) of the "
            f"nominal UR5e as a UR RTDE log, healthy but for: {'; '.join(episodes)}. "
            "`file=sample` names it.")  # fmt: skip


def main(runs: Path, corpus: Path) -> None:
    lines = ["# Ready models", "",
             "Exported models the wheel ships, addressed by name (`model=stock`). Each card "
             "gives its data, figures, operating point and how to commission it on your arm.",
             ""]  # fmt: skip
    for name in PROFILES:
        onnx = READY / f"{name}.onnx"
        shutil.copyfile(runs / name / "model.onnx", onnx)
        meta = read_metadata(onnx)
        atomic_write_text(READY / f"{name}.md", _card(name, runs / name, meta))
        lines.append(f"- [`{name}`]({name}.md): {PROFILES[name][0]}.")
    lines.append(_sample(corpus))
    atomic_write_text(READY / "README.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
