"""The Hydra configs, shipped in the wheel as ``robohealth_mj.conf`` (``pkg://robohealth_mj.conf``).

This folder stays at the repository's top level; ``pyproject.toml`` maps it into the package."""
