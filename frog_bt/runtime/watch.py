"""Hot reload between tours: watch the tree and config files, check a change, hand it over.

:class:`Watch` polls the files a loaded tree came from (every included file) and
the site configuration every ``interval`` wall seconds (file changes happen in
wall time; nothing of the tour is timed by it). A change is loaded and checked
in full (the same loader as at start: parameters, data flow) in a worker thread,
so the tick never waits for it. Building a tree touches nothing of the running one:
the loader keeps no state between loads, and a tree gets a board only when a core
sets it up (each core owns its own). A valid tree is handed to ``accept``; the
executive swaps it in at its next safe point (docked, no tour running). A bad
one is reported, one line per error, and the running tree stays.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from pathlib import Path

from frog_bt.behaviours import load_tree
from frog_bt.config import DEFAULT_CONFIG, Site, load_site
from frog_bt.errors import DefinitionError, error_lines
from frog_bt.tree.loader import DEFAULT_TREE, LoadedTree

log = logging.getLogger(__name__)
Stamp = tuple[int, int] | None  # (mtime_ns, size), None: missing


def tree_files(tree: LoadedTree) -> set[Path]:
    """Every file a loaded tree was built from."""
    return {Path(tree.file), *(Path(w.file) for w in tree.where.values())}


def _stamp(path: Path) -> Stamp:
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_mtime_ns, st.st_size


class Watch:
    def __init__(
        self,
        tree_path: Path | None,
        config_path: Path | None,
        tree: LoadedTree,
        accept: Callable[[Site, LoadedTree], None],
        *,
        refuse: Callable[[list[str]], None] | None = None,
        interval: float = 1.0,
    ) -> None:
        self.tree_path = tree_path
        self.config_path = config_path
        self.accept = accept
        self.refuse = refuse or (lambda lines: None)
        self.interval = interval
        self.stamps = self._stamps(tree)
        self.checks = 0

    def _stamps(self, tree: LoadedTree) -> dict[Path, Stamp]:
        files = tree_files(tree) | {self.config_path or DEFAULT_CONFIG}
        return {f: _stamp(f) for f in files}

    def changed(self) -> bool:
        return any(_stamp(f) != s for f, s in self.stamps.items())

    def _load(self) -> tuple[Site, LoadedTree]:
        site = load_site(self.config_path)
        return site, load_tree(self.tree_path or DEFAULT_TREE, site)

    async def check(self) -> bool | None:
        """Load and check the files if they changed: True accepted, False refused, None
        unchanged."""
        if not self.changed():
            return None
        self.checks += 1
        try:
            site, tree = await asyncio.to_thread(self._load)
        except DefinitionError as exc:
            lines = error_lines(exc)
            # Note the files as they are now, so that one bad save is reported once.
            self.stamps = {f: _stamp(f) for f in self.stamps}
            for line in lines:
                log.warning("tree change refused, the running tree stays: %s", line)
            self.refuse(lines)
            return False
        self.stamps = self._stamps(tree)
        self.accept(site, tree)
        return True

    async def run(self) -> None:
        while True:
            await asyncio.sleep(self.interval)
            await self.check()
