"""The MJCF scenes and the arm parameter files, shipped in the wheel as ``robohealth_mj.assets``.

This folder stays at the repository's top level; ``pyproject.toml`` maps it into the package."""
