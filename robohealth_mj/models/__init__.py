"""Spatio-temporal GNN variants (thesis §2.4, Table 3), built from ``conf/model/<name>.yaml``.

Every model takes a normalised window ``x: [B, W, N, F]`` (N = J joints then M sensors) and returns
a dict with ``class_logits [B, 7]``, ``joint_logits [B, J]`` and, where present,
``recon_energy [B, J]``, ``gamma []`` and ``severity [B]``.
"""

from robohealth_mj.models.build import build_model

# The nine variants in the thesis's Table 3 order (each has conf/model/<name>.yaml).
VARIANTS: tuple[str, ...] = (
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

__all__ = ["VARIANTS", "build_model"]
