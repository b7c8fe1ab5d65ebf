"""Spatio-temporal GNN variants (thesis §2.4, Table 3), built from ``conf/model/<name>.yaml``.

Every model takes a normalised window ``x: [B, W, N, F]`` (N = J joints then M sensors) and returns
a dict with ``class_logits [B, 7]``, ``joint_logits [B, J]`` and, where present,
``recon_energy [B, J]``, ``gamma []`` and ``severity [B]``.
"""

from robohealth_mj.models.build import build_model

__all__ = ["build_model"]
