"""Whose log line is it: the executive a record was logged for, in a context variable.

An executive marks its own asyncio task as it starts (``logctx.mark(self)``, the first
line of :meth:`~frog_bt.runtime.executive.Executive.run`). The tasks it creates, the
callbacks it schedules and the threads of :func:`asyncio.to_thread` copy that context, so
a record logged from any of them belongs to it, whichever module's logger wrote it. A
handler that shows one executive's lines (the console's) takes :class:`OwnedBy`; two
executives in one process each see their own. A record logged outside every executive's
context (the command line's own lines) belongs to none.

The cost is one context-variable read per record that reaches such a handler.
"""

from __future__ import annotations

import contextvars
import logging
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

_OWNER: contextvars.ContextVar[object | None] = contextvars.ContextVar(
    "frog_bt_log_owner", default=None
)


def mark(owner: object) -> None:
    """From here on, in the current context (this task and what it then starts), the
    records logged are ``owner``'s."""
    _OWNER.set(owner)


def owner() -> object | None:
    """Whose records the current context logs (None: no executive's)."""
    return _OWNER.get()


def run_as(owner: object, start: Callable[[], T]) -> T:
    """``start()`` in a copy of the current context marked as ``owner``'s: what it starts
    for an executive from outside its task (its webhooks' sender) logs as the executive's."""
    context = contextvars.copy_context()
    context.run(mark, owner)
    return context.run(start)


class OwnedBy(logging.Filter):
    """Passes the records logged in ``owner``'s context, and only those."""

    def __init__(self, owner: object) -> None:
        super().__init__()
        self.owner = owner

    def filter(self, record: logging.LogRecord) -> bool:
        return _OWNER.get() is self.owner
