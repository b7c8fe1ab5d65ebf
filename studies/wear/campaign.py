"""Wear over weeks (issues 39 and 68): a window model trained on lives, a health index per joint
and day, and the warnings a maintenance planner is given on lives it never saw.

    python -m robohealth_mj.corpus corpus=lives            # outputs/corpus/lives
    python studies/wear/campaign.py [--variant gbdt] [--seed 42] [--labels last]
        [--train-also 'outputs/corpus/standard/train_*'] [--estimators trend,progpy]

Steps (each skipped when done): train ``--variant`` on every day of the training lives
(``outputs/lives/<run>/model``); score every day of every life (``health_raw.json``: per joint the
raw index, its bootstrap band, the index split by mechanical mode and over only the windows in
which the joint turned); fit the channels' scales and the four modes' signatures on the standard
corpus and the training lives (``channel_scales.json``, ``signatures.json``). Then for each way of
reading the index (``robohealth_mj/prognostics/index_model.py``): fit its calibration on the
training lives' days in the model's validation split and the validation lives (each validation
life read through the maps fitted without it), tune the warning's lead time, floor and trend
(through the last sessions or since the index reached the floor; through at least 3 or 5
sessions) on the validation lives, and replay every life day by day as the monitor runs it, on
every joint: the index against the truth (on the wearing joint, and how high the others read),
each wearing life's first warning on any joint judged against the 5-20 day band (``in_band``,
``early``, ``late``, ``wrong_joint``, ``missed``), and warnings per 100 healthy arm-days. The index
model is chosen on the validation lives; the held-out lives (the corpus's) and the fresh lives
(seeds no choice ever saw) are reported. ``lives.json`` holds every number;
``studies/wear/summarise.py`` writes the tables.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.steps import run_step
from robohealth_mj.data.arrays import CACHE_SUFFIX
from robohealth_mj.data.windows import joints_moved
from robohealth_mj.learn.evaluation import score_checkpoint
from robohealth_mj.learn.trainer import CHECKPOINT
from robohealth_mj.prognostics import metrics
from robohealth_mj.prognostics.channels import CHANNELS, channel_readings, fit_scales
from robohealth_mj.prognostics.health import (
    MECHANICAL_CLASSES,
    mode_attribution,
    session_health,
    window_attribution,
)
from robohealth_mj.prognostics.index_model import (
    NO_CHANNELS,
    VARIANTS,
    ChannelFits,
    FittedIndex,
    IndexModel,
    fit_index,
    session_reading,
)
from robohealth_mj.prognostics.planner import (
    DEFAULT_BAND,
    Replay,
    first_warning,
    outcome_shares,
    replay_many,
)
from robohealth_mj.prognostics.rul import TrendRul
from robohealth_mj.prognostics.signature import LOAD_DAYS, Signatures, adapt, fit_signatures
from robohealth_mj.schema import JOINT_NAMES

CORPUS = Path("outputs/corpus/lives")
OUT = Path("outputs/lives")
HELD_OUT, TRAIN, HEALTHY = "heldout_lives", "train_lives", "healthy_lives"
CACHE = "graphs.jsonl" + CACHE_SUFFIX  # a recording's binary cache
VAL, VAL_WIDE = "val_lives", "val_wide_lives"  # never trained on: where the index is calibrated
# and the index model and the warning chosen (val_wide_lives drawn as the held-out lives are)
VAL_HEALTHY = "val_healthy_lives"  # and where those choices see healthy-day warnings
FRESH, FRESH_HEALTHY = "fresh_lives", "fresh_healthy_lives"  # seeds no choice ever saw
ROLES = (TRAIN, VAL, VAL_WIDE, VAL_HEALTHY, HELD_OUT, HEALTHY, FRESH, FRESH_HEALTHY)
GROUPS = {
    "validation": (VAL, VAL_WIDE, VAL_HEALTHY),
    "held_out": (HELD_OUT, HEALTHY),
    "fresh": (FRESH, FRESH_HEALTHY),
}


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
    """Per life, in name order: each day's raw index, band and truth per joint (cached; a life
    the cache lacks, such as a role added to the corpus later, is scored and added)."""
    cache = run_dir / "health_raw.json"
    out = json.loads(cache.read_text()) if cache.is_file() else {}
    todo = [(role, entry) for role in ROLES for entry in index["roles"].get(role, [])
            if "raw_moving" not in out.get(entry["dir"], {}).get("days", [{}])[0]]  # fmt: skip
    if not todo:
        return out
    for role, entry in tqdm(todo, desc="scoring lives", unit="life", disable=None):
        life = json.loads((CORPUS / entry["life"]).read_text())
        sessions = [CORPUS / entry["dir"] / d["dir"] for d in life["days"]]
        scored = score_checkpoint(ckpt, [str(s) for s in sessions], device="cpu")
        p = scored.predictions
        attribution = window_attribution(p.class_logits, p.joint_logits, p.severity)
        by_mode = mode_attribution(p.class_logits, p.joint_logits, p.severity)  # [K, M, J]
        moved = joints_moved(scored.rec, scored.windows)  # [K, J]
        run_of = np.asarray(scored.rec.run_ids)[scored.rec.run[scored.windows.end]]
        days = []
        for d, session in zip(life["days"], sessions, strict=True):
            rid = _manifest_run_id(session)
            mine = run_of == rid
            h = session_health(attribution[mine], seed=d["day"])
            days.append(
                {
                    "day": d["day"],
                    "run_id": rid,
                    "truth": [d["severity"][j] for j in JOINT_NAMES],
                    "raw": h.raw.tolist(),
                    "low": h.low.tolist(),
                    "high": h.high.tolist(),
                    **session_reading(by_mode[mine], moved[mine]),
                    "moving_share": moved[mine].mean(axis=0).round(4).tolist(),
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
    return dict(sorted(out.items()))  # as the cache reads back: a rerun meets the lives in order


def add_channels(scores: dict) -> None:
    """Each day's channel readings per joint (the recording alone, no model:
    :mod:`robohealth_mj.prognostics.channels`), added where the cache lacks them, and the last
    :data:`LOAD_DAYS` days' as the monitor keeps them (``recent_channel``, this day last)."""
    for name, life in scores.items():
        if not all(len(d.get("channel", [])) == len(CHANNELS) for d in life["days"]):
            for d in life["days"]:
                x = np.load(CORPUS / name / f"day_{int(d['day']):03d}" / CACHE)["x"]
                d["channel"] = np.round(channel_readings(x, len(JOINT_NAMES)), 8).tolist()
        days = sorted(life["days"], key=lambda d: d["day"])
        for k, d in enumerate(days):
            d["recent_channel"] = [e["channel"] for e in days[max(0, k + 1 - LOAD_DAYS) : k + 1]]


def channel_fits(run_dir: Path, extra: list[str], scores: dict) -> ChannelFits:
    """What the channel index models read through, fitted on the training data beside the lives
    (``--train-also``; none without it): friction's and backlash's scales and the four modes'
    signatures, these brought to whole days on the training lives (the channels, not the window
    model: no validation or held-out life is seen). Written to the run; a rerun reads them."""
    scales_path, signatures_path = run_dir / "channel_scales.json", run_dir / "signatures.json"
    if scales_path.is_file() and signatures_path.is_file():
        signatures = json.loads(signatures_path.read_text())
        return ChannelFits(np.array(json.loads(scales_path.read_text())),
                           Signatures.from_json(signatures, str(signatures_path)))  # fmt: skip
    caches = [c for pattern in extra for p in sorted(Path().glob(pattern))
              if (c := p / CACHE).is_file()]  # fmt: skip
    if not caches:
        return ChannelFits()
    scales = np.round(fit_scales(caches, len(JOINT_NAMES)), 8)
    signatures = adapt(fit_signatures(caches, len(JOINT_NAMES)), training_days(scores)).to_json()
    atomic_write_json(scales_path, scales.tolist())
    atomic_write_json(signatures_path, signatures)
    # as written, so that a rerun reading the files reads the same numbers
    return ChannelFits(scales, Signatures.from_json(signatures, str(signatures_path)))


def training_days(scores: dict) -> list[tuple[np.ndarray, np.ndarray, int]]:
    """The training lives' days as :func:`adapt` brings the signatures to whole days:
    ``(readings [C, J], truth [J], the life's mode index or -1 for a healthy life)``."""
    return [(np.asarray(d["channel"], float), np.asarray(d["truth"], float),
             MECHANICAL_CLASSES.index(life["mode"]) if life["mode"] else -1)
            for life in lives_of(scores, (TRAIN,)) for d in life["days"]]  # fmt: skip


def calibration_days(ckpt: Path, scores: dict) -> list[dict]:
    """The training lives' days in the model's validation split: with the validation lives
    (:func:`fitted_indexes`), what the index is calibrated on; never a held-out or fresh life."""
    val = set(torch.load(ckpt, map_location="cpu", weights_only=False)["split_runs"]["val"])
    return [d for life in scores.values() if life["role"] == TRAIN
            for d in life["days"] if d["run_id"] in val]  # fmt: skip


def lives_of(scores: dict, roles: tuple[str, ...]) -> list[dict]:
    return [life for life in scores.values() if life["role"] in roles]


@dataclass
class LifeView:
    """A life as one fitted index reads it: the daily index a monitor reports ``[S, J]`` and
    every joint's trend estimate replayed day by day."""

    life: dict
    days: np.ndarray
    truth: np.ndarray
    seen: np.ndarray
    replays: dict[tuple, Replay]  # per trend setting (:func:`trend_settings`)


LEADS = (4.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0, 25.0, 30.0)
FLOORS = (0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5)
FITS = ("window", "since")  # the trend's sessions: the last ones, or those since detection
MIN_SESSIONS = (3, 5)  # the fewest sessions a trend is drawn through: the estimator's least, a week


def trend_settings() -> list[tuple[str, int, float | None]]:
    """Every trend a warning can read: (fit, fewest sessions, the since level or None)."""
    floors = [f for f in FLOORS if f > 0]  # since 0 is every session: the window's fit
    return [("window", m, None) for m in MIN_SESSIONS] + [
        ("since", m, f) for m in MIN_SESSIONS for f in floors
    ]


def trend_of(est: TrendRul, fit: str, min_sessions: int, floor: float) -> TrendRul:
    """The estimator a warning setting reads (the since level is the warning's floor)."""
    return replace(est, min_sessions=min_sessions, since=floor if fit == "since" else None)


def view(life: dict, index: FittedIndex, est: TrendRul) -> LifeView:
    days = np.array([d["day"] for d in life["days"]], float)
    daily = np.stack([index.calibrate(d) for d in life["days"]])
    settings = trend_settings()
    trends = [trend_of(est, fit, m, level or 0.0) for fit, m, level in settings]
    return LifeView(
        life,
        days,
        np.array([d["truth"] for d in life["days"]]),
        index.life(life["days"]),
        dict(zip(settings, replay_many(days, daily, trends, index.online), strict=True)),
    )


def index_figures(views: list[LifeView]) -> dict:
    """The index a monitor reads each day against the truth: on the wearing joint, on the other
    joints of wearing lives, and on healthy lives."""
    wear, others, healthy, per_life = [], [], [], []
    for v in views:
        life, err = v.life, np.abs(v.seen - v.truth)
        if not life["joint"]:
            healthy += v.seen.ravel().tolist()
            continue
        j = JOINT_NAMES.index(life["joint"])
        wear += err[:, j].tolist()
        others += np.delete(v.seen, j, axis=1).ravel().tolist()
        per_life.append(
            {
                "life": life["name"],
                "mode": life["mode"],
                "joint": life["joint"],
                "path": life["path"],
                "mae": float(err[:, j].mean()),
                "final_truth": float(v.truth[-1, j]),
                "final_index": float(v.seen[-1, j]),
            }
        )
    mean = lambda v: float(np.mean(v)) if v else math.nan  # noqa: E731
    return {
        "wearing_joint_mae": mean(wear),
        "other_joints_mean_reading": mean(others),
        "other_joints_p95_reading": float(np.quantile(others, 0.95)) if others else math.nan,
        "healthy_lives_mean_reading": mean(healthy),
        "days_on_wearing_joint": len(wear),
        "per_life": per_life,
    }


def warning_figures(
    views: list[LifeView],
    lead: float,
    floor: float,
    fit: str = "window",
    min_sessions: int = MIN_SESSIONS[0],
    band=DEFAULT_BAND,
) -> dict:
    """Each wearing life's first warning on any joint, classified (:mod:`planner`), and the
    warnings on healthy arm-days (healthy lives, and wearing lives' days before onset)."""
    firsts, per_life, healthy_days, warned_days = [], [], 0, 0
    setting = (fit, min_sessions, floor if fit == "since" else None)
    for v in views:
        life = v.life
        warned = v.replays[setting].warned(lead, floor)
        before_onset = ~v.truth.any(axis=1)
        healthy_days += int(before_onset.sum())
        warned_days += int((warned.any(axis=1) & before_onset).sum())
        if life["joint"] and life["failure_day"] is not None:
            wearing = JOINT_NAMES.index(life["joint"])
            first = first_warning(v.days, warned, wearing, life["failure_day"], band)
            firsts.append(first)
            per_life.append({"life": life["name"], "mode": life["mode"], "joint": life["joint"],
                             "path": life["path"], "failure_day": life["failure_day"],
                             **vars(first)})  # fmt: skip
    centre = sum(band) / 2
    off = [abs(w.lead_days - centre) if w.outcome != "wrong_joint" and w.lead_days is not None
           else centre for w in firsts]  # fmt: skip
    return {
        "lives": len(firsts),
        **outcome_shares(firsts),
        "off_centre_days": float(np.mean(off)) if off else 0.0,
        "healthy_arm_days": healthy_days,
        "warned_healthy_days": warned_days,
        "warnings_per_100_healthy_days": 100 * warned_days / max(healthy_days, 1),
        "per_life": per_life,
    }


def tune_warning(
    views: list[LifeView],
    fits: tuple[str, ...] = FITS,
    min_sessions: tuple[int, ...] = MIN_SESSIONS,
    band=DEFAULT_BAND,
) -> dict:
    """Lead time, floor and the trend (its fit and fewest sessions) chosen on the validation
    lives: the most lives first warned inside the band on the right joint, then the fewest
    healthy-day warnings, then the first warnings nearest the band's centre on average (a
    missed or wrong-joint life counts as far as the centre is from failure): of settings equal
    on the count, the one with the most room either side. Among settings tied on all three, the
    last sessions' fit over the fit since detection and the fewer sessions (the simpler rule),
    then the middle lead time, then the middle floor (so that a tie does not put the pick at a
    grid's edge). ``at_edge`` says if the pick is there."""
    scored = []
    for fit, m, level in trend_settings():
        if fit not in fits or m not in min_sessions:
            continue
        for lead in LEADS:
            for floor in FLOORS if level is None else [level]:
                f = warning_figures(views, lead, floor, fit, m, band)
                key = (round(f["in_band"], 6), -round(f["warnings_per_100_healthy_days"], 6),
                       -round(f["off_centre_days"], 6))  # fmt: skip
                scored.append((key, fit, m, lead, floor))
    best = max(k for k, *_ in scored)
    tied = [setting for k, *setting in scored if k == best]
    fit = next(f for f in fits if any(t[0] == f for t in tied))
    m = next(m for m in min_sessions if any(t[:2] == [fit, m] for t in tied))
    tied = [t for t in tied if t[:2] == [fit, m]]
    leads = sorted({t[2] for t in tied})
    lead = leads[len(leads) // 2]
    floors = sorted(t[3] for t in tied if t[2] == lead)
    floor = floors[len(floors) // 2]
    edge_floors = (FLOORS[0] if fit == "window" else FLOORS[1], FLOORS[-1])
    return {
        "fit": fit,
        "min_sessions": m,
        "lead_days": lead,
        "floor": floor,
        "in_band": best[0],
        "tied_settings": len(tied),
        "at_edge": lead in (LEADS[0], LEADS[-1]) or floor in edge_floors,
    }


def fitted_indexes(
    model: IndexModel, scores: dict, cal_days: list[dict], channels: ChannelFits
) -> dict[str, FittedIndex]:
    """The index each life is read through. Maps are fitted on the training lives' validation
    days and the validation lives; a validation life is read through the maps fitted without it
    (leave one life out), so that the choices made on the validation lives see out-of-sample
    readings; every other life through the maps fitted on all of them."""
    val = lives_of(scores, GROUPS["validation"])
    full = fit_index(model, cal_days + [d for life in val for d in life["days"]], channels)
    out = {name: full for name in scores}
    for life in val:
        others = [d for other in val if other is not life for d in other["days"]]
        out[life["name"]] = fit_index(model, cal_days + others, channels)
    out["_all"] = full
    return out


def evaluate_variant(
    model: IndexModel,
    scores: dict,
    cal_days: list[dict],
    est: TrendRul,
    channels: ChannelFits = NO_CHANNELS,
) -> dict:
    """Fit, tune on the validation lives, report on every group of lives; ``ablation``: the
    warnings tuned on the last sessions' trend alone, then with the fit since detection, then
    with either fewest sessions too (what the tuning reads today)."""
    indexes = fitted_indexes(model, scores, cal_days, channels)
    views = {name: [view(life, indexes[life["name"]], est) for life in lives_of(scores, roles)]
             for name, roles in GROUPS.items()}  # fmt: skip

    def tuned_warnings(fits: tuple[str, ...], mins: tuple[int, ...]) -> dict:
        tuned = tune_warning(views["validation"], fits, mins)
        setting = (tuned["lead_days"], tuned["floor"], tuned["fit"], tuned["min_sessions"])
        figures = {name: warning_figures(v, *setting) for name, v in views.items()}
        return {"warning": tuned, "warnings": figures}

    ablation = {
        "last sessions": tuned_warnings(("window",), MIN_SESSIONS[:1]),
        "+ since the floor": tuned_warnings(FITS, MIN_SESSIONS[:1]),
        f"+ fewest sessions {' or '.join(map(str, MIN_SESSIONS))}": tuned_warnings(
            FITS, MIN_SESSIONS
        ),
    }
    chosen = list(ablation.values())[-1]
    return {
        "index_model": model.name,
        "warning": chosen["warning"],
        "groups": {
            name: {"index": index_figures(v), "warnings": chosen["warnings"][name]}
            for name, v in views.items()
        },
        "ablation": ablation,
        "_index": indexes["_all"],
    }


def choose(rows: list[dict]) -> dict:
    """The index model chosen on the validation lives: of those first warning, in band, as many
    lives as the best to within one life, the fewest healthy warnings, then the lowest
    wearing-joint MAE. One life is a step of 6 points among 16, inside the share's own noise (a
    binomial standard error of 9 points at 0.85), while the MAE over 390 joint-days separates
    index models far more finely: ranked on the share first, a one-life lead chose an index 0.04
    worse on the MAE (the issue-68 third pass, studies/wear/README.md)."""
    valid = [r["groups"]["validation"] for r in rows]
    step = 1.0 / max(valid[0]["warnings"]["lives"], 1)
    best = max(v["warnings"]["in_band"] for v in valid)
    near = [
        r
        for r, v in zip(rows, valid, strict=True)
        if v["warnings"]["in_band"] >= best - step - 1e-9
    ]
    return min(near, key=lambda r: (
        round(r["groups"]["validation"]["warnings"]["warnings_per_100_healthy_days"], 6),
        r["groups"]["validation"]["index"]["wearing_joint_mae"]))  # fmt: skip


def rul_rows(
    lives: list[dict], index: FittedIndex, estimators: dict, group: str, first: dict
) -> list:
    """Per wearing life and estimator: the RUL day by day on the wearing joint, the Saxena
    metrics (prognostic horizon, alpha-lambda, relative accuracy at half-life), the index with
    its band and the day of the life's first warning (``first``: per life, from
    :func:`warning_figures`), as ``python -m robohealth_mj.report --lives`` draws them."""
    rows = []
    for life in lives:
        if not life["joint"] or life["failure_day"] is None:
            continue
        days = np.array([d["day"] for d in life["days"]], float)
        j = JOINT_NAMES.index(life["joint"])
        daily = np.stack([index.calibrate(d) for d in life["days"]])[:, j]
        seen = index.life(life["days"])[:, j]
        low, high = index.band(np.array([d["low"][j] for d in life["days"]]),
                               np.array([d["high"][j] for d in life["days"]]), seen)  # fmt: skip
        truth = np.array([d["truth"][j] for d in life["days"]])
        eol, onset = float(life["failure_day"]), float(days[np.argmax(truth > 0)])
        for est_name, est in estimators.items():
            started = time.perf_counter()
            predicted = np.array(
                [
                    est.estimate(days[: k + 1], index.online(daily[: k + 1])).rul
                    for k in range(len(days))
                ]
            )
            rows.append(
                {
                    "group": group,
                    "life": life["name"],
                    "mode": life["mode"],
                    "joint": life["joint"],
                    "path": life["path"],
                    "estimator": est_name,
                    "failure_day": eol,
                    "onset_day": onset,
                    "days": days.tolist(),
                    "truth": truth.tolist(),
                    "index": seen.tolist(),
                    "index_low": low.tolist(),
                    "index_high": high.tolist(),
                    "first_warning_day": first[life["name"]]["day"],
                    "first_warning_outcome": first[life["name"]]["outcome"],
                    "rul": [None if not math.isfinite(v) else v for v in predicted.tolist()],
                    "prognostic_horizon": metrics.prognostic_horizon(
                        days, predicted, eol, onset, 0.2
                    ),
                    "alpha_lambda_0.5": metrics.alpha_lambda(days, predicted, eol, onset, 0.2, 0.5),
                    "relative_accuracy_0.5": metrics.relative_accuracy(days, predicted, eol, onset),
                    "wall_s": time.perf_counter() - started,
                }
            )
    return rows


def first_by_life(group: dict) -> dict[str, dict]:
    return {life["life"]: life for life in group["warnings"]["per_life"]}


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
    ap.add_argument("--estimators", default="trend", help="trend[,progpy] for the RUL metrics")
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
    for name, life in scores.items():
        life["name"] = name
    add_channels(scores)
    channels = channel_fits(run_dir, data[1:], scores)
    cal_days = calibration_days(ckpt, scores)
    trend = TrendRul(threshold=threshold)
    variants = [m for m in VARIANTS if channels.serve(m.raw)]
    rows = [evaluate_variant(m, scores, cal_days, trend, channels)
            for m in tqdm(variants, desc="index models", disable=None)]  # fmt: skip
    chosen = choose(rows)
    warning = chosen["warning"]
    estimators = {  # as the chosen warning reads the trend
        "trend": trend_of(trend, warning["fit"], warning["min_sessions"], warning["floor"])
    }
    if "progpy" in args.estimators.split(","):
        from robohealth_mj.prognostics.progpy_rul import ProgpyRul

        estimators["progpy"] = ProgpyRul(threshold=threshold)
    fitted: FittedIndex = chosen["_index"]
    result = {
        "variant": args.variant,
        "seed": args.seed,
        "labels": args.labels,
        "train_data": data,
        "run": run_dir.name,
        "train_s": train_s,
        "calibration_sessions": len(cal_days),
        "band_days": list(DEFAULT_BAND),
        "chosen": chosen["index_model"],
        "index_models": [{k: v for k, v in r.items() if k != "_index"} for r in rows],
        "calibration": fitted.to_json(),
        "lead_days": chosen["warning"]["lead_days"],
        "floor": chosen["warning"]["floor"],
        "fit": chosen["warning"]["fit"],  # monitor health.fit_since_floor=true when "since"
        "min_sessions": chosen["warning"]["min_sessions"],  # monitor health.min_sessions
        "rul": [row for name, roles in GROUPS.items() if name != "validation"
                for row in rul_rows(lives_of(scores, roles), fitted, estimators, name,
                                    first_by_life(chosen["groups"][name]))],
    }  # fmt: skip
    atomic_write_json(run_dir / "lives.json", result)
    atomic_write_json(run_dir / "calibration.json", fitted.to_json())  # monitor health.calibration=
    for r in rows:
        g = r["groups"]
        print(
            f"{r['index_model']:28s} {r['warning']['fit']:6s} min "
            f"{r['warning']['min_sessions']} lead {r['warning']['lead_days']:4.0f} floor "
            f"{r['warning']['floor']:.2f} | "
            + " | ".join(
                f"{n}: mae {g[n]['index']['wearing_joint_mae']:.3f} in-band "
                f"{g[n]['warnings']['in_band']:.2f} early {g[n]['warnings']['early']:.2f} "
                f"wrong {g[n]['warnings']['wrong_joint']:.2f} "
                f"h/100d {g[n]['warnings']['warnings_per_100_healthy_days']:.2f}"
                for n in GROUPS
            )
        )
    print(f"chosen on the validation lives: {chosen['index_model']} -> {run_dir / 'lives.json'}")


if __name__ == "__main__":
    main()
