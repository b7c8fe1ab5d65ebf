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
    from robohealth_mj.deploy.commission import SETTLED, commission


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
                            contact_margin=cfg.get("contact_margin"))  # fmt: skip
        atomic_write_json(out / "commissioning.json", record)
    print(f"{record['healthy_minutes']:g} healthy minutes -> {record['checkpoint']}")
    for row in record["settling"]:
        print(f"  after {row['minutes']:>4g} min: {row['relative_error']:.3f} of the final shift")
    settled = record["settled_minutes"]
    if "settling_skipped" in record:
        print(f"residual baseline not used: {record['settling_skipped']}")
    elif settled is not None:
        print(f"baseline settled (within {SETTLED:.0%}) after {settled:g} min")
    else:
        print(f"baseline not settled within {SETTLED:.0%}: record more healthy running")
    if "placement" in record:
        p = record["placement"]
        parts = [f"placement self-calibration ({p['fit']}): C refitted"]
        if "reconstruction_before" in p:
            before, after = p["reconstruction_before"], p["reconstruction_after"]
            parts.append(f"reconstruction {before:.3f} -> {after:.3f}")
        if "coupling_correlation" in p:
            parts.append(f"corr. with the arm's placement {p['coupling_correlation']:.2f}")
        print(", ".join(parts))
        train = f"python -m robohealth_mj.train graph=harness graph.coupling_file={p['file']}"
        print(f"placement found -> {p['file']} (a model trained on it: {train} ...)")
    point = record.get("operating_point", {})
    if "class_offset" in point:
        print(
            f"healthy operating point ({point['recipe']}): this arm's healthy windows called "
            f"healthy {point['arm_healthy_rate_before']:.3f} -> "
            f"{point['arm_healthy_rate_after']:.3f} (validation: "
            f"{point['validation_healthy_rate']:.3f})"
        )
    if "healthy_rate_asked" in point:
        print(
            f"asked for {point['healthy_rate_asked']:g} healthy: validation's faulted windows "
            f"called a fault {point['validation_fault_recall_before']:.3f} -> "
            f"{point['validation_fault_recall_after']:.3f}"
        )
    contact = record.get("contact", {})
    if "threshold_nm" in contact:
        values = " / ".join(f"{v:.2f}" for v in contact["threshold_nm"])
        print(f"contact watch: thresholds {values} N·m ({contact['rule']})")
    elif contact:
        print(f"contact watch off: {contact['skipped']}")
    if "onnx" in record:
        print(f"exported -> {record['onnx']}")


if __name__ == "__main__":
    main()
