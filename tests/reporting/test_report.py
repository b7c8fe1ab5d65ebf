"""The campaign report: mean ± std over seeds per (setting, model, window), in the thesis's
layout (Tables 6, 7, 8), from hand-made run files and from a tiny real campaign."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from robohealth_mj.reporting.build import build_report
from robohealth_mj.schema import FAULT_CLASSES


def _run(
    root: Path,
    graph: str,
    variant: str,
    seed: int,
    acc: float,
    loc: float,
    corr: float | None = None,
    anomaly_scores: str | None = None,
) -> None:
    d = root / graph / "full" / "C0" / f"{variant}{anomaly_scores or ''}" / "w16" / f"seed{seed}"
    d.mkdir(parents=True)
    (d / "train_summary.json").write_text(
        json.dumps(
            {
                "variant": variant,
                "window": 16,
                "seed": seed,
                "graph": graph,
                "gamma": None,
                "best_epoch": 3,
                "anomaly_scores": anomaly_scores,
            }
        )
    )
    per_class = {
        c: {"precision": 0.5, "recall": 0.5, "f1": 0.5, "support": 1} for c in FAULT_CLASSES
    }
    metrics = {
        "accuracy": acc,
        "fault_present_accuracy": acc,
        "macro_f1": acc,
        "localisation_accuracy": loc,
        "per_class": per_class,
        "confusion_matrix": [[1] * 7 for _ in range(7)],
        "by_severity": {"0.3": {"accuracy": acc - 0.2}},
        "by_motion": {"moving": {"accuracy": acc}, "still": {"accuracy": acc - 0.3}},
    }
    heldout = {"metrics": metrics}
    if corr is not None:
        heldout |= {"coupling_correlation": corr, "coupling": [[1.0] * 4] * 6}
    (d / "eval_heldout.json").write_text(json.dumps(heldout))
    (d / "eval_probe.json").write_text(json.dumps({"metrics": metrics}))


def test_report_aggregates_seeds_and_writes_tables_and_figures(tmp_path):
    for seed, acc in ((42, 0.8), (43, 0.9), (44, 1.0)):
        _run(tmp_path, "structural", "stgnn_fixed", seed, acc, acc - 0.1)
    _run(tmp_path, "structural", "mlp", 42, 0.7, 0.2)
    _run(tmp_path, "harness", "anomaly_residual", 42, 0.6, 0.5, corr=0.9)
    (tmp_path / "structural" / "gat" / "w16" / "seed42").mkdir(parents=True)  # unfinished run
    text, figures = build_report(tmp_path)
    assert "### Table 6: every model at W = 16" in text and "### Table 8" in text
    assert "| stgnn_fixed | 16 | 3 | 0.900 ± 0.082 |" in text
    assert "| mlp | 16 | 1 |" in text and "gat" not in text
    assert text.index("| mlp |") < text.index("| stgnn_fixed |")  # thesis order
    assert "0.900 ± 0.000" in text  # the harness run's C-C0 correlation
    # what each fault shows: recall per class, severity 0.3 and moving/still faulted windows
    visibility = text[text.index("### Held-out recall per class") :]
    row = next(line for line in visibility.splitlines() if "| stgnn_fixed |" in line)
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[0] == "structural/full/C0"
    assert cells[3:9] == ["0.500 ± 0.000"] * 6  # the six fault classes' recall
    assert cells[9] == "0.700 ± 0.082" and cells[11] == "—"  # sev. 0.3; no 0.9 stratum
    assert cells[12:] == ["0.900 ± 0.082", "0.600 ± 0.082"]  # moving, still
    assert (tmp_path / "report" / "results.md").is_file()
    assert (
        (tmp_path / "report" / "results.csv")
        .read_text()
        .startswith("graph,sensing,placement,variant,window")
    )
    assert {p.name for p in figures} >= {
        "localisation_by_variant.png",
        "payload_shift.png",
        "confusion_best_worst_headline.png",
        "harness_localisation.png",
        "coupling_vs_c0.png",
    }


def _cells(text: str, heading: str, first: str) -> list[str]:
    """The cells of the row starting with ``first`` in the table under ``heading``."""
    section = text[text.index(heading) :]
    row = next(line for line in section.splitlines() if line.startswith(f"| {first} |"))
    return [c.strip() for c in row.strip("|").split("|")]


@pytest.mark.slow
def test_a_tiny_campaign_goes_through_the_report_into_every_table(tiny_corpus, tmp_path):
    """Two variants x two seeds (Table 6), a second window (Table 7), the harness with the
    retrofit profile and sign-pinned scores (Table 8), the severity head, and the cost: real
    training runs in the campaign's directory layout, and the tables hold their numbers."""
    from robohealth_mj.common.config import compose_config, placement_name
    from robohealth_mj.learn.run import train_and_evaluate as run

    def train(*overrides: str) -> dict:
        cfg = compose_config(
            "train",
            [
                f"data.train=[{tiny_corpus}/train_*]",
                f"data.evaluate.heldout={tiny_corpus}/heldout",
                "data.evaluate.probe=null",
                "trainer.epochs=1",
                "trainer.progress=false",
                "model.hidden=8",
                "window=8",
                *overrides,
            ],
        )
        label = cfg.variant + ("+severity" if cfg.model.get("severity_head") else "")
        out = tmp_path / cfg.graph._target_.rsplit(".", 1)[1].removesuffix("_graph")
        out = out / cfg.sensing.name / placement_name(cfg.graph) / label
        return run(cfg, out / f"w{cfg.window}" / f"seed{cfg.seed}")

    accuracy = {}
    for variant in ("mlp", "anomaly_residual"):
        for seed in (1, 2):
            result = train(f"variant={variant}", f"seed={seed}")
            accuracy[variant, seed] = result["heldout"]["metrics"]["accuracy"]
    train("variant=mlp", "seed=1", "window=16")
    harness = train(
        "variant=anomaly_residual",
        "graph=harness",
        "sensing=retrofit",
        "model.anomaly_scores=energy",
        "seed=1",
    )
    train("variant=anomaly_residual", "model.severity_head=true", "seed=1")

    text, figures = build_report(tmp_path)
    table6 = "### Table 6: every model at W = 8"
    mean = np.mean([accuracy["mlp", 1], accuracy["mlp", 2]])
    std = np.std([accuracy["mlp", 1], accuracy["mlp", 2]])
    cells = _cells(text, table6, "mlp")
    assert cells[1:4] == ["8", "2", f"{mean:.3f} ± {std:.3f}"]
    assert _cells(text, table6, "anomaly_residual")[2] == "2"
    assert _cells(text, "### Table 7", "mlp")[1:3] != ["—", "—"]  # W = 8 and W = 16
    row8 = _cells(text, "### Table 8", "retrofit")
    assert row8[:3] == ["retrofit", "C0", "anomaly_residual+energy"]
    corr = harness["heldout"]["coupling_correlation"]
    assert row8[8] == f"{corr:.3f} ± 0.000"
    severity = _cells(text, "### Severity head", "structural/full/C0")
    assert severity[1] == "anomaly_residual+severity" and severity[4] != "—"
    assert "### Cost: wall time per run" in text and "7 runs" in text
    assert {p.name for p in figures} >= {
        "localisation_by_variant.png",
        "window_ablation.png",
        "harness_localisation.png",
        "coupling_vs_c0.png",
        "confusion_best_worst_headline.png",
    }


def test_the_archive_keeps_a_campaign_that_outlives_its_machine(tmp_path):
    """``report ROOT --archive A``: the finished runs' records (not their checkpoints) are copied
    into A, a later campaign's runs join them, a rerun replaces its record, the block times are
    kept once, and the report is built from everything archived."""
    from robohealth_mj.report import main

    first, second, archive = tmp_path / "first", tmp_path / "second", tmp_path / "archive"
    for seed, acc in ((42, 0.8), (43, 0.9)):
        _run(first, "structural", "stgnn_fixed", seed, acc, acc - 0.1)
    _run(first, "structural", "mlp", 42, 0.7, 0.2)
    run_dir = first / "structural" / "full" / "C0"
    (run_dir / "stgnn_fixed" / "w16" / "seed42" / "model.pt").write_bytes(b"checkpoint")
    (run_dir / "gat" / "w16" / "seed42").mkdir(parents=True)  # unfinished
    (first / "blocks.tsv").write_text("matrix\t100\t2\thost\n")
    main([str(first), "--archive", str(archive), "--out", str(tmp_path / "report")])
    run42 = archive / "structural" / "full" / "C0" / "stgnn_fixed" / "w16" / "seed42"
    assert sorted(p.name for p in run42.iterdir()) == [
        "eval_heldout.json",
        "eval_probe.json",
        "train_summary.json",
    ]
    assert not (archive / "structural" / "full" / "C0" / "gat").exists()

    # the first machine is gone; a second one reruns seed 43 and adds seed 44
    import shutil

    shutil.rmtree(first)
    _run(second, "structural", "stgnn_fixed", 43, 1.0, 0.9)
    _run(second, "structural", "stgnn_fixed", 44, 1.0, 0.9)
    (second / "blocks.tsv").write_text("matrix\t100\t2\thost\nmatrix\t50\t2\thost\n")
    main([str(second), "--archive", str(archive), "--out", str(tmp_path / "report")])
    text = (tmp_path / "report" / "results.md").read_text()
    assert "| stgnn_fixed | 16 | 3 | 0.933 ± 0.094 |" in text  # 0.8 kept, 0.9 replaced by 1.0
    assert "| mlp | 16 | 1 | 0.700 ± 0.000 |" in text
    assert (archive / "blocks.tsv").read_text() == "matrix\t100\t2\thost\nmatrix\t50\t2\thost\n"


def test_report_on_a_missing_directory_is_one_line(tmp_path, capsys):
    import pytest

    from robohealth_mj.report import main

    with pytest.raises(SystemExit) as exit_info:
        main([str(tmp_path / "nowhere"), "--archive", str(tmp_path / "a")])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nowhere" in err


def test_q1_effects_are_paired_over_the_seeds_every_cell_has(tmp_path):
    """The pose kernel's and the learned residual's effects, per seed, then mean ± std: seed 43
    lifts every variant by 0.05, which a paired effect ignores; seed 44 lacks three cells."""
    cells = {  # variant: accuracy at seed 42, seed 43
        "stgnn_fixed": (0.80, 0.85),
        "stgnn_fixed_pose": (0.82, 0.89),
        "stgnn_learnable": (0.78, 0.83),
        "stgnn_pose_cond": (0.80, 0.87),
    }
    for variant, accs in cells.items():
        for seed, acc in zip((42, 43), accs, strict=True):
            _run(tmp_path, "structural", variant, seed, acc, acc - 0.1)
    _run(tmp_path, "structural", "stgnn_fixed", 44, 0.99, 0.99)
    text, _ = build_report(tmp_path)
    section = "### Q1: the pose kernel and the learned residual"
    assert _cells(text, section, "16")[:4] == ["16", "2", "pose kernel", "+0.030 ± 0.010"]
    residual = next(
        line for line in text[text.index(section) :].splitlines() if "| learned residual |" in line
    )
    assert "| -0.020 ± 0.000 | -0.020 ± 0.000 |" in residual  # accuracy, localisation


def test_q2_differences_are_paired_per_seed_and_per_harness_setting(tmp_path):
    """The coupling head minus each model under the harness, per seed: seed 44 lifts `gbdt`
    alone (no head run to pair it with), so a difference of means would hide the head's lead."""
    for seed, loc in ((42, 0.80), (43, 0.90)):
        _run(tmp_path, "harness", "anomaly_residual", seed, 0.8, loc, 0.9, anomaly_scores="energy")
    for seed, loc in ((42, 0.75), (43, 0.80), (44, 0.99)):
        _run(tmp_path, "harness", "gbdt", seed, 0.7, loc)
    _run(tmp_path, "harness", "stgnn_fixed", 42, 0.8, 0.70)
    _run(tmp_path, "structural", "gbdt", 42, 0.8, 0.10)  # not a harness run: not compared
    text, _ = build_report(tmp_path)
    section = "### Q2: the coupling head"
    rows = [
        line.split(" | ") for line in text[text.index(section) :].split("\n\n")[1].splitlines()[2:]
    ]
    assert [r[:5] for r in rows] == [
        ["| harness/full/C0", "16", "2", "gbdt", "+0.075 ± 0.025"],
        ["| harness/full/C0", "16", "1", "stgnn_fixed", "+0.100 ± 0.000"],
    ]
    assert rows[0][5] == "+0.100 ± 0.000"  # accuracy 0.8 - 0.7 on both seeds


def test_mean_pm_std_is_the_tables_cell_over_the_finite_values():
    """The one ``mean ± std`` every results table and research script prints."""
    from robohealth_mj.reporting.statistics import mean_pm_std

    assert mean_pm_std([0.8312, 0.8401, 0.8233]) == "0.832 ± 0.007"
    assert mean_pm_std([0.5, None, float("nan"), 0.7], digits=2) == "0.60 ± 0.10"
    assert mean_pm_std([]) == "—"


def _life_row(name: str, estimator: str, warn: float | None) -> dict:
    days = list(range(10))
    return {
        "life": name, "mode": "friction", "path": "linear", "joint": "elbow",
        "estimator": estimator, "failure_day": 10.0, "onset_day": 1.0, "days": days,
        "truth": [0.08 * d for d in days], "index": [0.08 * d + 0.01 for d in days],
        "index_low": [0.08 * d for d in days], "index_high": [0.08 * d + 0.02 for d in days],
        "rul": [None, None, *[10.0 - d for d in days[2:]]], "first_warning_day": warn,
    }  # fmt: skip


def test_report_draws_each_held_out_life_and_refuses_a_file_that_is_none(tmp_path, capsys):
    from robohealth_mj.report import main

    lives = {"lead_days": 5.0, "rul": [_life_row("a", "trend", 5.0), _life_row("a", "progpy", None),
                                       _life_row("b", "trend", None)]}  # fmt: skip
    path = tmp_path / "lives.json"
    path.write_text(json.dumps(lives))
    main(["--lives", str(path), "--out", str(tmp_path / "figs")])
    drawn = sorted(p.name for p in (tmp_path / "figs").glob("*.png"))
    assert drawn == ["heldout_lives.png", "life_a.png", "life_b.png"]
    assert all(p.stat().st_size > 10_000 for p in (tmp_path / "figs").glob("*.png"))
    (tmp_path / "other.json").write_text(json.dumps({"runs": []}))
    with pytest.raises(SystemExit) as exc:
        main(["--lives", str(tmp_path / "other.json")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "other.json" in err[0] and "not a lives result" in err[0]
