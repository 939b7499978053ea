"""Modules the executive needs later, imported in a thread once it is up.

``frog-bt run`` connects without importing numpy (0.1 s of start-up; only the
engagement maths needs it, at the first face sample). Importing it then would stall
that tick by 0.1 s, so :func:`warm` imports it in a daemon thread soon after the
start: the import takes the GIL in slices (``sys.getswitchinterval``), so the event
loop keeps running meanwhile.
"""

from __future__ import annotations

import importlib
import logging
import threading

log = logging.getLogger(__name__)
LATER = ("numpy",)  # imported lazily by frog_bt.maths.engagement


def _import(names: tuple[str, ...]) -> None:
    for name in names:
        try:
            importlib.import_module(name)
        except ImportError as exc:  # the first use will say so again
            log.warning("could not import %s ahead of use: %s", name, exc)


def warm(names: tuple[str, ...] = LATER) -> threading.Thread:
    """Import ``names`` in a daemon thread (returned, started)."""
    thread = threading.Thread(target=_import, args=(names,), name="frog-bt warm", daemon=True)
    thread.start()
    return thread
