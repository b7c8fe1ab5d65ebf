"""Deployment: ONNX models that take raw windows, and the streaming health-monitoring runtime."""
