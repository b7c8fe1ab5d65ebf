"""Training and evaluation: tensors on the device, losses, metrics, checkpoints."""
