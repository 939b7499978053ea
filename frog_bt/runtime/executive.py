"""The online executive: a :class:`~frog_bt.engine.core.Core` between the robot's link
and the front end's, ticked.

The executive is handed its two links ready-made (:class:`~frog_bt.rosbridge.link.RobotLink`:
the rosbridge client; :class:`~frog_bt.frontend.link.FrontendPort`: the UDP link): the
command that runs it builds them (``frog-bt run``, :mod:`frog_bt.rehearsal`), tests may hand
in links over memory (:mod:`frog_bt.rosbridge.memory`, :mod:`frog_bt.frontend.memory`). It
does not decide when a run ends, nor keep anything on disk: those are observers the
command attaches (:mod:`frog_bt.runtime.exits`, :mod:`frog_bt.runtime.keeper`), and the
command calls :meth:`Executive.stop`.

Ticks are event-driven — a tick follows any relevant input (a navigation
response, a docking state, a front-end event, detections, diagnostics, a link
change) — plus a periodic tick (``executive.tick_hz``, default 10 Hz) on the
project clock. Bursts of inputs coalesce into one tick. All I/O happens in the
links' own tasks; a tick only reads the snapshot and hands frames to
non-blocking sends.

With ``--sim-time`` nothing is timed before the first ``/clock``.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import py_trees

from frog_bt.clock import Clock, ManualClock
from frog_bt.config import Site
from frog_bt.engine.core import Core
from frog_bt.engine.standing import Standing
from frog_bt.frontend.link import FrontendPort
from frog_bt.model import keys
from frog_bt.model.channels import Alert, Restored
from frog_bt.model.events import AlertChanged, Datagram, Event, LinksChanged
from frog_bt.model.frontend import FrontendMessage
from frog_bt.model.links import Links, states
from frog_bt.model.outcomes import DockingState, IncidentKind, TourState
from frog_bt.model.wire import CLOCK, INPUTS, OUTPUTS
from frog_bt.rosbridge.link import LinkState, RobotLink
from frog_bt.runtime import background, logctx
from frog_bt.runtime.notify import Notifier
from frog_bt.runtime.observer import Observers
from frog_bt.runtime.resuming import ResumingLedger
from frog_bt.runtime.staff import Staff
from frog_bt.runtime.status import link_line, status_line
from frog_bt.tree.loader import LoadedTree

log = logging.getLogger(__name__)
Status = py_trees.common.Status
FRONTEND_DRAIN = 1.2  # wall seconds for the last commands' acks (of a 2 s shutdown budget)
ROSBRIDGE_FLUSH = 0.5  # wall seconds for the last frames to the robot (of the same budget)


@dataclass(slots=True)
class Outcome:
    """Why :meth:`Executive.run` returned: exit code and one-line reason (the first
    :meth:`Executive.stop`'s); ``tours``: completed, as the one count of tours has them
    (:attr:`Executive.ledger`, set by the exit rules: :class:`~frog_bt.runtime.exits.ExitRules`;
    0 without them)."""

    code: int = 0
    reason: str = ""
    tours: int = 0


class Executive:
    """The tree, ticked between ``client`` (the robot) and ``link`` (the front end)."""

    def __init__(
        self,
        site: Site,
        tree: LoadedTree,
        clock: Clock,
        client: RobotLink,
        link: FrontendPort,
        *,
        sim_time: bool = False,
    ) -> None:
        if sim_time and not isinstance(clock, ManualClock):
            raise ValueError("sim time needs a ManualClock (SimClock)")
        self.site = site
        self.clock = clock
        self.sim_time = sim_time
        self.outcome = Outcome()
        self.observers = Observers()  # every observer, told each event (on_event)
        self.observers.host_settles = True  # tick() tells them the tick's end itself
        self.ledger = ResumingLedger(site.tour_plan())  # the one count of tours, told first
        self.observers.attach(self, [self.ledger])
        self.client = client
        client.on_input, client.on_link = self._on_ros, self._on_link
        self.link = link
        link.on_message, link.on_datagram = self._on_event, self._on_datagram
        self.link_listeners: list[Callable[[LinkState], None]] = []  # each robot link change
        self.standing = Standing(clock)  # what outlives a tree: each core gets it
        self.core = self._core(site, tree)
        self._wake = asyncio.Event()
        self._stopping = asyncio.Event()
        self._pending_at_loss: object = None
        self._peer_restarts = 0
        self._swap: tuple[Site, LoadedTree] | None = None  # a checked tree, for the next idle
        self.was_connected = False  # to rosbridge, at some point: a loss is a reconnect
        self._link_states = states(self)
        self.swaps = 0
        self.staff = Staff(self)  # operator commands and alerts
        # what this executive took up from before it (a Keeper sets it): recorded
        self.restored: Restored | None = None
        self.staff.book.listeners.append(self._on_alert)
        self.notifier = Notifier.from_env()  # systemd: READY, STATUS, watchdog pings

    def _core(self, site: Site, tree: LoadedTree) -> Core:
        """A core for ``tree``, on this executive's links, observers and standing state."""
        return Core(
            site,
            tree,
            self.clock,
            self.client.publish,
            self.link.send,
            emit=self.observers,
            standing=self.standing,
            after_tick=self._after_tick,
            blame_first=False,  # the Blamed event reads it after the send
        )

    def _after_tick(self) -> None:
        """Inside each tick, before the observers hear it: the alerts checked."""
        self.staff.after_tick()

    def emit(self, event: Event) -> None:
        """Tell every observer."""
        self.observers.emit(event)

    # ------------------------------------------------------------ I/O callbacks (cache only)

    def _on_ros(self, topic: str, value: object, raw: Any) -> None:
        try:
            self._take_ros(topic, value, raw)
        except Exception as exc:
            self.core.faults.failed(f"input {topic}", exc, "its handling")

    def _take_ros(self, topic: str, value: object, raw: Any) -> None:
        if topic == CLOCK.name and self.sim_time:
            if isinstance(value, float):
                self.clock.set(value)  # type: ignore[attr-defined]
            self.core.on_ros(topic, None, raw)  # the observers hear it; the tree does not
            return
        if self.core.on_ros(topic, value, raw):
            self._wake.set()

    def _on_alert(self, t: float, alert: Alert) -> None:
        self.emit(AlertChanged(t, alert))

    def _on_link(self, state: LinkState) -> None:
        self.was_connected = self.was_connected or state.connected
        actions = self.core.actions
        if not state.connected:
            self._pending_at_loss = actions.pending
        elif (
            state.reconnects > 0
            and actions.pending is not None
            and actions.pending is self._pending_at_loss
        ):
            # A goal sent before the loss may have been answered while we could not hear:
            # send it again. One issued while down went out from the queue just now.
            actions.resend_pending()
            self.core.ctx.note(
                f"link back: re-sent {actions.pending.kind} to {actions.pending.target}"
            )
        self.check_links()
        for listener in self.link_listeners:
            listener(state)
        self._wake.set()

    def wake(self) -> None:
        """Tick soon (a queued operator command waits for the next tick)."""
        self._wake.set()

    @property
    def links(self) -> Links:
        """Each link's state as of the latest check."""
        return Links(*self._link_states)

    def check_links(self) -> None:
        """Compare the links' states with the last seen; tell the observers a change."""
        now_states = states(self)
        if now_states != self._link_states:
            self._link_states = now_states
            now = self.clock.now() if self.clock.ready else 0.0
            self.staff.links_changed(now)
            if self.observers:
                self.emit(LinksChanged(now, self.links))

    def _on_event(self, message: FrontendMessage) -> None:
        try:
            self.core.on_event(message)
        except Exception as exc:
            self.core.faults.failed(f"front-end event {message.type}", exc, "its handling")
        self._wake.set()

    def _on_datagram(self, direction: str, data: bytes, t: float) -> None:
        if self.observers:
            self.emit(Datagram(t, "in" if direction == "in" else "out", bytes(data)))

    # ------------------------------------------------------------ lifecycle

    def setup_wire(self) -> None:
        """Advertise every output and subscribe to every input of the wire table (sent
        once connected, and again after each reconnect)."""
        for role, topic in OUTPUTS.items():
            self.client.advertise(self.site.topic(role), topic.type)
        for role, topic in INPUTS.items():
            self.client.subscribe(self.site.topic(role), topic.type)
        if self.sim_time:
            self.client.subscribe(CLOCK.name, CLOCK.type)

    async def run(self) -> Outcome:
        """Connect, tick until :meth:`stop`, then halt cleanly and close the links."""
        logctx.mark(self)  # this task's log lines (and its tasks') are this executive's
        self.setup_wire()
        await self.link.start()
        self.client.start()
        self.notifier.ready(f"frog-bt: rosbridge {self.client.url}")
        try:
            if await self._until_stopped(self._ready_or_alive()):
                self.core.setup()
                await self._loop()
        finally:
            self.notifier.stopping()
            await self._shutdown()
            self.notifier.close()
        return self.outcome

    def _alive(self) -> float:
        """One turn of the loop: the watchdog's ping, the status line for systemd; how
        long the loop may wait before its next turn."""
        self.notifier.alive()
        self.notifier.status(lambda: self.status_text(countdown=False))
        return self.notifier.ping_every or 1.0

    async def _ready_or_alive(self) -> None:
        """Wait for the clock (under sim time, the first /clock), pinging meanwhile."""
        while not self.clock.ready:
            wait = self._alive()
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(wait):  # not wait_for: 3.11 may swallow a cancel
                    await self.clock.wait_ready()

    def status_text(self, countdown: bool = True) -> str:
        """The live status: the rosbridge link while it keeps the tree waiting, else the tree;
        then the alerts not yet acknowledged (``countdown``: a terminal's, see link_line)."""
        line = (
            link_line(self.client.url, self.client.link, self.clock.ready, countdown=countdown)
            or f"{status_line(self.core, self.ledger)} | {self.links.text()}"
        )
        alerts = [a.kind for a in self.staff.book.shown() if a.state == "raised"]
        return line + (f" | ALERT: {', '.join(alerts)}" if alerts else "")

    async def _until_stopped(self, awaitable: Any) -> bool:
        """Await ``awaitable`` unless stop() comes first; True when it completed."""
        task = asyncio.ensure_future(awaitable)
        stop = asyncio.ensure_future(self._stopping.wait())
        await asyncio.wait({task, stop}, return_when=asyncio.FIRST_COMPLETED)
        task.cancel()
        stop.cancel()
        return not self._stopping.is_set()

    def stop(self, reason: str = "", code: int = 0) -> None:
        """End :meth:`run` (after the tick under way): the first stop's ``code`` and
        ``reason`` are the outcome's."""
        if not self._stopping.is_set():
            self.outcome.code, self.outcome.reason = code, reason
        self._stopping.set()
        self._wake.set()

    async def _loop(self) -> None:
        periodic = asyncio.create_task(self._periodic())
        try:
            while not self._stopping.is_set():
                wait = self._alive()  # from the loop itself: a wedged loop stops the pings
                try:  # (a timeout, not wait_for: no extra task between a wake and its tick)
                    async with asyncio.timeout(wait):
                        await self._wake.wait()
                except TimeoutError:
                    continue
                self._wake.clear()
                if not self._stopping.is_set():
                    try:
                        self.tick()
                    except Exception as exc:
                        self.core.faults.failed("the executive", exc, "a tick")
                    # the observers heard the tick's end in tick(); an exit rule that stops
                    # the run stops it before another tick. Let the loop's callbacks run.
                    await asyncio.sleep(0)
        finally:
            periodic.cancel()

    async def _periodic(self) -> None:
        period = 1.0 / self.site.executive.tick_hz
        next_at = self.clock.now()
        while True:
            next_at = max(next_at + period, self.clock.now())
            await self.clock.sleep_until(next_at)
            self._wake.set()

    # ------------------------------------------------------------ hot reload

    def offer(self, site: Site, tree: LoadedTree) -> None:
        """A checked tree (and site) to swap in at the next safe point: docked, no tour
        running. A later offer replaces an earlier one not yet swapped in."""
        if site.links != self.site.links or site.topics != self.site.topics:
            log.warning("tree change refused: links and topics take a restart")
            return
        self._swap = (site, tree)
        log.info("tree change checked; it takes over when the robot is docked and idle")

    def idle(self) -> bool:
        """Docked, and no tour running: a safe point to swap the tree."""
        docking = self.core.inputs.latest.get(INPUTS["docking_state"].key)
        return (
            self.core.board.get(keys.TOUR_STATE) is not TourState.STARTED
            and docking is not None
            and docking.value == DockingState.DOCKED
        )

    def _swap_tree(self) -> None:
        assert self._swap is not None
        site, tree = self._swap
        self._swap = None
        self.core.halt()
        core = self.core = self._core(site, tree)  # same observers and standing state
        core.setup()
        self.site, self.swaps = site, self.swaps + 1
        nodes = sum(1 for _ in tree.nodes())
        log.warning("tree reloaded at an idle point: %s (%d nodes)", tree.file, nodes)
        core.ctx.note(f"tree reloaded: {tree.file}")

    def tick(self) -> Status:
        """One tick of the tree, after what must happen between two ticks; its status.
        (Observers hear it as :class:`~frog_bt.model.events.Ticked`: the exit rules, the
        keeper of the checkpoint, the recorder.)"""
        self._between_ticks()
        self.client.hold()  # the tick's commands to the robot in one write (a goal: at once)
        try:
            return self.core.tick()  # the staff check the alerts at its end (_after_tick)
        finally:
            self.client.release()
            self.observers.settle()  # they hear the tick's end now its commands are out
            background.hold()  # the answers to its commands go before telemetry's work

    def _between_ticks(self) -> None:
        """The links' states, a checked tree swapped in at an idle point, a restart of the
        front end noted, the staff's queued commands applied."""
        self.check_links()
        if self._swap is not None and self.idle():
            self._swap_tree()
        restarts = self.link.stats.peer_restarts
        if restarts != self._peer_restarts:
            self._peer_restarts = restarts
            self.core.ctx.note("front end restarted", incident=IncidentKind.FRONTEND_RESTARTED)
        self.staff.before_tick()

    async def _shutdown(self) -> None:
        """Halt the tree (scopes switch the face stream off, ...) and flush the links."""
        self.core.halt()
        # The last front-end commands (tour ended, projector off, finish_poi) are resent
        # until acked, within the shutdown budget. First: on sim time the resends need
        # /clock, which stops with the unsubscriptions below.
        await self.link.drain(FRONTEND_DRAIN)
        # Leave the robot's rosbridge tidy: the last commands out, then unsubscribe and
        # unadvertise (only sent while connected; nothing is queued for later).
        self.client.leave()
        await self.client.flush(ROSBRIDGE_FLUSH)
        await self.client.close()
        self.link.close()
        await self.link.wait_closed()
