"""``python -m robohealth_mj.evaluate ckpt=… data=…``: score a checkpoint on whole recordings.

``data`` is a file, a session directory or a glob (quote it); ``out`` is the output prefix
(default: ``eval_<data name>`` next to the checkpoint); ``labels`` how a window is labelled
(``last``, ``majority``, ``time_weighted``, ``visible``; default: as the model was trained);
``observability`` which calls the model may make (``all``; ``motion``: friction and backlash only
on a joint that moved in the window, :mod:`robohealth_mj.data.observability`); ``threads``
the CPU threads of torch (``auto``: the cores free at the start).
Writes JSON and CSV atomically.
"""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import one_line_errors
from robohealth_mj.common.threads import resolve_threads, use_torch_threads

with one_line_errors("evaluate"):  # a missing extra is one line, not a traceback
    from robohealth_mj.learn.evaluation import evaluate_checkpoint, write_evaluation


def main(argv: list[str] | None = None) -> None:
    run_tool("evaluate", run, argv)


def run(cfg: DictConfig) -> None:
    if not cfg.ckpt or not cfg.data:
        raise SystemExit("usage: python -m robohealth_mj.evaluate ckpt=PATH data=PATH [out=PREFIX]")
    with one_line_errors("evaluate"):
        use_torch_threads(resolve_threads(cfg.threads, "threads"))
        result = evaluate_checkpoint(cfg.ckpt, cfg.data, cfg.device, cfg.labels, cfg.observability)
    prefix = cfg.out or Path(cfg.ckpt).parent / f"eval_{Path(str(cfg.data)).stem}"
    json_path, _ = write_evaluation(result, prefix)
    m = result["metrics"]
    print(
        f"{result['variant']} on {len(result['data'])} file(s): accuracy {m['accuracy']:.3f}  "
        f"fault-present {m['fault_present_accuracy']:.3f}  macro-F1 {m['macro_f1']:.3f}  "
        f"localisation {m['localisation_accuracy']:.3f} -> {json_path}"
    )


if __name__ == "__main__":
    main()
