"""The thesis's Figure 7: the affected sensor's traces for each fault class against healthy."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robohealth_mj.data.read import read_samples
from robohealth_mj.schema import FAULT_CLASSES, feature_index

_VIB_ACC = [feature_index(name) for name in ("vib", "acc_x", "acc_y", "acc_z")]


def _episodes(path: Path) -> dict[str, tuple[str, np.ndarray, np.ndarray]]:
    """Per fault class, the highest-severity episode: (joint, faulted traces, healthy traces).

    Traces are ``[T, 4]`` (vib, acc x/y/z) of the target sensor; the healthy reference is the
    same sensor over the healthy interval that follows the episode.
    """
    samples = list(read_samples(path))
    labels = [(s.fault.fault_class, s.fault.joint, s.fault.severity) for s in samples]
    best: dict[str, tuple[float, int, int]] = {}
    start = 0
    for k in range(1, len(samples) + 1):
        if k == len(samples) or labels[k] != labels[start]:
            cls, _, sev = labels[start]
            if cls != "none" and sev > best.get(cls, (-1.0, 0, 0))[0]:
                best[cls] = (sev, start, k)
            start = k
    out = {}
    for cls, (_, a, b) in best.items():
        graph = samples[a].graph
        node = graph.n_joints + graph.joints.index(labels[a][1])
        faulted = np.array([samples[i].x[node, _VIB_ACC] for i in range(a, b)])
        after = range(b, min(len(samples), b + (b - a)))
        healthy = np.array(
            [samples[i].x[node, _VIB_ACC] for i in after if not samples[i].fault.active]
        )
        out[cls] = (labels[a][1], faulted, healthy)
    return out


def plot_signatures(path: Path | str, out: Path | str) -> Path:
    """Write a PNG: one row per fault class, vibration and acceleration, faulted vs healthy."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    episodes = _episodes(Path(path))
    classes = [c for c in FAULT_CLASSES[1:] if c in episodes]
    if not classes:
        raise ValueError(f"{path}: no faulted episode to plot")
    fig, axes = plt.subplots(
        len(classes), 2, figsize=(11, 2.0 * len(classes)), squeeze=False, sharex=True
    )
    for row, cls in enumerate(classes):
        joint, faulted, healthy = episodes[cls]
        t_f = np.arange(len(faulted)) * 0.05
        t_h = np.arange(len(healthy)) * 0.05
        ax_v, ax_a = axes[row]
        ax_v.plot(t_h, healthy[:, 0], color="0.6", lw=1, label="healthy")
        ax_v.plot(t_f, faulted[:, 0], color="C3", lw=1, label=cls)
        ax_v.set_ylabel(f"{cls}\n@{joint}", fontsize=8)
        for axis, colour in zip(range(3), ("C0", "C1", "C2"), strict=True):
            mean_h = healthy[:, 1 + axis].mean() if len(healthy) else 0.0
            ax_a.plot(t_h, healthy[:, 1 + axis] - mean_h, color="0.6", lw=0.8)
            ax_a.plot(
                t_f,
                faulted[:, 1 + axis] - faulted[:, 1 + axis].mean(),
                color=colour,
                lw=0.8,
                label="xyz"[axis],
            )
        if row == 0:
            ax_v.set_title("piezo vibration (m/s² RMS)")
            ax_a.set_title("acceleration minus its mean (m/s²)")
            ax_v.legend(fontsize=7, loc="upper right")
            ax_a.legend(fontsize=7, loc="upper right", ncol=3)
    for ax in axes[-1]:
        ax.set_xlabel("time in episode (s)")
    fig.suptitle(f"Fault signatures at the affected sensor: {Path(path).name}", fontsize=10)
    fig.tight_layout()
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
