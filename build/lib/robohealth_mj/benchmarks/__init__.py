"""Throughput benchmarks behind ``python -m robohealth_mj.bench`` (measurements, not tests)."""
