"""Normalised windows as tensors on the training device, gathered by index per batch."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from robohealth_mj.data.arrays import Recording
from robohealth_mj.data.windows import Windows


@dataclass
class WindowBatch:
    x: torch.Tensor  # [B, W, N, F] normalised
    fault_class: torch.Tensor  # [B]
    fault_joint: torch.Tensor  # [B], -1 when healthy
    severity: torch.Tensor  # [B]
    active: torch.Tensor  # [B] bool


class WindowTensors:
    """Holds a recording's (graph-transformed) snapshots once; a batch is an index gather."""

    def __init__(
        self, x: np.ndarray, rec: Recording, mean: np.ndarray, std: np.ndarray, device: torch.device
    ) -> None:
        self.device = device
        self.x = torch.from_numpy((x - mean) / std).float().to(device)
        self.fault_class = torch.from_numpy(rec.fault_class).to(device)
        self.fault_joint = torch.from_numpy(rec.fault_joint).to(device)
        self.severity = torch.from_numpy(rec.severity).float().to(device)
        self.active = torch.from_numpy(rec.active).to(device)

    def snapshots(self, windows: Windows, which: np.ndarray | torch.Tensor) -> torch.Tensor:
        """The snapshot indices ``[B, W]`` of the windows ``which``."""
        starts = torch.as_tensor(windows.start[np.asarray(which)], device=self.device)
        offsets = torch.arange(windows.window, device=self.device)
        return starts[:, None] + offsets[None, :]

    def batch(self, windows: Windows, which: np.ndarray | torch.Tensor) -> WindowBatch:
        idx = self.snapshots(windows, which)
        last = idx[:, -1]
        return WindowBatch(
            self.x[idx],
            self.fault_class[last],
            self.fault_joint[last],
            self.severity[last],
            self.active[last],
        )
