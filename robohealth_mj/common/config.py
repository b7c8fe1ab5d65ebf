"""Composing the project's Hydra configs outside a ``@hydra.main`` entry point (bench, tests)."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from typing import Any

from hydra import compose, initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from hydra.errors import ConfigCompositionException, OverrideParseException
from omegaconf import DictConfig, OmegaConf

from robohealth_mj.common.errors import InputError, report
from robohealth_mj.common.resources import conf_dir


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


def load_cli_config(
    name: str, argv: Sequence[str], prog: str, include: Sequence[str] = ()
) -> DictConfig:
    """``conf/<name>.yaml`` with ``key=value`` overrides, for the small tools that are not Hydra
    apps (``model=`` there names a file, not the training ``model`` config group). Each name in
    ``include`` adds ``conf/<include>.yaml`` under that key (one block shared by several tools)."""
    cfg = OmegaConf.load(conf_dir() / f"{name}.yaml")
    for key in include:
        cfg[key] = OmegaConf.load(conf_dir() / f"{key}.yaml")
    if argv and argv[0] in ("-h", "--help"):  # the file itself: every key, its default, why
        texts = [(conf_dir() / f"{n}.yaml").read_text() for n in (name, *include)]
        print(f"usage: python -m {prog} key=value ...\n\nconf/{name}.yaml:\n{texts[0]}", end="")
        for key, text in zip(include, texts[1:], strict=True):
            print(f"\n{key}.* (conf/{key}.yaml):\n{text}", end="")
        raise SystemExit(0)
    keys = [a.split("=", 1)[0] for a in argv]
    unknown = [k for k in keys if k.split(".")[0] not in cfg]
    tool = prog.rsplit(".", 1)[-1]
    if unknown or any("=" not in a for a in argv):
        raise SystemExit(report(tool, InputError(
            f"usage: python -m {prog} key=value ... (keys: {', '.join(cfg)}); "
            f"not understood: {unknown or list(argv)}"
        )))  # fmt: skip
    given = []
    for arg in argv:  # each value is read as YAML, one by one: say which one it cannot read
        try:
            given.append(OmegaConf.from_dotlist([arg]))
        except Exception as exc:  # YAML's and OmegaConf's own parse errors
            raise SystemExit(report(tool, InputError(
                f"{arg}: not a value ({type(exc).__name__}); quote text that holds braces or "
                "a colon, e.g. key='\"{arm}_\"'"
            ))) from None  # fmt: skip
    for arg, value in zip(argv, given, strict=True):
        _check_kind(cfg, arg.split("=", 1)[0], value, tool)
    return OmegaConf.merge(cfg, *given)


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


def run_hydra_app(prog: str, app: Callable[[], Any]) -> None:
    """Run a ``@hydra.main`` entry point so that an override Hydra cannot apply (a key the config
    lacks, a config group option that does not exist, a value it cannot parse) is one line and
    exit status 2, as every other user error is: Hydra's own report of it is several lines and
    exit status 1. Hydra raises instead of reporting only under ``HYDRA_FULL_ERROR``, which is
    set for the call (a bug inside the app then keeps its whole traceback)."""
    before = os.environ.get("HYDRA_FULL_ERROR")
    os.environ["HYDRA_FULL_ERROR"] = "1"
    try:
        app()
    except (ConfigCompositionException, OverrideParseException) as exc:
        raise SystemExit(report(prog, InputError(_one_line(exc)))) from None
    finally:
        if before is None:
            os.environ.pop("HYDRA_FULL_ERROR", None)
        else:
            os.environ["HYDRA_FULL_ERROR"] = before


def _one_line(exc: BaseException) -> str:
    """Hydra's message on one line: the override it could not parse first, the reason it gives
    (OmegaConf's, behind it) after, without the key dump and the config search path."""
    text = str(exc).split("Config search path:")[0]
    if exc.__cause__ is not None:
        text += f" ({str(exc.__cause__).splitlines()[0]})"
    lines = (line.strip() for line in text.splitlines())
    kept = [line for line in lines if line and not line.startswith(("full_key:", "object_type="))]
    override = getattr(exc, "override", None)
    return " ".join([f"{override}:"] * bool(override) + kept)
