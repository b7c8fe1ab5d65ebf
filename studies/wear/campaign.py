"""Wear over weeks (issue 39): a window model trained on lives, a health index per joint and
session, and the RUL and wear warnings it gives on held-out lives.

    python -m robohealth_mj.corpus corpus=lives            # outputs/corpus/lives
    python studies/wear/campaign.py [--variant gbdt] [--seed 42] [--labels last]
        [--estimators trend,progpy] [--lead-days 10] [--floor 0.15]

Steps (each skipped when done): train ``--variant`` on every day of the training lives
(``outputs/lives/<run>/model``); score every day of every life (``health_raw.json``: the raw
index per joint with its bootstrap band); fit the index's calibration on the days the model's
validation split holds (never on a held-out life); tune the warning's lead time and floor on the
validation lives (lives the model never trained on); then per held-out life the index against the
truth, each estimator's RUL day by day on the wearing joint (prognostic horizon, alpha-lambda,
relative accuracy at half-life) and the first warning; warnings on healthy arm-days.
``lives.json`` holds every number; ``studies/wear/summarise.py`` writes the tables.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import torch

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.steps import run_step
from robohealth_mj.learn.evaluation import score_checkpoint
from robohealth_mj.learn.trainer import CHECKPOINT
from robohealth_mj.prognostics import metrics
from robohealth_mj.prognostics.health import Calibration, session_health, window_attribution
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.schema import JOINT_NAMES

CORPUS = Path("outputs/corpus/lives")
OUT = Path("outputs/lives")
HELD_OUT, TRAIN, HEALTHY = "heldout_lives", "train_lives", "healthy_lives"
VAL = "val_lives"  # never trained on: the warning's lead time and floor are tuned here


def train(
    variant: str,
    seed: int,
    labels: str,
    run_dir: Path,
    epochs: int,
    extra: list[str],
    overrides: list[str],
) -> Path:
    ckpt = run_dir / "model" / CHECKPOINT
    if ckpt.is_file():
        return ckpt
    run_step(
        "robohealth_mj.train",
        f"variant={variant}",
        f"seed={seed}",
        "window=32",
        f"labels={labels}",
        f"data.train=[{','.join(extra)}]",
        "data.evaluate=null",
        f"out_dir={run_dir / 'model'}",
        "trainer.progress=false",
        f"trainer.epochs={epochs}",
        *overrides,
    )
    return ckpt


def _manifest_run_id(session: Path) -> str:
    return json.loads((session / "manifest.json").read_text())["recording_run_id"]


def score_lives(ckpt: Path, index: dict, run_dir: Path) -> dict:
    """Per life: each day's raw index, band and truth per joint (cached; a life the cache lacks,
    such as a role added to the corpus later, is scored and added)."""
    cache = run_dir / "health_raw.json"
    out = json.loads(cache.read_text()) if cache.is_file() else {}
    todo = [(role, entry) for role in (TRAIN, VAL, HELD_OUT, HEALTHY)
            for entry in index["roles"].get(role, []) if entry["dir"] not in out]  # fmt: skip
    if not todo:
        return out
    for role, entry in todo:
        life = json.loads((CORPUS / entry["life"]).read_text())
        sessions = [CORPUS / entry["dir"] / d["dir"] for d in life["days"]]
        scored = score_checkpoint(ckpt, [str(s) for s in sessions], device="cpu")
        p = scored.predictions
        attribution = window_attribution(p.class_logits, p.joint_logits, p.severity)
        run_of = np.asarray(scored.rec.run_ids)[scored.rec.run[scored.windows.end]]
        days = []
        for d, session in zip(life["days"], sessions, strict=True):
            rid = _manifest_run_id(session)
            h = session_health(attribution[run_of == rid], seed=d["day"])
            days.append(
                {
                    "day": d["day"],
                    "run_id": rid,
                    "truth": [d["severity"][j] for j in JOINT_NAMES],
                    "raw": h.raw.tolist(),
                    "low": h.low.tolist(),
                    "high": h.high.tolist(),
                }
            )
        out[entry["dir"]] = {
            "role": role,
            "mode": entry["mode"],
            "joint": entry["joint"],
            "path": entry["path"],
            "failure_day": life["failure_day"],
            "days": days,
        }
        print(f"scored {entry['dir']}: {len(days)} days", flush=True)
    atomic_write_json(cache, out)
    return out


def calibrate(ckpt: Path, scores: dict) -> tuple[Calibration, int]:
    """Isotonic map raw -> severity on the training lives' days in the model's validation split."""
    val = set(torch.load(ckpt, map_location="cpu", weights_only=False)["split_runs"]["val"])
    raw, truth = [], []
    for life in scores.values():
        if life["role"] != TRAIN:
            continue
        for d in life["days"]:
            if d["run_id"] in val:
                raw += d["raw"]
                truth += d["truth"]
    return Calibration.fit(np.array(raw), np.array(truth)), len(raw) // len(JOINT_NAMES)


def health_table(scores: dict, cal: Calibration, role: str) -> dict:
    err, err_wear, inside, n = [], [], [], 0
    for life in scores.values():
        if life["role"] != role:
            continue
        for d in life["days"]:
            hi, lo, up = cal(np.array(d["raw"])), cal(np.array(d["low"])), cal(np.array(d["high"]))
            t = np.array(d["truth"])
            err.append(np.abs(hi - t))
            inside.append((lo - 0.02 <= t) & (t <= up + 0.02))
            if life["joint"]:
                j = JOINT_NAMES.index(life["joint"])
                err_wear.append(abs(hi[j] - t[j]))
            n += 1
    return {
        "sessions": n,
        "index_mae_all_joints": float(np.mean(err)) if err else math.nan,
        "index_mae_wearing_joint": float(np.mean(err_wear)) if err_wear else math.nan,
        "band_coverage_0.02": float(np.mean(inside)) if inside else math.nan,
    }


def life_curves(life: dict, cal: Calibration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    days = np.array([d["day"] for d in life["days"]], float)
    index = cal(np.array([d["raw"] for d in life["days"]]))  # [S, J]
    truth = np.array([d["truth"] for d in life["days"]])
    return days, index, truth


def rul_rows(scores: dict, cal: Calibration, estimators: dict, lead: float, floor: float) -> list:
    """Per held-out life and estimator: RUL day by day on the wearing joint, the metrics, the
    first warning (any joint) and whether it named the wearing joint."""
    rows = []
    for name, life in scores.items():
        if life["role"] != HELD_OUT or life["failure_day"] is None:
            continue
        days, index, truth = life_curves(life, cal)
        j = JOINT_NAMES.index(life["joint"])
        low = cal(np.array([d["low"][j] for d in life["days"]]))
        high = cal(np.array([d["high"][j] for d in life["days"]]))
        eol = float(life["failure_day"])
        onset = float(days[np.argmax(truth[:, j] > 0)])
        for est_name, est in estimators.items():
            started = time.perf_counter()
            estimates = [est.estimate(days[: k + 1], index[: k + 1, j]) for k in range(len(days))]
            wall = time.perf_counter() - started
            predicted = np.array([e.rul for e in estimates])
            warn_day = next(
                (days[k] for k, e in enumerate(estimates) if e.warns(lead, floor)), None
            )
            rows.append(
                {
                    "life": name,
                    "mode": life["mode"],
                    "path": life["path"],
                    "joint": life["joint"],
                    "estimator": est_name,
                    "failure_day": eol,
                    "onset_day": onset,
                    "days": days.tolist(),
                    "truth": truth[:, j].tolist(),
                    "index": index[:, j].tolist(),
                    "index_low": low.tolist(),
                    "index_high": high.tolist(),
                    "rul": [None if not math.isfinite(v) else v for v in predicted.tolist()],
                    "rul_low": [e.low if math.isfinite(e.low) else None for e in estimates],
                    "rul_high": [e.high if math.isfinite(e.high) else None for e in estimates],
                    "prognostic_horizon": metrics.prognostic_horizon(
                        days, predicted, eol, onset, 0.2
                    ),
                    "alpha_lambda_0.5": metrics.alpha_lambda(days, predicted, eol, onset, 0.2, 0.5),
                    "relative_accuracy_0.5": metrics.relative_accuracy(days, predicted, eol, onset),
                    "first_warning_day": warn_day,
                    "warning_lead_days": None if warn_day is None else eol - warn_day,
                    "wall_s": wall,
                }
            )
    return rows


def healthy_warnings(scores: dict, cal: Calibration, est: TrendRul, lead: float, floor: float):
    """Warnings raised on healthy arm-days: every day of the healthy lives and every day of a
    wearing life on which no joint had worn yet; a warning on a wearing life's other joints is
    counted apart (wrong joint)."""
    healthy_days = warned_days = wrong_joint = 0
    for life in scores.values():
        if life["role"] not in (HELD_OUT, HEALTHY):
            continue
        days, index, truth = life_curves(life, cal)
        for k in range(len(days)):
            warns = [
                est.estimate(days[: k + 1], index[: k + 1, j]).warns(lead, floor)
                for j in range(len(JOINT_NAMES))
            ]
            if not truth[k].any():
                healthy_days += 1
                warned_days += any(warns)
            elif life["joint"]:
                wear = JOINT_NAMES.index(life["joint"])
                wrong_joint += any(w for j, w in enumerate(warns) if j != wear)
    return {
        "healthy_arm_days": healthy_days,
        "warned_healthy_days": warned_days,
        "warnings_per_100_healthy_days": 100 * warned_days / max(healthy_days, 1),
        "wrong_joint_warning_days": wrong_joint,
    }


def warned_share(rows: list[dict], days: float = 5.0) -> float:
    """The share of :func:`rul_rows`' lives first warned at least ``days`` before failure."""
    return float(np.mean([(r["warning_lead_days"] or -1) >= days for r in rows]))


def tuning_role(scores: dict) -> str:
    """Where the warning is tuned: the validation lives where the corpus has them (the model
    never trained on them), else the training lives (in-sample, so every setting tends to warn
    every life in time)."""
    return VAL if any(v["role"] == VAL for v in scores.values()) else TRAIN


def as_held_out(scores: dict, role: str) -> dict:
    """``scores`` with ``role``'s lives in the held-out role and every other life left out, so
    that :func:`rul_rows` and :func:`healthy_warnings` read them."""
    return {k: {**v, "role": HELD_OUT if v["role"] == role else "skip"} for k, v in scores.items()}


def tune_warning(scores: dict, cal: Calibration, est: TrendRul) -> dict:
    """Lead time and floor chosen on the validation lives (:func:`tuning_role`; never the
    held-out ones): the most lives warned >= 5 days ahead, then the fewest warned > 20 days
    ahead, then the shorter lead."""
    role = tuning_role(scores)
    tuning = as_held_out(scores, role)
    best = None
    for lead in (6.0, 8.0, 10.0, 12.0, 15.0, 20.0, 25.0):
        for floor in (0.05, 0.1, 0.15, 0.2, 0.3):
            rows = rul_rows(tuning, cal, {"trend": est}, lead, floor)
            ok = warned_share(rows)
            early = np.mean([(r["warning_lead_days"] or 0) > 20 for r in rows])
            key = (round(float(ok), 3), -round(float(early), 3), -lead)
            if best is None or key > best[0]:
                best = (key, lead, floor)
    return {"lead_days": best[1], "floor": best[2], "tuned_on": role, "warned_5_days": best[0][0]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--variant", default="gbdt")
    ap.add_argument("--seed", type=int, default=42)
    ap.add_argument("--labels", default="last")
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument(
        "--train-also",
        default="",
        help="more training data beside the training lives, e.g. 'outputs/corpus/standard/train_*'",
    )
    ap.add_argument("--name", default=None, help="run name (default: variant_labels_sSEED)")
    ap.add_argument("--estimators", default="trend,progpy")
    ap.add_argument(
        "--lead-days", type=float, default=None, help="default: tuned on the validation lives"
    )
    ap.add_argument("--floor", type=float, default=None)
    ap.add_argument(
        "--override",
        action="append",
        default=[],
        help="a training config override, repeatable (e.g. model.severity_objective=regression)",
    )
    args = ap.parse_args()
    index = json.loads((CORPUS / "corpus.json").read_text())
    threshold = float(index["config"]["threshold"])
    run_dir = OUT / (args.name or f"{args.variant}_{args.labels}_s{args.seed}")
    data = [f"{CORPUS}/{TRAIN}_*/day_*", *filter(None, args.train_also.split(","))]
    ckpt = train(args.variant, args.seed, args.labels, run_dir, args.epochs, data, args.override)
    train_s = json.loads((ckpt.parent / "train_summary.json").read_text()).get("wall_seconds")
    scores = score_lives(ckpt, index, run_dir)
    cal, n_cal = calibrate(ckpt, scores)
    trend = TrendRul(threshold=threshold)
    estimators = {"trend": trend}
    if "progpy" in args.estimators.split(","):
        from robohealth_mj.prognostics.progpy_rul import ProgpyRul

        estimators["progpy"] = ProgpyRul(threshold=threshold)
    tuned = tune_warning(scores, cal, trend)
    lead = args.lead_days if args.lead_days is not None else tuned["lead_days"]
    floor = args.floor if args.floor is not None else tuned["floor"]
    result = {
        "variant": args.variant,
        "seed": args.seed,
        "labels": args.labels,
        "train_data": data,
        "run": run_dir.name,
        "train_s": train_s,
        "calibration": vars(cal),
        "calibration_sessions": n_cal,
        "warning_tuning": tuned,
        "lead_days": lead,
        "floor": floor,
        "health": {
            role: health_table(scores, cal, role) for role in (TRAIN, VAL, HELD_OUT, HEALTHY)
        },
        "rul": rul_rows(scores, cal, estimators, lead, floor),
        "healthy": healthy_warnings(scores, cal, trend, lead, floor),
    }
    atomic_write_json(run_dir / "lives.json", result)
    atomic_write_json(run_dir / "calibration.json", vars(cal))  # monitor health.calibration=
    print(json.dumps({k: result[k] for k in ("health", "healthy", "lead_days", "floor")}, indent=1))
    print(f"-> {run_dir / 'lives.json'}")


if __name__ == "__main__":
    main()
