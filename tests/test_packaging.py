"""What a user meets before any model: the wheel carries the configs and assets and runs from any
directory, the deployment side imports no deep-learning stack, and the research scripts under
``studies/`` import only what the package has."""

from __future__ import annotations

import ast
import importlib
import importlib.resources
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

# What the deployment install (`pip install '.[monitor]'`) lacks; importing any of it from the
# torch-free modules below is a bug.
HEAVY = ("torch", "torch_geometric", "lightgbm", "sklearn", "mujoco", "dm_control", "scipy",
         "matplotlib")  # fmt: skip
TORCH_FREE = (
    "robohealth_mj.monitor",
    "robohealth_mj.bag",
    "robohealth_mj.ingest",
    "robohealth_mj.robot",
    "robohealth_mj.runtime.fleet",
    "robohealth_mj.runtime.runtime",
    "robohealth_mj.runtime.online_eval",
    "robohealth_mj.runtime.sources",
    "robohealth_mj.runtime.metadata",
    "robohealth_mj.ros2.node",
    "robohealth_mj.ros2.live",
    "robohealth_mj.ros2.assembly",
    "robohealth_mj.runtime.online_report",
    "robohealth_mj.runtime.contact",
    "robohealth_mj.arms.description",
)

_BLOCKER = f"""
import sys
class _Blocked:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {HEAVY!r}:
            raise ImportError(f"{{name}} is not installed (blocked by the test)")
sys.meta_path.insert(0, _Blocked())
"""


def _blocked_python(code: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", _BLOCKER + textwrap.dedent(code)],
        cwd=cwd, capture_output=True, text=True, timeout=timeout,
    )  # fmt: skip


def test_the_deployment_modules_import_no_deep_learning_stack_or_simulator(tmp_path):
    done = _blocked_python(
        "import importlib\n"
        f"for name in {TORCH_FREE!r}:\n"
        "    importlib.import_module(name)\n"
        f"print(sorted(m for m in sys.modules if m.split('.')[0] in {HEAVY!r}))\n",
        tmp_path,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "[]"


def test_the_blocker_would_catch_a_heavy_import(tmp_path):
    """The guard above is only worth its name if an import of torch through it fails."""
    done = _blocked_python("import robohealth_mj.learn.trainer\n", tmp_path)
    assert done.returncode != 0 and "blocked by the test" in done.stderr


@pytest.mark.slow
def test_the_monitor_runs_an_exported_model_without_torch(deployed, tmp_path):
    out = tmp_path / "eval.json"
    done = _blocked_python(
        f"""
        from robohealth_mj.monitor import main
        main(["model={deployed["structural_onnx"]}", "source=replay",
              "file={deployed["heldout"]}", "evaluate=true", "quiet=true", "out={out}"])
        """,
        tmp_path,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    result = json.loads(out.read_text())
    assert result["source"] == "replay" and result["online_accuracy"] > 0.5


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The project's wheel, built from this checkout with the setuptools already installed."""
    out, source = tmp_path_factory.mktemp("wheel"), tmp_path_factory.mktemp("source")
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE", "NOTICE"):  # a build writes
        shutil.copy2(REPO / name, source / name)  # beside its source: build from a copy
    for name in ("robohealth_mj", "conf", "assets", "ready_models"):
        shutil.copytree(REPO / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
    done = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "--no-build-isolation",
         "--quiet", "-w", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    if done.returncode != 0 and "No module named" in done.stderr and "setuptools" in done.stderr:
        pytest.skip("building the wheel needs setuptools in this environment")
    assert done.returncode == 0, done.stderr[-2000:]
    (path,) = out.glob("robohealth_mj-*.whl")
    return path


def test_the_wheel_carries_every_config_and_asset(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for folder, package in (("conf", "robohealth_mj/conf"), ("assets", "robohealth_mj/assets")):
        shipped = {
            str(p.relative_to(REPO / folder))
            for p in (REPO / folder).rglob("*")
            if p.is_file() and p.suffix in (".yaml", ".xml", ".md")
        }
        assert shipped and {f"{package}/{name}" for name in shipped} <= names, folder


def test_the_wheel_carries_the_licence_and_the_notice(wheel):
    """Apache-2.0 in the metadata, and the licence texts (ours, UR's BSD-3 for its numbers)."""
    archive = zipfile.ZipFile(wheel)
    names = archive.namelist()
    (metadata,) = [n for n in names if n.endswith(".dist-info/METADATA")]
    assert "License-Expression: Apache-2.0" in archive.read(metadata).decode()
    licences = {n.rsplit("/", 1)[-1] for n in names if ".dist-info/licenses/" in n}
    assert {"LICENSE", "NOTICE", "ur_description_licence.md"} <= licences
    assert (
        "Apache License"
        in archive.read(next(n for n in names if n.endswith("licenses/LICENSE"))).decode()
    )


@pytest.fixture(scope="module")
def site(wheel, tmp_path_factory) -> Path:
    """The wheel installed into a folder of its own (not editable, not the source tree)."""
    target = tmp_path_factory.mktemp("site")
    done = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-compile",
         "--target", str(target), str(wheel)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    return target


def test_the_installed_wheel_records_from_an_empty_directory(site, tmp_path):
    """Installed (not editable, not the source tree), from a directory with nothing in it: the
    configs come from the package, the recording lands under that directory's ``outputs/``, and
    a user's own config directory adds a group option (``--config-dir``)."""
    empty = tmp_path / "work"
    mine = empty / "my_conf" / "curriculum"
    mine.mkdir(parents=True)
    standard = importlib.resources.files("robohealth_mj.conf") / "curriculum" / "standard.yaml"
    (mine / "mine.yaml").write_text(standard.read_text())
    env = {**os.environ, "PYTHONPATH": str(site), "PYTHONUNBUFFERED": "1"}
    done = subprocess.run(
        [sys.executable, "-c",
         "import runpy, sys, robohealth_mj; print('package:', robohealth_mj.__file__);"
         "sys.argv[0] = 'record'; runpy.run_module('robohealth_mj.record', run_name='__main__')",
         "--config-dir", "my_conf", "curriculum=mine", "session.duration_s=1",
         "session.progress=false"],
        cwd=empty, env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert f"package: {site}" in done.stdout
    (manifest,) = (empty / "outputs" / "record").glob("*/manifest.json")
    assert json.loads(manifest.read_text())["sample_count"] == 20


def test_the_installed_monitor_diagnoses_the_sample_with_a_ready_model(wheel, site, tmp_path):
    """``pip install 'robohealth_mj[monitor]'`` then one command, in an empty directory, with
    the simulator and the training stack out of reach: the stock model, by name, diagnoses the
    shipped sample log; the names are in the wheel with their cards."""
    names = set(zipfile.ZipFile(wheel).namelist())
    for name in ("full", "stock", "ur_driver"):
        assert {f"robohealth_mj/ready_models/{name}.{ext}" for ext in ("onnx", "md")} <= names
    empty = tmp_path / "work"
    empty.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site), "PYTHONUNBUFFERED": "1"}
    done = subprocess.run(
        [sys.executable, "-c", _BLOCKER + "import runpy, sys\nsys.argv[0] = 'monitor'\n"
         "runpy.run_module('robohealth_mj.monitor', run_name='__main__')",
         "model=stock", "file=sample"],
        cwd=empty, env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert ": friction @" in done.stdout and list(empty.iterdir()) == []


def _imports(path: Path) -> list[tuple[str, list[str], int]]:
    """``(module, names, line)`` of every absolute import in a script."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module != "__future__":
            found.append((node.module, [a.name for a in node.names], node.lineno))
        elif isinstance(node, ast.Import):
            found += [(a.name, [], node.lineno) for a in node.names]
    return found


SCRIPTS = sorted((REPO / "studies").rglob("*.py"))
# rclpy and the ROS message packages: installed by studies/ros2/*.sh in a venv of their own
ROS_VENV = ("rclpy", "sensor_msgs", "diagnostic_msgs", "std_msgs", "builtin_interfaces")


@pytest.mark.parametrize("script", SCRIPTS, ids=[str(p.relative_to(REPO)) for p in SCRIPTS])
def test_a_research_script_imports_only_what_exists(script):
    """The scripts that made the committed tables run against today's package: every module
    they import is installed and each name they take from the package exists (running them
    needs a campaign's outputs)."""
    for module, names, line in _imports(script):
        where = f"{script.relative_to(REPO)}:{line}"
        sibling = script.parent / f"{module}.py"
        if sibling.is_file():  # a helper beside the script in its study's folder
            body = ast.parse(sibling.read_text()).body
            assigned = (n.targets if isinstance(n, ast.Assign) else [n.target]
                        for n in body if isinstance(n, ast.Assign | ast.AnnAssign))  # fmt: skip
            imported = (n.names for n in body if isinstance(n, ast.ImportFrom))
            defined = (
                {n.name for n in body if hasattr(n, "name")}
                | {a.asname or a.name for names in imported for a in names}
                | {t.id for targets in assigned for t in targets if isinstance(t, ast.Name)}
            )  # what it defines, imports or assigns (its constants) for its scripts
            assert set(names) <= defined, f"{where}: {sibling.name} has no {set(names) - defined}"
            continue
        if not module.startswith("robohealth_mj"):
            if module.split(".")[0] in ROS_VENV:  # a real ROS 2 node's side, run in its own venv
                continue
            assert importlib.util.find_spec(module.split(".")[0]), f"{where}: no module {module}"
            continue
        loaded = importlib.import_module(module)
        for name in names:
            assert hasattr(loaded, name) or importlib.util.find_spec(f"{module}.{name}"), (
                f"{where}: {module} has no {name}"
            )


# The layers, lowest first: a module may import from its own layer and those below it.
LAYERS = (
    ("schema", "common"),
    ("arms",),  # each arm's description and ratings: the runtime reads them without the simulator
    ("sim",),
    ("faults",),
    ("data", "logs", "bags"),  # recordings on disk, controller logs and bags: one layer of readers
    ("recording", "twin"),  # simulating sessions; identifying a real arm's twin from its logs
    ("models",),
    ("learn",),
    ("prognostics",),  # health index and RUL: NumPy only, under the torch-free runtime
    ("runtime",),  # torch-free streaming
    ("deploy", "ros2"),  # offline deployment tools; the live bus
    ("reporting", "benchmarks"),
    ("<entry point>",),
)
PACKAGE = REPO / "robohealth_mj"


def _layer_of(parts: tuple[str, ...]) -> int:
    """The layer of ``robohealth_mj.<parts>``: a subpackage's, or the schema's, or an entry
    point's (every other module at the package root)."""
    name = parts[0] if parts else "<entry point>"
    if (PACKAGE / name).is_dir() or name == "schema":
        return next(k for k, layer in enumerate(LAYERS) if name in layer)
    return len(LAYERS) - 1


def test_the_runtime_imports_neither_the_simulator_nor_torch():
    """The streaming runtime reads arm data from ``arms/``, never from ``sim/`` (whose package
    holds the MuJoCo model): no module of ``runtime/`` names ``robohealth_mj.sim``."""
    offenders = [
        f"{path.name}:{line}"
        for path in sorted((REPO / "robohealth_mj" / "runtime").glob("*.py"))
        for module, _, line in _imports(path)
        if module.startswith(("robohealth_mj.sim", "torch"))
    ]
    assert not offenders, offenders


def test_layers_point_one_way():
    """sim -> data -> recording -> models/learn -> runtime -> deploy -> entry points: no module
    imports from a layer above its own (a lazy import inside a function counts too)."""
    upward = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts[0] in ("conf", "assets") or parts == ("__init__",):
            continue
        own = _layer_of(parts if len(parts) > 1 else (parts[0],))
        for module, _, line in _imports(path):
            if not module.startswith("robohealth_mj."):
                continue
            target = _layer_of(tuple(module.split(".")[1:]))
            if target > own:
                upward.append(f"robohealth_mj/{'/'.join(parts)}.py:{line} imports {module}")
    assert upward == []


def test_the_package_root_holds_the_entry_points_only():
    library = [
        p.name
        for p in PACKAGE.glob("*.py")
        if p.stem != "__init__" and '__name__ == "__main__"' not in p.read_text()
    ]
    assert library == []
