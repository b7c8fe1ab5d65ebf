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

from omegaconf import DictConfig, OmegaConf

from robohealth_mj.common.atomic import atomic_write_json, atomic_write_text
from robohealth_mj.common.config import arm_choice, run_tool
from robohealth_mj.common.errors import InputError, one_line_errors
from robohealth_mj.schema import JOINT_NAMES


def _paths(value) -> list[str]:
    if value is None:
        return []
    return (
        [str(v) for v in OmegaConf.to_container(value)]
        if OmegaConf.is_list(value)
        else [str(value)]
    )


def _cutoff(value) -> float | None:
    """``cutoff_hz``: a frequency in Hz, or ``auto`` (None: chosen on the fit logs)."""
    if value == "auto":
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise InputError(f"cutoff_hz: a frequency in Hz > 0 or auto, got {value!r}")
    return float(value)


def main(argv: list[str] | None = None) -> None:
    run_tool("identify", run, argv)


def run(cfg: DictConfig) -> None:
    with one_line_errors("identify"):
        from robohealth_mj.twin.report import run_identification

        fit, validate = _paths(cfg.fit), _paths(cfg.validate)
        if not fit:
            raise InputError("usage: python -m robohealth_mj.identify arm=ARM fit=[LOG,...] "
                             "validate=[LOG,...] out=DIR")  # fmt: skip
        result = run_identification(arm_choice(cfg), fit, validate, cfg.map, Path(cfg.out),
                                    _cutoff(cfg.get("cutoff_hz", "auto")))  # fmt: skip
    drives = result["twin"]["drive_overrides"]
    print(f"fitted on {result['twin']['fit']['seconds']:g} s of {len(fit)} log(s) -> "
          f"{result['twin_file']}")  # fmt: skip
    fitted = result["twin"]["fit"]
    tried = fitted.get("held_out_nrmse_by_cutoff_hz")
    how = ("given" if tried is None else "chosen on the fit logs, mean NRMSE on one left out: "
           + ", ".join(f"{c:g} Hz {100 * v:.2f} %" for c, v in tried.items()))  # fmt: skip
    print(f"  velocity low-pass {fitted['cutoff_hz']:g} Hz ({how})")
    k_t = result["twin"]["torque_constant_nm_per_a"]
    for j, joint in enumerate(JOINT_NAMES):
        d = drives[joint]
        print(f"  {joint:14s} armature {d['armature']:7.3f}  damping {d['damping']:7.3f}  "
              f"frictionloss {d['frictionloss']:7.3f}  k_t {k_t[j]:6.3f}")  # fmt: skip
    if result["fidelity_md"]:
        atomic_write_text(Path(cfg.out) / "fidelity.md", result["fidelity_md"])
        atomic_write_json(Path(cfg.out) / "fidelity.json", result["fidelity"])
        print(result["fidelity_md"])
    print(f"record on it: python -m robohealth_mj.record arm={arm_choice(cfg)} "
          f"sim.twin={result['twin_file']}")  # fmt: skip


if __name__ == "__main__":
    main()
