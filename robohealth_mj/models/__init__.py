"""Spatio-temporal GNN variants (thesis §2.4, Table 3) and the ``gbdt`` baseline, built from
``conf/variant/<name>.yaml`` (plus ``conf/backbone/<name>.yaml`` for the networks).

Every model takes a normalised window ``x: [B, W, N, F]`` (N = J joints then M sensors) and returns
a dict with ``class_logits [B, 7]``, ``joint_logits [B, J]`` and, where present,
``recon_energy [B, J]``, ``gamma []`` and ``severity [B]``.
"""

from robohealth_mj.models.build import build_model

# The nine networks in the thesis's Table 3 order (each has conf/variant/<name>.yaml).
NETWORK_VARIANTS: tuple[str, ...] = (
    "mlp",
    "gat",
    "stgnn_fixed",
    "stgnn_fixed_pose",
    "stgnn_learnable",
    "stgnn_pose_cond",
    "stgnn_pose_spectral",
    "anomaly_residual",
    "pose_anomaly",
)
# Every variant, the classical baseline first: it is the bar each table compares against.
VARIANTS: tuple[str, ...] = ("gbdt", *NETWORK_VARIANTS)

__all__ = ["NETWORK_VARIANTS", "VARIANTS", "build_model"]
