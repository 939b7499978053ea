"""Alerts to people's phones: each alert change POSTed as JSON to every configured URL.

Never on the tick: :meth:`Webhooks.notify` only queues (a bounded queue; the oldest is
dropped, counted and logged, when a receiver is down for long). One asyncio task posts,
each URL in turn, retrying a failed POST (a connection error, a timeout, a 5xx) after
``webhook_backoff`` seconds, doubling, up to ``webhook_attempts`` tries; a 4xx is not
retried (the receiver refuses the message). Retries wait in real time: the receiver is
outside the project clock, like the rosbridge reconnect backoff.

The body: ``{"id", "kind", "text", "state", "since", "robot"}`` (``state``: raised,
cleared or acknowledged; ``since``: epoch seconds the alert was raised).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING

import msgspec

from frog_bt.config import AlertsCfg
from frog_bt.model.channels import Alert
from frog_bt.model.events import AlertChanged, Event
from frog_bt.warning_limit import WarningLimiter

if TYPE_CHECKING:
    from frog_bt.runtime.observer import Host

log = logging.getLogger(__name__)
QUEUE = 256  # alert changes waiting to be posted


@dataclass(slots=True)
class WebhookStats:
    posted: int = 0  # POSTs answered 2xx
    retried: int = 0
    failed: int = 0  # (alert, URL) given up on after its attempts, or refused (4xx)
    dropped: int = 0  # alert changes dropped from a full queue


class Webhooks:
    """Posts alert changes to ``cfg.webhooks``; start it inside the event loop."""

    def __init__(self, cfg: AlertsCfg, robot: str = "frog") -> None:
        self.cfg = cfg
        self.robot = robot
        self.stats = WebhookStats()
        self._queue: deque[Alert] = deque()
        self._ready = asyncio.Event()
        self._task: asyncio.Task[None] | None = None
        self._warnings = WarningLimiter(60.0, logger=log)

    def start(self) -> None:
        if self.cfg.webhooks and self._task is None:
            self._task = asyncio.get_running_loop().create_task(self._run())

    def attach(self, host: Host) -> None:
        """An observer of the executive: it hears every alert change."""

    def on_event(self, event: Event) -> None:
        if type(event) is AlertChanged:
            self.notify(event.t, event.alert)  # type: ignore[union-attr]

    def notify(self, _now: float, alert: Alert) -> None:
        """Queue one alert change."""
        if not self.cfg.webhooks:
            return
        if len(self._queue) >= QUEUE:
            self._queue.popleft()
            self.stats.dropped += 1
            self._warnings.warn("full", f"webhooks: queue full, {self.stats.dropped} alert "
                                        "changes dropped so far")
        self._queue.append(alert)
        self._ready.set()

    @property
    def pending(self) -> int:
        return len(self._queue)

    async def _run(self) -> None:
        import aiohttp

        timeout = aiohttp.ClientTimeout(total=self.cfg.webhook_timeout)
        async with aiohttp.ClientSession(timeout=timeout) as session:
            while True:
                await self._ready.wait()
                self._ready.clear()
                while self._queue:
                    alert = self._queue[0]
                    body = msgspec.json.encode({**msgspec.structs.asdict(alert),
                                                "robot": self.robot})
                    for url in self.cfg.webhooks:
                        await self._post(session, url, body, alert)
                    self._queue.popleft()

    async def _post(self, session: object, url: str, body: bytes, alert: Alert) -> None:
        import aiohttp

        assert isinstance(session, aiohttp.ClientSession)
        delay = self.cfg.webhook_backoff
        for attempt in range(1, self.cfg.webhook_attempts + 1):
            try:
                async with session.post(url, data=body, headers={
                        "Content-Type": "application/json"}) as response:
                    if response.status < 300:
                        self.stats.posted += 1
                        return
                    if response.status < 500:
                        self.stats.failed += 1
                        log.warning("webhook %s refused alert %s: HTTP %d", url, alert.id,
                                    response.status)
                        return
                    why = f"HTTP {response.status}"
            except (aiohttp.ClientError, TimeoutError, OSError) as exc:
                why = f"{type(exc).__name__}: {exc}"[:120]
            if attempt == self.cfg.webhook_attempts:
                break
            self.stats.retried += 1
            log.info("webhook %s: %s; try %d of %d in %.1f s", url, why, attempt + 1,
                     self.cfg.webhook_attempts, delay)
            await asyncio.sleep(delay)
            delay *= 2
        self.stats.failed += 1
        log.warning("webhook %s: alert %s not delivered after %d tries",
                    url, alert.id, self.cfg.webhook_attempts)

    async def close(self, timeout: float = 1.0) -> None:
        """Give what is queued up to ``timeout`` seconds, then stop."""
        task, self._task = self._task, None
        if task is None:
            return
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(timeout):
                while self._queue and not task.done():
                    await asyncio.sleep(0.05)
        task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await task
