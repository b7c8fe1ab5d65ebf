"""What ``python -m robohealth_mj.commission`` prints of a commissioning record: the healthy
minutes used, how the residual baseline settled, the placement found, the operating point moved,
the contact watch's thresholds and where the new model went."""

from __future__ import annotations

from robohealth_mj.deploy.commission import SETTLED


def commission_summary(record: dict) -> str:
    """The record (``commissioning.json``) as the lines a person reads after commissioning."""
    lines: list[str] = []
    lines.append(f"{record['healthy_minutes']:g} healthy minutes -> {record['checkpoint']}")
    for row in record["settling"]:
        lines.append(
            f"  after {row['minutes']:>4g} min: {row['relative_error']:.3f} of the final shift"
        )
    settled = record["settled_minutes"]
    if "settling_skipped" in record:
        lines.append(f"residual baseline not used: {record['settling_skipped']}")
    elif settled is not None:
        lines.append(f"baseline settled (within {SETTLED:.0%}) after {settled:g} min")
    else:
        lines.append(f"baseline not settled within {SETTLED:.0%}: record more healthy running")
    if "placement" in record:
        p = record["placement"]
        parts = [f"placement self-calibration ({p['fit']}): C refitted"]
        if "reconstruction_before" in p:
            before, after = p["reconstruction_before"], p["reconstruction_after"]
            parts.append(f"reconstruction {before:.3f} -> {after:.3f}")
        if "coupling_correlation" in p:
            parts.append(f"corr. with the arm's placement {p['coupling_correlation']:.2f}")
        lines.append(", ".join(parts))
        train = f"python -m robohealth_mj.train graph=harness graph.coupling_file={p['file']}"
        lines.append(f"placement found -> {p['file']} (a model trained on it: {train} ...)")
    point = record.get("operating_point", {})
    if "class_offset" in point:
        lines.append(
            f"healthy operating point ({point['recipe']}): this arm's healthy windows called "
            f"healthy {point['arm_healthy_rate_before']:.3f} -> "
            f"{point['arm_healthy_rate_after']:.3f} (validation: "
            f"{point['validation_healthy_rate']:.3f})"
        )
    if "healthy_rate_asked" in point:
        lines.append(
            f"asked for {point['healthy_rate_asked']:g} healthy: validation's faulted windows "
            f"called a fault {point['validation_fault_recall_before']:.3f} -> "
            f"{point['validation_fault_recall_after']:.3f}"
        )
    contact = record.get("contact", {})
    if "threshold_nm" in contact:
        values = " / ".join(f"{v:.2f}" for v in contact["threshold_nm"])
        lines.append(f"contact watch: thresholds {values} N·m ({contact['rule']})")
    elif contact:
        lines.append(f"contact watch off: {contact['skipped']}")
    if "onnx" in record:
        lines.append(f"exported -> {record['onnx']}")
    return "\n".join(lines)
