"""robohealth_mj: mechanical health monitoring of robot arms with graph neural networks."""

__version__ = "0.1.0"
