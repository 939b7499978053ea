"""Where batch work runs: ``--jobs N`` processes on this machine, or ``--scheduler ADDRESS``
a dask.distributed cluster (the ``fleet`` extra). Both are a
:class:`concurrent.futures.Executor`; ``frog-bt replay`` (batch) and ``frog-bt report``
submit their per-file work to it the same way."""

from __future__ import annotations

import contextlib
import multiprocessing
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor

from frog_bt.errors import FrogError


class ExecutorError(FrogError):
    """The executor cannot be had (dask.distributed missing, scheduler unreachable)."""


@contextlib.contextmanager
def executor(
    jobs: int, scheduler: str | None = None, *, connect_timeout: float = 10.0
) -> Iterator[Executor]:
    """Processes (forked where the platform allows: workers start with the modules
    already imported), or a dask.distributed client's executor."""
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise ExecutorError(
                "--scheduler needs dask.distributed: pip install 'frog-bt[fleet]'"
            ) from None
        try:
            client = Client(scheduler, timeout=connect_timeout)
        except (OSError, TimeoutError) as exc:
            raise ExecutorError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
        try:
            yield client.get_executor()
        finally:
            client.close()
        return
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else None)
    with ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
        yield pool
