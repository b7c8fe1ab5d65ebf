"""``python -m robohealth_mj.commission model=CKPT healthy=LOG_OR_DIR [out=DIR]``.

Commissions a trained model on a new arm from minutes of its healthy running (no labels): the
healthy baseline of the residual channels is refitted (:mod:`robohealth_mj.deploy.commission`),
a new checkpoint and ONNX are written whose metadata records the commissioning data's
fingerprint, and the table says after how many healthy minutes the baseline settled.
"""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from robohealth_mj.common.atomic import atomic_write_json
from robohealth_mj.common.config import arm_choice, run_tool
from robohealth_mj.common.errors import InputError, one_line_errors

with one_line_errors("commission"):  # a missing extra is one line, not a traceback
    from robohealth_mj.deploy.commission import commission
    from robohealth_mj.deploy.commission_summary import commission_summary


def main(argv: list[str] | None = None) -> None:
    run_tool("commission", run, argv)


def run(cfg: DictConfig) -> None:
    with one_line_errors("commission"):
        if not cfg.model or not cfg.healthy:
            raise InputError("usage: python -m robohealth_mj.commission model=CKPT healthy=DATA")
        healthy = (
            OmegaConf.to_container(cfg.healthy) if OmegaConf.is_list(cfg.healthy) else cfg.healthy
        )
        out = Path(cfg.out or Path(cfg.model).parent / "commissioned")
        given = OmegaConf.to_container(cfg.placement) if cfg.get("placement") else {}
        placement = {k: v for k, v in given.items() if v is not None} or None
        record = commission(cfg.model, healthy, out, cfg.reference, cfg.export, placement=placement,
                            placement_fit=cfg.placement_fit,
                            placement_prune=cfg.get("placement_prune"),
                            operating_point=cfg.operating_point,
                            arm=arm_choice(cfg),
                            healthy_rate=cfg.get("healthy_rate"),
                            contact_margin=cfg.get("contact_margin"),
                            normalisation=cfg.get("normalisation", "none"))  # fmt: skip
        atomic_write_json(out / "commissioning.json", record)
    print(commission_summary(record))


if __name__ == "__main__":
    main()
