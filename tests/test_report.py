"""The campaign report: mean ± std over seeds per (graph, variant, window)."""

from __future__ import annotations

import json
from pathlib import Path

from robohealth_mj.report import build_report
from robohealth_mj.schema import FAULT_CLASSES


def _run(
    root: Path,
    graph: str,
    variant: str,
    seed: int,
    acc: float,
    loc: float,
    corr: float | None = None,
) -> None:
    d = root / graph / variant / "w16" / f"seed{seed}"
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
    assert "| stgnn_fixed | 16 | 3 | 0.900 ± 0.082 |" in text
    assert "| mlp | 16 | 1 |" in text and "gat" not in text
    assert text.index("| mlp |") < text.index("| stgnn_fixed |")  # thesis order
    assert "0.900 ± 0.000" in text  # the harness run's C-C0 correlation
    # what each fault shows: recall per class, severity 0.3 and moving/still faulted windows
    visibility = text[text.index("### Held-out recall per class") :]
    row = next(line for line in visibility.splitlines() if "| stgnn_fixed |" in line)
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[3:9] == ["0.500 ± 0.000"] * 6  # the six fault classes' recall
    assert cells[9] == "0.700 ± 0.082" and cells[11] == "—"  # sev. 0.3; no 0.9 stratum
    assert cells[12:] == ["0.900 ± 0.082", "0.600 ± 0.082"]  # moving, still
    assert (tmp_path / "report" / "results.md").is_file()
    assert (tmp_path / "report" / "results.csv").read_text().startswith("graph,variant,window")
    assert {p.name for p in figures} >= {
        "localisation_by_variant.png",
        "payload_shift.png",
        "confusion_and_f1.png",
        "coupling_vs_c0.png",
    }
