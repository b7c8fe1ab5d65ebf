"""Offline deployment tools (they need torch): ONNX export, commissioning on an arm's healthy
running, placement refit, the healthy operating point, alarm tuning, episode rendering. What they
produce is run by the torch-free streaming runtime (:mod:`robohealth_mj.runtime`)."""
