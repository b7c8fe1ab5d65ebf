"""The streaming health-monitoring runtime: exported ONNX models on live or replayed streams,
evidence, alarms and on-line evaluation. Needs numpy and onnxruntime, never torch (a test blocks
the import); the offline tools that make its models are in :mod:`robohealth_mj.deploy`."""
