"""``python -m robohealth_mj.identify arm=ur10e fit=[LOG,...] validate=[LOG,...] out=DIR``.

Identifies a twin of a real arm from its healthy controller logs (:mod:`robohealth_mj.twin`):
per joint the rotor inertia, viscous and Coulomb friction and torque constant of our drive model,
written to ``DIR/twin.yaml``, which ``record arm=<arm> sim.twin=DIR/twin.yaml`` simulates. The
fidelity table (``DIR/fidelity.md``, ``.json``) gives, per joint and validation log, the NRMSE
of the simulated torque against the controller's target moment and against the measured current
x torque constant, before and after identification, beside the floor: the controller's own
model (target moment and fitted friction) as a predictor of the current.
"""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig

from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.common.config import arm_choice, as_paths, run_tool
from robohealth_mj.common.errors import InputError, one_line_errors


def main(argv: list[str] | None = None) -> None:
    run_tool("identify", run, argv)


def run(cfg: DictConfig) -> None:
    with one_line_errors("identify"):
        from robohealth_mj.twin.report import (
            cutoff_choice,
            identification_summary,
            run_identification,
        )

        fit, validate = as_paths(cfg.fit), as_paths(cfg.validate)
        if not fit:
            raise InputError("usage: python -m robohealth_mj.identify arm=ARM fit=[LOG,...] "
                             "validate=[LOG,...] out=DIR")  # fmt: skip
        result = run_identification(arm_choice(cfg), fit, validate, cfg.map, Path(cfg.out),
                                    cutoff_choice(cfg.cutoff_hz))  # fmt: skip
    if result["fidelity_md"]:
        atomic_write_text(Path(cfg.out) / "fidelity.md", result["fidelity_md"])
        atomic_write_json(Path(cfg.out) / "fidelity.json", result["fidelity"])
    print(identification_summary(result, arm_choice(cfg), len(fit)))


if __name__ == "__main__":
    main()
