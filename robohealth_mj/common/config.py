"""The project's Hydra configs: every configured command runs as a Hydra app (``run_tool``), and
bench and tests compose them outside one (``compose_config``)."""

from __future__ import annotations

import functools
import logging
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeVar

import hydra
from hydra import compose, initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from hydra.core.hydra_config import HydraConfig
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.core.override_parser.types import OverrideType
from hydra.errors import ConfigCompositionException, MissingConfigException, OverrideParseException
from omegaconf import DictConfig, OmegaConf
from omegaconf.errors import OmegaConfBaseException

from robohealth_mj.common.errors import InputError, report
from robohealth_mj.common.resources import HYDRA_CONF, conf_dir, is_arm_file

T = TypeVar("T")


def placement_name(graph_cfg: Any) -> str:
    """A short name for a graph config's placement, for run directories and report rows:
    ``C0`` (the default harness or no coupling at all), ``seed7_m6`` (drawn), ``file`` or
    ``given``."""
    get = graph_cfg.get if hasattr(graph_cfg, "get") else lambda k, d=None: d
    if get("coupling_seed") is not None:
        return f"seed{int(get('coupling_seed'))}_m{int(get('coupling_sensors', 4))}"
    if get("coupling_file"):
        return "file"
    if get("coupling") is not None:
        return "given"
    return "C0"


def arm_choice(cfg: DictConfig) -> str | None:
    """The arm a tool's ``arm=<name>`` chose (the ``arm`` config group: its ``name``), or None."""
    arm = cfg.get("arm")
    return None if arm is None else str(arm if isinstance(arm, str) else arm.name)


def as_paths(value: Any) -> list[str]:
    """A key that takes one path or a list of them (``fit=a.csv``, ``fit=[a.csv,b.csv]``)."""
    if value is None:
        return []
    listed = OmegaConf.to_container(value) if OmegaConf.is_list(value) else [value]
    return [str(v) for v in listed]


def register_resolvers() -> None:
    """``${placement:${graph}}`` in the configs (run directories): see ``placement_name``."""
    OmegaConf.register_new_resolver("placement", placement_name, replace=True)


def compose_config(name: str, overrides: Sequence[str] = ()) -> DictConfig:
    """Compose ``conf/<name>.yaml`` with overrides, leaving Hydra's global state clean."""
    register_resolvers()
    GlobalHydra.instance().clear()
    with initialize_config_dir(config_dir=str(conf_dir()), version_base="1.3"):
        cfg = compose(config_name=name, overrides=list(overrides))
    GlobalHydra.instance().clear()
    return cfg


def run_tool(
    name: str, task: Callable[[DictConfig], T], argv: Sequence[str] | None = None
) -> T | None:
    """Run ``task`` as the Hydra app of ``conf/<name>.yaml``: every configured command is one
    (``--help`` lists its groups and keys, ``--config-dir`` adds a user's configs, ``-m`` sweeps),
    called as ``python -m robohealth_mj.<name> key=value ...`` or as ``main([...])`` from code and
    tests, which get the task's return value (the last job's in a sweep).

    A user's mistake in an override is one line and exit status 2, as every other user error
    is: Hydra's own report of a key the config lacks, a group option that does not exist or a
    value it cannot parse is several lines and exit status 1, and a value of another kind than
    the key's default (``speed=fast`` where a number goes) would pass Hydra and fail deep in the
    tool. Hydra raises instead of reporting only under ``HYDRA_FULL_ERROR``, which is set for the
    call (a bug inside the app then keeps its whole traceback)."""
    returned: list[T] = []
    started: list[bool] = []

    @functools.wraps(task)  # Hydra names the job after the task's module (monitor, record ...)
    def job(cfg: DictConfig) -> None:
        started.append(True)
        hydra_cfg = HydraConfig.get()
        if not checked:  # a sweep's jobs, a user's --config-dir: checked as Hydra composed them
            _check_override_kinds(
                name, hydra_cfg.overrides.task, hydra_cfg.runtime.choices, _compose_here
            )
        returned.append(task(cfg))

    app = hydra.main(config_path=HYDRA_CONF, config_name=name, version_base="1.3")(job)
    args = [o for a in (sys.argv[1:] if argv is None else list(argv)) for o in arm_override(a)]
    checked = _check_before_hydra(name, args)
    before = os.environ.get("HYDRA_FULL_ERROR")
    os.environ["HYDRA_FULL_ERROR"] = "1"
    GlobalHydra.instance().clear()
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level  # Hydra's logging set-up is the call's alone
    try:
        saved, sys.argv = sys.argv, [f"robohealth_mj.{name}", *args]  # what hydra.main parses
        try:
            app()
        finally:
            sys.argv = saved
    except (ConfigCompositionException, OverrideParseException, MissingConfigException) as exc:
        raise SystemExit(report(name, InputError(_one_line(exc)))) from None
    except OmegaConfBaseException as exc:
        if started:  # inside the task: a bug, with its traceback
            raise
        # Hydra took an override but could not resolve the config with it: OmegaConf's reason
        raise SystemExit(report(name, InputError(str(exc).splitlines()[0]))) from None
    finally:
        GlobalHydra.instance().clear()
        root.handlers[:], root.level = handlers, level
        if before is None:
            os.environ.pop("HYDRA_FULL_ERROR", None)
        else:
            os.environ["HYDRA_FULL_ERROR"] = before
    return returned[-1] if returned else None


def arm_override(arg: str) -> list[str]:
    """``arm=<your.urdf>`` is the arm group's option ``ur5e`` with its ``name`` set to the file
    (absolute, so it reads back from any directory): a file is not one of the group's options.
    Any other argument as it is."""
    key, _, value = arg.partition("=")
    if key in ("arm", "+arm") and is_arm_file(value):
        return [f"{key}=ur5e", f"arm.name={Path(value).resolve()}"]
    return [arg]


_FLAGS_WITH_VALUE = ("--config-dir", "-cd", "--config-path", "-cp", "--config-name", "-cn",
                     "--cfg", "-c", "--package", "-p", "--info", "-i")  # fmt: skip


def _check_before_hydra(name: str, args: Sequence[str]) -> bool:
    """The kind check on the packaged configs before Hydra runs (a value that replaces a block,
    ``model=gat``, would otherwise fail inside Hydra's own set-up in OmegaConf's wording); False
    where it cannot be made here (a sweep, a user's ``--config-dir``), so the job makes it."""
    if any(a in ("-m", "--multirun") or a.startswith(_FLAGS_WITH_VALUE[:2]) for a in args):
        return False
    given = [
        arg for before, arg in zip(["", *args], args, strict=False)
        if "=" in arg and not arg.startswith("-") and before not in _FLAGS_WITH_VALUE
    ]  # fmt: skip
    try:
        OverridesParser.create().parse_overrides(given)
    except OverrideParseException:
        return True  # Hydra names what it cannot parse
    _check_override_kinds(name, given, {}, compose_config)
    return True


def _compose_here(name: str, overrides: Sequence[str]) -> DictConfig:
    """Compose inside a running Hydra app (its search path, a user's ``--config-dir`` too)."""
    return compose(config_name=name, overrides=list(overrides))


def _check_override_kinds(
    tool: str, given: Sequence[str], choices: Any, compose_with: Callable[..., DictConfig]
) -> None:
    """Each ``key=value`` of the command line against the key's default in the config composed
    with the same group choices (``arm=ur10e`` changes which defaults ``arm.*`` has). A group is
    a key Hydra chose an option for, or a folder of the packaged configs."""

    def is_group(key: str) -> bool:
        return key in choices or (conf_dir() / key).is_dir()

    overrides = OverridesParser.create().parse_overrides(list(given))
    groups = [o.input_line for o in overrides if is_group(o.key_or_group)]
    changed = (o for o in overrides if o.type == OverrideType.CHANGE and not o.is_sweep_override())
    values = [o for o in changed if not is_group(o.key_or_group)]
    if not values:
        return
    try:
        default = compose_with(tool, groups)
    except (ConfigCompositionException, OverrideParseException):
        return  # a group option that does not exist: Hydra names it
    for override in values:
        key = override.key_or_group
        given = OmegaConf.create()
        OmegaConf.update(given, key, override.value(), force_add=True)
        _check_kind(default, key, given, tool)


_KINDS = (
    (bool, "true or false"),
    ((int, float), "a number"),
    (str, "text"),
    (dict, "a block of keys, each set on its own (key.name=value)"),
    (list, "a list, [a, b]"),
)


def _kind(value: Any) -> tuple[type, str] | None:
    return next((k for k in _KINDS if isinstance(value, k[0])), None)


def _check_kind(cfg: DictConfig, key: str, given: DictConfig, tool: str) -> None:
    """A value of another kind than the key's default (``speed=fast`` where a number goes,
    ``alarm=3`` for a block of keys) is one line naming the key, not a failure deep inside the
    tool. A default of null takes anything, a word default a number too."""
    default = OmegaConf.select(cfg, key, default=None)
    value = OmegaConf.select(given, key)
    if OmegaConf.is_config(default):
        default = OmegaConf.to_container(default)
    if OmegaConf.is_config(value):
        value = OmegaConf.to_container(value)
    want, have = _kind(default), _kind(value)
    if want is None or value is None or have == want:
        return
    if want[0] is str and have is not None and have[0] == (int, float):
        return  # a word default with a number beside it (cutoff_hz: auto or Hz)
    shown = f"keys {', '.join(default)}" if isinstance(default, dict) else f"default {default!r}"
    raise SystemExit(report(tool, InputError(f"{key}={value!r}: {key} takes {want[1]} ({shown})")))


def _one_line(exc: BaseException) -> str:
    """Hydra's message on one line: the override it could not parse first, the reason it gives
    (OmegaConf's, behind it) after, without the key dump and the config search path."""
    text = str(exc).split("Config search path:")[0]
    named = re.search(r"Could not override '([^']+)'", text)
    if named and "is not in struct" in str(exc.__cause__):  # Hydra's advice (+key=) adds a key no
        return f"{named[1]}: no such key; --help lists the keys"  # one reads
    if exc.__cause__ is not None:
        text += f" ({str(exc.__cause__).splitlines()[0]})"
    lines = (line.strip() for line in text.splitlines())
    kept = [line for line in lines if line and not line.startswith(("full_key:", "object_type="))]
    override = getattr(exc, "override", None)
    return " ".join([f"{override}:"] * bool(override) + kept)
