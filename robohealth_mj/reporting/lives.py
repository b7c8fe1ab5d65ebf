"""Held-out lives drawn: the wearing joint's true severity, the health index with its band, and
the RUL estimates against the true RUL (``python -m robohealth_mj.report --lives FILE``)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from robohealth_mj.common.errors import InputError


def read_lives(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a lives result ({exc})") from None
    if not isinstance(data, dict) or not isinstance(data.get("rul"), list):
        raise InputError(f"{path}: not a lives result (no 'rul' rows; studies/wear)")
    return data


def plot_lives(result: dict[str, Any], out: Path) -> list[Path]:
    """One figure per held-out life (index above, RUL below) and one page of all of them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    by_life: dict[str, list[dict]] = {}
    for row in result["rul"]:
        by_life.setdefault(row["life"], []).append(row)
    names = sorted(by_life)
    cols = 4
    rows = int(np.ceil(len(names) / cols))
    page, axes = plt.subplots(2 * rows, cols, figsize=(4 * cols, 5 * rows), squeeze=False)
    written = []
    for k, name in enumerate(names):
        single, (a1, a2) = plt.subplots(2, 1, figsize=(6, 6), sharex=True)
        for ax_i, ax_r in ((a1, a2), (axes[2 * (k // cols), k % cols],
                                       axes[2 * (k // cols) + 1, k % cols])):  # fmt: skip
            _draw(ax_i, ax_r, by_life[name], result.get("lead_days"))
        single.tight_layout()
        path = out / f"life_{name}.png"
        single.savefig(path, dpi=100)
        plt.close(single)
        written.append(path)
    for k in range(len(names), rows * cols):
        axes[2 * (k // cols), k % cols].axis("off")
        axes[2 * (k // cols) + 1, k % cols].axis("off")
    page.tight_layout()
    path = out / "heldout_lives.png"
    page.savefig(path, dpi=80)
    plt.close(page)
    return [path, *written]


def _draw(ax_index, ax_rul, rows: list[dict], lead_days: float | None) -> None:
    first = rows[0]
    days = np.array(first["days"])
    eol = first["failure_day"]
    ax_index.plot(days, first["truth"], "k-", lw=2, label="true severity")
    ax_index.plot(days, first["index"], "C0.-", label="health index")
    ax_index.fill_between(days, first["index_low"], first["index_high"], color="C0", alpha=0.25)
    ax_index.axhline(0.8, color="r", ls=":", lw=1)
    ax_index.set_title(f"{first['mode']} @ {first['joint']} ({first['path']})", fontsize=9)
    ax_index.set_ylim(-0.02, 1.0)
    ax_index.legend(fontsize=7, loc="upper left")
    ax_rul.plot(days, eol - days, "k-", lw=2, label="true RUL")
    ax_rul.fill_between(days, 0.8 * (eol - days), 1.2 * (eol - days), color="k", alpha=0.1,
                        label="alpha = 0.2")  # fmt: skip
    for c, row in enumerate(rows):
        rul = np.array([np.nan if v is None else v for v in row["rul"]], float)
        ax_rul.plot(days, rul, f"C{c + 1}.-", label=row["estimator"])
        if row.get("first_warning_day") is not None:
            ax_rul.axvline(row["first_warning_day"], color=f"C{c + 1}", ls="--", lw=1)
    if lead_days:
        ax_rul.axhline(lead_days, color="grey", ls=":", lw=1)
    ax_rul.set_ylim(0, 1.3 * max(eol, 1))
    ax_rul.set_xlabel("operating day")
    ax_rul.set_ylabel("RUL, days")
    ax_rul.legend(fontsize=7, loc="upper right")
