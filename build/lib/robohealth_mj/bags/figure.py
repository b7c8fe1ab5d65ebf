"""Truth and diagnosis on one timeline, drawn from a bag's own topics (what the Foxglove layout in
``docs/foxglove_layout.json`` shows, for where no browser is at hand)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robohealth_mj.bags.messages import typestore
from robohealth_mj.bags.topics import BagTopics
from robohealth_mj.schema import FAULT_CLASSES


def _statuses(path: Path, topic: str) -> list[tuple[float, int, dict[str, str]]]:
    from rosbags.rosbag2 import Reader

    store = typestore()
    with Reader(path) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            raise FileNotFoundError(f"{path}: no topic '{topic}' to plot")
        out = []
        for _, stamp, raw in reader.messages(connections=conns):
            status = store.deserialize_cdr(raw, conns[0].msgtype).status[0]
            out.append((stamp / 1e9, int(status.level), {kv.key: kv.value for kv in status.values}))
    return out


def plot_timeline(bag: Path | str, out: Path | str) -> Path:
    """Three rows over time: the true fault (class, joint), the alarm (class, joint) and the
    per-tick fault probability; from ``/fault_state`` and ``/health_diagnosis``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    topics = BagTopics.load()
    bag, out = Path(bag), Path(out)
    truth = _statuses(bag, topics.fault_state)
    diag = _statuses(bag, topics.health_diagnosis)
    colours = dict(zip(FAULT_CLASSES, plt.get_cmap("tab10").colors, strict=False))
    fig, axes = plt.subplots(3, 1, figsize=(11, 5.2), sharex=True, height_ratios=[1, 1, 1.3])

    def bands(ax, rows, cls_key, joint_key, title):
        t = np.array([r[0] for r in rows])
        labels = [(r[2].get(cls_key) or "none", r[2].get(joint_key) or "") for r in rows]
        start = 0
        for k in range(1, len(rows) + 1):
            if k == len(rows) or labels[k] != labels[start]:
                cls, joint = labels[start]
                if cls not in ("", "none"):
                    end = t[k - 1] + 0.05
                    ax.axvspan(t[start], end, color=colours.get(cls, "grey"), alpha=0.8)
                    if end - t[start] > 4:
                        ax.text((t[start] + end) / 2, 0.5, f"{cls}\n{joint}", ha="center",
                                va="center", fontsize=7)  # fmt: skip
                start = k
        ax.set_yticks([])
        ax.set_ylabel(title, rotation=0, ha="right", va="center")

    truth_rows = [(t, lvl, {**v, "class": v["class"] if v["active"] == "true" else "none"})
                  for t, lvl, v in truth]  # fmt: skip
    bands(axes[0], truth_rows, "class", "joint", "/fault_state\n(truth)")
    bands(axes[1], diag, "alarm_class", "alarm_joint", "/health_diagnosis\n(alarm)")
    t = np.array([r[0] for r in diag])
    p_fault = np.array([1.0 - float(r[2].get("p.none") or 1.0) for r in diag])
    axes[2].plot(t, p_fault, lw=0.7, color="black")
    axes[2].set_ylim(0, 1.02)
    axes[2].set_ylabel("P(fault)\nper tick", rotation=0, ha="right", va="center")
    axes[2].set_xlabel("simulation time (s)")
    handles = [plt.Rectangle((0, 0), 1, 1, color=colours[c]) for c in FAULT_CLASSES[1:]]
    fig.legend(handles, FAULT_CLASSES[1:], loc="upper center", ncol=6, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
