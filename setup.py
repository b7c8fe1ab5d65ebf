"""The package list, which pyproject.toml alone cannot say: every ``robohealth_mj*`` package
found in the source tree, plus ``conf/``, ``assets/`` and ``ready_models/``, which stay at the
repository's top level and are mapped into the package (``[tool.setuptools] package-dir``).
Everything else is in pyproject.toml."""

from setuptools import find_packages, setup

packages = find_packages(include=["robohealth_mj*"])
setup(
    packages=[*packages, "robohealth_mj.conf", "robohealth_mj.assets", "robohealth_mj.ready_models"]
)
