"""User errors: a bad file or setting gets one line naming it and exit status 2, no traceback.

Library code raises :class:`InputError` (or the schema's ``SchemaError``, a bag's ``BagError``,
``FileNotFoundError``) with a message that names the file and the line, field, topic or key; the
entry points run their work inside :func:`one_line_errors`, which turns exactly those into
``<prog>: error: <message>`` on stderr and ``SystemExit(2)``. Anything else is a bug and keeps its
traceback.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager

from robohealth_mj.schema import SchemaError


class InputError(ValueError):
    """A user's file or setting cannot be used; the message says which and why."""


USER_ERRORS = (InputError, SchemaError, FileNotFoundError, IsADirectoryError, PermissionError)


@contextmanager
def one_line_errors(prog: str) -> Iterator[None]:
    try:
        yield
    except USER_ERRORS as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr, flush=True)
        raise SystemExit(2) from None
