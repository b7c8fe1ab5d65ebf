"""User errors: a bad file or setting gets one line naming it and exit status 2, no traceback.

Library code raises :class:`InputError` (or the schema's ``SchemaError``, a bag's ``BagError``,
``FileNotFoundError``) with a message that names the file and the line, field, topic or key; the
entry points run their work inside :func:`one_line_errors`, which turns exactly those (and a
config object whose constructor refused a value, which Hydra wraps) into
``<prog>: error: <message>`` on stderr and ``SystemExit(2)``. A third-party module that an extra
brings and this install lacks is the user's error too: the line names the extra to install
(:func:`missing_extra`). Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from robohealth_mj.schema import SchemaError


class InputError(ValueError):
    """A user's file or setting cannot be used; the message says which and why."""


USER_ERRORS = (InputError, SchemaError, FileNotFoundError, IsADirectoryError, PermissionError)

# The extra of pyproject.toml that brings each third-party module a command may need; the base
# install (the deployment side) has none of them.
EXTRA_OF = {
    **dict.fromkeys(
        ("mujoco", "dm_control", "scipy", "matplotlib", "PIL", "imageio", "imageio_ffmpeg"), "sim"
    ),
    **dict.fromkeys(
        ("torch", "torch_geometric", "lightgbm", "sklearn", "onnxscript", "tensorboard"), "train"
    ),
    **dict.fromkeys(("cyclonedds", "pyarrow", "cryptography"), "monitor"),
    "progpy": "prognostics",
}


def missing_extra(exc: BaseException) -> InputError | None:
    """The one line for an import an extra would have satisfied, found anywhere in ``exc``'s
    chain (Hydra and importlib wrap it); None when ``exc`` is not that."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, ImportError) and (exc.name or "").split(".")[0] in EXTRA_OF:
            module = exc.name.split(".")[0]
            extra = EXTRA_OF[module]
            return InputError(
                f"this needs the '{extra}' extra (no module '{module}' here): "
                f"pip install 'robohealth_mj[{extra}]'"
            )
        exc = exc.__cause__ or exc.__context__
    return None


def report(prog: str, exc: BaseException) -> int:
    """Print the one line; the exit status for it."""
    print(f"{prog}: error: {exc}", file=sys.stderr, flush=True)
    return 2


def user_error(exc: BaseException) -> BaseException | None:
    """The user's error behind ``exc``: itself, or, for a config object Hydra could not build
    (``_target_``), the user error its constructor raised, prefixed with the config key; or
    the extra a missing module needs."""
    if isinstance(exc, USER_ERRORS):
        return exc
    if (extra := missing_extra(exc)) is not None:
        return extra
    from hydra.errors import InstantiationException

    if isinstance(exc, InstantiationException) and isinstance(exc.__cause__, USER_ERRORS):
        key = re.search(r"full_key: (\S+)", str(exc))
        return InputError(f"config '{key.group(1)}': {exc.__cause__}" if key else exc.__cause__)
    return None


@contextmanager
def one_line_errors(prog: str) -> Iterator[None]:
    try:
        yield
    except Exception as exc:
        error = user_error(exc)
        if error is None:
            raise
        raise SystemExit(report(prog, error)) from None


def exit_status(prog: str, run: Callable[[], int], *also: type[Exception]) -> int:
    """``run()``'s status, or 2 after the one line for a user error (or one of ``also``): for
    the argparse tools whose ``main`` returns a status."""
    try:
        return run()
    except (*USER_ERRORS, *also) as exc:
        return report(prog, exc)
    except Exception as exc:
        error = user_error(exc)
        if error is None:
            raise
        return report(prog, error)
