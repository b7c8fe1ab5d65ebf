"""User errors: a bad file or setting gets one line naming it and exit status 2, no traceback.

Library code raises :class:`InputError` (or the schema's ``SchemaError``, a bag's ``BagError``,
``FileNotFoundError``) with a message that names the file and the line, field, topic or key; the
entry points run their work inside :func:`one_line_errors`, which turns exactly those (and a
config object whose constructor refused a value, which Hydra wraps) into
``<prog>: error: <message>`` on stderr and ``SystemExit(2)``. Anything else is a bug and keeps its
traceback.
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


def report(prog: str, exc: BaseException) -> int:
    """Print the one line; the exit status for it."""
    print(f"{prog}: error: {exc}", file=sys.stderr, flush=True)
    return 2


def user_error(exc: BaseException) -> BaseException | None:
    """The user's error behind ``exc``: itself, or, for a config object Hydra could not build
    (``_target_``), the user error its constructor raised, prefixed with the config key."""
    if isinstance(exc, USER_ERRORS):
        return exc
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
