"""``python -m robohealth_mj.train``: train one variant, then evaluate it on the held-out sets.

    python -m robohealth_mj.train variant=anomaly_residual seed=42 window=32
    python -m robohealth_mj.train variant=anomaly_residual graph=harness
    python -m robohealth_mj.train -m variant=mlp,stgnn_fixed seed=42,43,44    # a sweep
    python -m robohealth_mj.train -m +experiment=thesis_matrix                # the campaign

A run whose held-out evaluation already exists, made on the data the config names now, is
skipped, so a killed sweep can be relaunched (a re-recorded corpus trains again).
"""

from __future__ import annotations

from pathlib import Path

from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from robohealth_mj.common.config import register_resolvers, run_tool
from robohealth_mj.common.errors import one_line_errors

with one_line_errors("train"):  # a missing extra is one line, not a traceback
    from robohealth_mj.learn.run import train_and_evaluate

register_resolvers()


def main(argv: list[str] | None = None) -> None:
    run_tool("train", run, argv)


def run(cfg: DictConfig) -> None:
    with one_line_errors("train"):
        train_and_evaluate(cfg, Path(cfg.out_dir or HydraConfig.get().runtime.output_dir))


if __name__ == "__main__":
    main()
