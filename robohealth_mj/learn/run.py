"""One run of a campaign: train, then evaluate on every held-out set the config names."""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig

from robohealth_mj.learn.evaluation import evaluate_checkpoint, write_evaluation
from robohealth_mj.learn.trainer import CHECKPOINT, finished_on_current_data, train_run


def train_and_evaluate(cfg: DictConfig, out_dir: Path) -> dict:
    """Train one run (or skip it when its evaluation on the current data exists), then evaluate
    the best checkpoint on each of ``cfg.data.evaluate``; prints the one-line result."""
    if cfg.skip_done and finished_on_current_data(cfg, out_dir):
        print(f"skip {out_dir}: evaluation on the current data exists")
        return {"skipped": True}
    summary = train_run(cfg, out_dir)
    results = {"train": summary}
    for name, data in (cfg.data.evaluate or {}).items():
        if data:
            result = evaluate_checkpoint(out_dir / CHECKPOINT, data, cfg.trainer.device)
            write_evaluation(result, out_dir / f"eval_{name}")
            results[name] = result
    m = results.get("heldout", {}).get("metrics", summary["test"])
    print(
        f"{cfg.variant} W={cfg.window} seed={cfg.seed} [{summary['graph']}]: "
        f"accuracy {m.get('accuracy', float('nan')):.3f}  "
        f"localisation {m.get('localisation_accuracy', float('nan')):.3f}  "
        f"macro-F1 {m.get('macro_f1', float('nan')):.3f}  -> {out_dir}",
        flush=True,
    )
    return results
