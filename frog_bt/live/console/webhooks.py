"""Alerts to people's phones and to the site's alert router: each alert change POSTed to
every destination of ``alerts.webhooks``, in the format it understands
(:mod:`.alertbodies`: the generic JSON, ntfy, Alertmanager); and a shift's handover
(:mod:`.handover`) to those people read (the generic JSON and ntfy), through the same
queues (:meth:`Webhooks.hand_over`).

Never on the tick: :meth:`Webhooks.notify` only queues. Each destination has its own
bounded queue and its own task (:class:`Destination`), so a dead receiver delays nobody
else; when a queue is full its oldest change is dropped, counted and logged. A failed POST
(a connection error, a timeout, a 5xx) is tried again after ``webhook_backoff`` seconds,
doubling, up to ``webhook_attempts`` tries; a 4xx is not retried (the receiver refuses the
message), nor is a 3xx: redirects are never followed, a body goes only where the site
configuration says. Retries wait in real time: the receivers are outside the project
clock, like the rosbridge reconnect backoff.

URLs may carry a password or a key: every log line shows them as ``scheme://host[:port]``
(:func:`redact`). Bodies are bounded (:data:`BODY_MAX`), and of an answer at most
:data:`ANSWER_MAX` bytes are read.

With ``alerts.console_url`` set, a notification of an alert not yet acknowledged carries a
signed link acknowledging it (:mod:`.acklink`; the key is derived from the console's
token, which is passed in as ``ack_secret``).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from datetime import tzinfo
from typing import TYPE_CHECKING
from urllib.parse import urlsplit

import msgspec

from frog_bt.clock import SITE_TZ
from frog_bt.config import AlertsCfg, Webhook
from frog_bt.live.console import alertbodies, handover
from frog_bt.live.console.acklink import ack_link, link_key
from frog_bt.live.console.alertbodies import Outgoing, Sender
from frog_bt.live.console.handover import Handover
from frog_bt.model.channels import Alert
from frog_bt.model.events import AlertChanged, Event
from frog_bt.warning_limit import WarningLimiter

if TYPE_CHECKING:
    import aiohttp

    from frog_bt.runtime.observer import Host

log = logging.getLogger(__name__)
QUEUE = 256  # alert changes waiting to be posted, per destination
BODY_MAX = 32_768  # bytes of a body sent (text fields are cut well before)
ANSWER_MAX = 4096  # bytes of an answer read
HANDOVER_FORMATS = ("json", "ntfy")  # Alertmanager routes alerts, not handovers
Told = Outgoing | Handover  # what a destination sends: an alert change, or a handover


def redact(url: str) -> str:
    """``url`` as it may be shown: ``scheme://host[:port]``, without user, password, path
    or query (any of which may be a secret)."""
    try:
        parts = urlsplit(url)
        port = parts.port
    except ValueError:
        return "<a malformed URL>"
    if not parts.scheme or not parts.hostname:
        return "<a malformed URL>"
    host = f"[{parts.hostname}]" if ":" in parts.hostname else parts.hostname
    return f"{parts.scheme}://{host}" + (f":{port}" if port is not None else "")


@dataclass(slots=True)
class WebhookStats:
    posted: int = 0  # POSTs answered 2xx
    retried: int = 0
    failed: int = 0  # (alert, URL) given up on after its attempts, or refused (3xx, 4xx)
    dropped: int = 0  # alert changes dropped from a full queue


class Destination:
    """One URL: its queue, its task, its retries. Alertmanager destinations also re-send
    their firing alerts every :data:`~.alertbodies.REFRESH` seconds (Alertmanager's
    clients keep firing alerts alive)."""

    def __init__(
        self,
        hook: Webhook,
        cfg: AlertsCfg,
        sender: Sender,
        stats: WebhookStats,
        wall: Callable[[], float],
        tz: tzinfo = SITE_TZ,
    ) -> None:
        self.hook = hook
        self.tz = tz
        self.cfg = cfg
        self.sender = sender
        self.stats = stats
        self.wall = wall
        self.shown = redact(hook.url)
        self.url = alertbodies.target(hook)
        self.refresh = alertbodies.REFRESH if hook.format == "alertmanager" else None
        self.queue: deque[Told] = deque()
        self.firing: dict[str, Outgoing] = {}  # alertmanager: id -> latest, to re-send
        self.busy = False
        self._ready = asyncio.Event()
        self._warnings = WarningLimiter(60.0, logger=log)
        self.task: asyncio.Task[None] | None = None

    def put(self, out: Told) -> None:
        if len(self.queue) >= QUEUE:
            self.queue.popleft()
            self.stats.dropped += 1
            self._warnings.warn(
                "full",
                f"webhook {self.shown}: queue full, "
                f"{self.stats.dropped} alert changes dropped so far",
            )
        self.queue.append(out)
        self._ready.set()

    @property
    def idle(self) -> bool:
        return not self.queue and not self.busy

    async def run(self) -> None:
        import aiohttp

        loop = asyncio.get_running_loop()
        timeout = aiohttp.ClientTimeout(total=self.cfg.webhook_timeout)
        next_refresh = loop.time() + (self.refresh or 0.0)
        async with aiohttp.ClientSession(timeout=timeout) as session:
            while True:
                with contextlib.suppress(TimeoutError):
                    async with asyncio.timeout(
                        None if self.refresh is None else next_refresh - loop.time()
                    ):
                        await self._ready.wait()
                self._ready.clear()
                if self.refresh is not None and loop.time() >= next_refresh:
                    # alertmanager: say the firing ones still fire, however busy the queue
                    next_refresh = loop.time() + self.refresh
                    await self._refresh(session)
                while self.queue:
                    out = self.queue[0]
                    self.busy = True
                    try:
                        if isinstance(out, Handover):
                            await self._post(session, self._encode_handover(out), "the handover")
                        else:
                            self._track(out)
                            await self._post(session, self._encode(out), f"alert {out.alert.id}")
                    finally:
                        self.busy = False
                    if self.queue and self.queue[0] is out:
                        self.queue.popleft()

    def _track(self, out: Outgoing) -> None:
        if self.refresh is None:
            return
        if out.alert.state == "cleared":
            self.firing.pop(out.alert.id, None)
        else:
            self.firing[out.alert.id] = out

    async def _refresh(self, session: aiohttp.ClientSession) -> None:
        if not self.firing:
            return
        now = self.wall()
        outs = [Outgoing(o.alert, now, o.started, o.ack_url) for o in self.firing.values()]
        await self._post(
            session,
            msgspec.json.encode(alertbodies.alertmanager(outs, self.sender)),
            "alerts (still firing)",
        )

    def _encode(self, out: Outgoing) -> bytes:
        data = msgspec.json.encode(alertbodies.body(self.hook, out, self.sender))
        if len(data) > BODY_MAX:  # text fields are cut well before: say so, send the gist
            log.warning(
                "webhook %s: alert %s body of %d bytes cut", self.shown, out.alert.id, len(data)
            )
            data = msgspec.json.encode(
                {
                    "id": out.alert.id,
                    "kind": out.alert.kind,
                    "state": out.alert.state,
                    "robot": self.sender.robot,
                }
            )
        return data

    def _encode_handover(self, h: Handover) -> bytes:
        if self.hook.format == "ntfy":
            data = handover.ntfy(h, self.sender, alertbodies.ntfy_topic(self.hook), self.tz)
        else:
            data = handover.generic(h, self.sender, self.tz)
        return msgspec.json.encode(data)

    async def _post(self, session: aiohttp.ClientSession, data: bytes, what: str) -> None:
        import aiohttp

        delay = self.cfg.webhook_backoff
        for attempt in range(1, self.cfg.webhook_attempts + 1):
            try:
                async with session.post(
                    self.url,
                    data=data,
                    allow_redirects=False,
                    headers={"Content-Type": "application/json"},
                ) as response:
                    await response.content.read(ANSWER_MAX)  # at most; the rest is dropped
                    if response.status < 300:
                        self.stats.posted += 1
                        return
                    if response.status < 500:
                        self.stats.failed += 1
                        log.warning(
                            "webhook %s refused %s: HTTP %d%s",
                            self.shown,
                            what,
                            response.status,
                            " (redirects are not followed)" if response.status < 400 else "",
                        )
                        return
                    why = f"HTTP {response.status}"
            except (aiohttp.ClientError, TimeoutError, OSError, ValueError) as exc:
                why = self._why(exc)
            if attempt == self.cfg.webhook_attempts:
                break
            self.stats.retried += 1
            log.info(
                "webhook %s: %s; try %d of %d in %.1f s",
                self.shown,
                why,
                attempt + 1,
                self.cfg.webhook_attempts,
                delay,
            )
            await asyncio.sleep(delay)
            delay *= 2
        self.stats.failed += 1
        log.warning(
            "webhook %s: %s not delivered after %d tries (%s)",
            self.shown,
            what,
            self.cfg.webhook_attempts,
            why,
        )

    def _why(self, exc: BaseException) -> str:
        text = str(exc)
        for url in {self.hook.url, self.url}:
            text = text.replace(url, self.shown)
        parts = urlsplit(self.hook.url)
        for part in (parts.username, parts.password, parts.query, parts.path):
            if part and len(part) > 1:
                text = text.replace(part, "…")
        return f"{type(exc).__name__}: {text}"[:160]


class Webhooks:
    """Posts alert changes to ``cfg.webhooks``, one task per destination; start it inside
    the event loop. ``ack_secret``: the console's token, from which the key of the
    acknowledgement links is derived (None: no links). ``wall``: the wall clock
    (epoch seconds) the receivers' times and the links' expiry are on."""

    def __init__(
        self,
        cfg: AlertsCfg,
        robot: str | None = None,
        *,
        ack_secret: str | None = None,
        wall: Callable[[], float] = time.time,
        language: str = "en",
        tz: tzinfo = SITE_TZ,
    ) -> None:
        self.cfg = cfg
        self.robot = robot or cfg.robot
        self.stats = WebhookStats()
        self.wall = wall
        self._key = link_key(ack_secret) if ack_secret and cfg.console_url else None
        self._started: dict[str, float] = {}  # alert id -> wall time it was raised
        sender = Sender(self.robot, cfg.console_url, language)
        # a plain URL is validated here too: ``model_copy(update=...)`` does not validate
        hooks = [Webhook.model_validate(h) for h in cfg.webhooks]
        self.destinations = [Destination(hook, cfg, sender, self.stats, wall, tz) for hook in hooks]

    def start(self) -> None:
        loop = asyncio.get_running_loop()
        for d in self.destinations:
            if d.task is None:
                d.task = loop.create_task(d.run(), name=f"webhook {d.shown}")

    def attach(self, host: Host) -> None:
        """An observer of the executive: it hears every alert change."""

    def on_event(self, event: Event) -> None:
        if isinstance(event, AlertChanged):
            self.notify(event.t, event.alert)

    def notify(self, _now: float, alert: Alert) -> None:
        """Queue one alert change for every destination (O(destinations), no I/O)."""
        if not self.destinations:
            return
        at = self.wall()
        if alert.state == "raised" and alert.repeat == 0:
            self._started[alert.id] = at
        started = self._started.get(alert.id, at)
        if alert.state == "cleared":
            self._started.pop(alert.id, None)
        out = Outgoing(alert, at, started, self.link(alert, at))
        for d in self.destinations:
            d.put(out)

    def hand_over(self, h: Handover) -> None:
        """Queue a shift's handover for every destination that shows one to people (the
        generic JSON and ntfy; no I/O)."""
        for d in self.destinations:
            if d.hook.format in HANDOVER_FORMATS:
                d.put(h)

    def link(self, alert: Alert, at: float) -> str:
        """The signed link acknowledging this raise of ``alert`` on this robot ("" without
        a console URL or a token, or once it is acknowledged)."""
        if self._key is None or alert.state == "acknowledged":
            return ""
        exp = int(at + self.cfg.ack_link_ttl)
        return ack_link(
            self.cfg.console_url, self._key, self.robot, alert.id, alert.occurrence, exp
        )

    @property
    def pending(self) -> int:
        return sum(len(d.queue) for d in self.destinations)

    def close(self) -> None:
        """As an observer: nothing to finish here (the sending tasks end in :meth:`finish`,
        which the command that started them awaits)."""

    async def finish(self, timeout: float = 1.0) -> None:
        """Give what is queued up to ``timeout`` seconds, then stop."""
        tasks = [d.task for d in self.destinations if d.task is not None]
        for d in self.destinations:
            d.task = None
        if not tasks:
            return
        with contextlib.suppress(TimeoutError):
            async with asyncio.timeout(timeout):
                while any(not d.idle for d in self.destinations) and not all(
                    t.done() for t in tasks
                ):
                    await asyncio.sleep(0.05)
        for task in tasks:
            task.cancel()
        for task in tasks:
            with contextlib.suppress(asyncio.CancelledError):
                await task
