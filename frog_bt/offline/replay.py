"""Re-run the tree offline on a recording's inputs, on the recording's clock.

:class:`Replay` reads an MCAP recording (:mod:`frog_bt.live.recording`) in log-time
order and feeds a fresh :class:`~frog_bt.engine.core.Core` on a
:class:`~frog_bt.clock.ManualClock` that takes the recorded times: ROS inputs
go through :data:`~frog_bt.model.ros.ROS_TYPES` (by the channel's schema name) to
``Core.on_ros``; ``/frontend/in`` datagrams go through a fresh
:class:`~frog_bt.frontend.protocol.Endpoint`, so duplicates are suppressed exactly
as live, to ``Core.on_event``; ``/clock`` moves the clock (under sim time what
arrived before the first ``/clock`` is fed with the clock not yet ready, as live).

The recording is read through the one decoder of recordings
(:class:`~frog_bt.recordings.reader.Reader`): a message that does not decode (a damaged
robot input, command, datagram or one of our own) is counted and reported in
:attr:`ReplayResult.bad`, never dropped silently; live, the executive did not act on it
either.

Ticks: a recording made by :class:`~frog_bt.live.recording.Recorder` has the live
ticks (``/frog_bt/tick``), and replay ticks exactly there, in the same place
among the inputs. Live ticks coalesce bursts of inputs and land wherever the
event loop gets to them, so no rule can recompute them; with the recorded ones,
replaying the same tree is exact. A recording without ticks is replayed by the
live rules instead (periodic ticks at ``executive.tick_hz`` on the clock, and a
tick after each input that calls for one and after each front-end event), which
is close but not guaranteed identical.

What the executive held beside the tree is rebuilt with the executive's own code: a
:class:`~frog_bt.runtime.staff.Staff` with its alert book. Each recorded operator command
(``/frog_bt/operator``: from the console, ``frog-bt ctl`` or an acknowledgement link) is
applied again through :meth:`Staff.apply <frog_bt.runtime.staff.Staff.apply>` before the
same tick (``ack_alert`` to the alert book, the others to the tree); after each tick the
alert conditions are checked as live; the links' states come from ``/frog_bt/links`` and
what a restarted executive took up from before it (its checkpoint's resume point, the
staff's decisions, the help it waited for) from ``/frog_bt/restored``.

The commands the replayed tree sends are compared, in order, with the recorded
ones: ROS outputs (``header.stamp`` left out), new front-end commands
(``/frontend/out`` without acks and resends; ``seq`` left out), the answer to each
operator command and each alert raised, told again, cleared or acknowledged (its id,
state and repeat; its words are the site's, not compared). The first difference is a
:class:`Divergence`, with a sentence in domain terms when it is about an alert or a
command's answer. With a changed tree or configuration this answers "what would the
robot have done": until the first divergence the recorded inputs are exactly what the
new tree would have seen.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from frog_bt.clock import ManualClock
from frog_bt.config import Site, parse_hostport
from frog_bt.engine.belief import Judgement
from frog_bt.engine.core import Core
from frog_bt.engine.operator import Command as OperatorCommand
from frog_bt.frontend.protocol import Endpoint
from frog_bt.model import channels, keys
from frog_bt.model.channels import (
    ALERT,
    BLAME,
    FRONTEND_IN,
    FRONTEND_OUT,
    LINKS,
    OPERATOR,
    TICK,
    from_ns,
)
from frog_bt.model.events import AlertChanged
from frog_bt.model.frontend import EVENTS, FrontendMessage, message_fields
from frog_bt.model.goals import Goal
from frog_bt.model.links import Links
from frog_bt.model.wire import CLOCK, OUTPUTS
from frog_bt.offline.beside import STAFF, Beside, Said, alert_command
from frog_bt.recordings.commands import (
    Command,
    ReplayError,
    chain,
    plain,
    without_stamp,
)
from frog_bt.recordings.mcapfile import RecordingError
from frog_bt.recordings.reader import (
    CLOCK_ROLE,
    Bad,
    FrontendAck,
    FrontendIn,
    FrontendOut,
    Own,
    Primed,
    Reader,
    Record,
    RobotCommand,
    RobotInput,
)
from frog_bt.runtime import decisions
from frog_bt.runtime.observer import Observers
from frog_bt.runtime.staff import Staff
from frog_bt.tree.loader import LoadedTree

# alerts about the links: without /frog_bt/links (older recordings) replay cannot tell them
LINK_ALERTS = frozenset({"rosbridge_down", "frontend_silent"})


@dataclass(frozen=True, slots=True)
class Divergence:
    """The first command that differs: its number (from 1), the recorded one, the replayed
    one; ``story``: what happened on each side in domain terms, when it is about an alert
    or the answer to an operator command (empty otherwise)."""

    number: int
    expected: Command | None
    got: Command | None
    story: str = ""
    # robot answers one side did not believe and the other did, since the last command
    # both sent alike: ("recorded" | "replayed", why), in domain terms
    doubts: list[tuple[str, str]] = field(default_factory=list)

    @property
    def t(self) -> float:
        """When the runs parted: the earlier of the two commands."""
        return min(c.t for c in (self.expected, self.got) if c is not None)


@dataclass(slots=True)
class ReplayResult:
    start: float  # first and last recorded times
    end: float
    covered: float  # last recorded time replayed
    inputs: int = 0  # ROS messages and front-end datagrams fed in
    ticks: int = 0
    ros_commands: int = 0  # recorded commands, compared
    frontend_commands: int = 0
    exact: bool = True  # ticks taken from the recording
    divergence: Divergence | None = None
    wall: float = 0.0  # seconds the replay took
    recovered: list[str] = field(default_factory=list)  # files cut short, what was read
    bad: list[str] = field(default_factory=list)  # messages that did not decode: where, why
    bad_count: int = 0  # all of them (``bad`` keeps the first few)
    operator_commands: int = 0  # recorded operator commands, applied again
    alerts: int = 0  # recorded alert changes, compared

    @property
    def identical(self) -> bool:
        return self.divergence is None


class Replay:
    """One replay of ``path`` with ``site`` and ``tree``; see the module docstring.

    Raises :class:`ReplayError` when the file is no frog-bt recording. A replay is an
    :class:`~frog_bt.runtime.observer.Host` without raw traffic or links: attach observers
    (telemetry) to it before :meth:`run`.
    """

    links: Links | None = None  # no links (and no raw traffic) in a replay

    def __init__(self, path: Path, site: Site, tree: LoadedTree) -> None:
        self.path = Path(path)
        self.site = site
        self._peer = parse_hostport(site.links.frontend, "links.frontend")[0]
        try:
            self.files = chain(self.path)
        except RecordingError as exc:
            raise ReplayError(str(exc)) from None
        self.types = {topic: type_ for f in self.files for topic, type_ in f.types.items()}
        self.recovered = [f"{f.path.name}: {f.recovered}" for f in self.files if f.recovered]
        self.outputs = {site.topic(role) for role in OUTPUTS}
        missing = sorted({FRONTEND_IN, FRONTEND_OUT, *self.outputs} - set(self.types))
        if missing:
            raise ReplayError(
                f"{self.path}: not a frog-bt recording for this configuration: "
                f"no channel {', '.join(missing)}"
            )
        self.start = from_ns(self.files[0].start)
        self.end = from_ns(self.files[-1].end)
        self.sim_time = CLOCK.name in self.types
        self.exact = TICK in self.types
        self.period = 1.0 / site.executive.tick_hz
        self.clock = ManualClock(None)
        self.observers = Observers()  # attach with attach_all(replay, [...]) before run()
        self.core = Core(
            site,
            tree,
            self.clock,
            self._publish,
            self._send,
            emit=self.observers,
            after_tick=self._after_tick,  # the alerts checked, as the executive does
        )
        # beside the tree, as the executive: the staff and its alert book, on the recorded
        # links' states (None until the recording tells them)
        self.recorded_links: Links | None = None
        self.staff = Staff(Beside(self))
        self.staff.book.listeners.append(self._on_alert)
        self.staff.book.logged = False  # the live log said it; a replay's output is its report
        self._alerts_compared = ALERT in self.types  # (older recordings have none)
        self._links_known = LINKS in self.types
        self.said = Said()  # each alert's latest change on each side, for the story
        self.reader = Reader(site)  # the one decoder; its tally counts the bad messages
        self.endpoint = Endpoint(self._peer, EVENTS)  # the same dedup as the live link
        self._expected: deque[Command] = deque()
        self._got: deque[Command] = deque()
        self._last_expected: Command | None = None
        # observers: ("recorded" | "replayed", command) and the divergence (the viewer)
        self.on_command: list[Callable[[str, Command], None]] = []
        self.on_divergence: list[Callable[[Divergence], None]] = []
        self._seqs: set[int] = set()
        # answers not believed, each side: (when, why); the replayed ones from the core
        self.doubts: dict[str, list[tuple[float, str]]] = {"recorded": [], "replayed": []}
        self._agreed_at = self.start  # when the last command both sides sent alike was sent
        self._judge = self.core.actions.on_doubt
        self.core.actions.on_doubt = self._replayed_doubt
        self._compared = 0
        self._next_tick = 0.0
        self.result = ReplayResult(
            self.start, self.end, self.start, exact=self.exact, recovered=self.recovered
        )

    # ------------------------------------------------------------ outputs of the replayed tree

    def _publish(self, topic: str, msg: dict[str, Any]) -> None:
        self._got.append(
            Command(
                self.clock.now(),
                topic,
                without_stamp(plain(msg)),
                self.core.blamed,
                self.core.blamed_reads,
            )
        )
        self._compare()

    def _send(self, message: FrontendMessage) -> None:
        payload = plain({"type": message.type, **message_fields(message)})
        self._got.append(
            Command(
                self.clock.now(), FRONTEND_OUT, payload, self.core.blamed, self.core.blamed_reads
            )
        )
        self._compare()

    def _compare(self) -> None:
        while self._expected and self._got and self.result.divergence is None:
            expected, got = self._expected.popleft(), self._got.popleft()
            self._compared += 1
            for observe in self.on_command:
                observe("recorded", expected)
                observe("replayed", got)
            if (expected.channel, expected.payload) != (got.channel, got.payload):
                self._diverged(Divergence(self._compared, expected, got))
            else:
                self._agreed_at = max(expected.t, got.t)

    def _diverged(self, divergence: Divergence) -> None:
        story = self.said.story(divergence.expected, divergence.got)
        divergence = replace(divergence, story=story, doubts=self._doubts_apart())
        self.result.divergence = divergence
        for seen in self.on_divergence:
            seen(divergence)

    def _replayed_doubt(self, code: int, goal: Goal, judgement: Judgement) -> None:
        self.doubts["replayed"].append((self.clock.now(), judgement.why))
        if self._judge is not None:
            self._judge(code, goal, judgement)

    def _doubts_apart(self) -> list[tuple[str, str]]:
        """The answers one side did not believe and the other did, since both last agreed:
        what a divergence about a stale or doubted answer names."""
        since = {
            side: [why for t, why in seen if t >= self._agreed_at]
            for side, seen in self.doubts.items()
        }
        return [
            (side, why)
            for side, other in (("recorded", "replayed"), ("replayed", "recorded"))
            for why in since[side]
            if why not in since[other]
        ]

    # ------------------------------------------------------------ the run

    def run(self, progress: Callable[[float], None] | None = None) -> ReplayResult:
        """Replay to the end, or to the first divergence; the result says which."""
        wall0 = time.monotonic()
        result = self.result
        parted = False
        for record in self.reader.read_all(self.files):  # a lead-in first, if any
            if parted and not (isinstance(record, Own) and record.channel == BLAME):
                break  # the blame of the diverging command, recorded after it, is read
            self._on_record(record)
            if parted:
                break
            result.covered = record.t
            if progress is not None:
                progress(record.t)
            parted = result.divergence is not None
        else:
            if not self.recovered:  # cut short: the live run neither halted nor sent more
                self.core.halt()  # as the executive does when it stops (face stream off, ...)
                if result.divergence is None and (self._expected or self._got):
                    expected = self._expected.popleft() if self._expected else None
                    got = self._got.popleft() if self._got else None
                    self._diverged(Divergence(self._compared + 1, expected, got))
        result.ticks = self.core.ticks
        result.bad_count = self.reader.tally.count
        result.bad = self.reader.tally.lines(self.start)
        result.wall = time.monotonic() - wall0
        return result

    def _on_record(self, record: Record) -> None:
        if isinstance(record, RobotInput) and record.role == CLOCK_ROLE:
            if self.sim_time and isinstance(record.value, float):
                self._advance(record.value)  # /clock: the time it carries
            return
        if isinstance(record, Bad) and record.channel == CLOCK.name:
            return  # live, a malformed /clock does not move the clock either
        if self.clock.ready or not self.sim_time:
            self._advance(record.t)
        if isinstance(record, RobotInput):
            self._on_ros(record)
        elif (datagram := _datagram_in(record)) is not None:
            self._on_datagram(datagram)  # a bad one too: live, the link acked it if it could
        elif isinstance(record, FrontendOut):
            self._expect_datagram(record)
        elif isinstance(record, RobotCommand):
            self.result.ros_commands += 1
            self._expect(Command(record.t, record.topic, without_stamp(record.msg)))
        elif isinstance(record, Own):
            self._on_own(record)
        elif isinstance(record, Primed):
            self._prime(record)

    def _on_own(self, record: Own) -> None:
        message = record.message
        if isinstance(message, channels.Tick):
            if self.exact:
                self._tick()
        elif isinstance(message, channels.Blame):
            self._blame(message)
        elif isinstance(message, channels.Operator):
            self._operator(record.t, message)
        elif isinstance(message, channels.Doubt):
            self.doubts["recorded"].append((record.t, message.why))
        elif isinstance(message, channels.Alert):
            self._expect_alert(record.t, message)
        elif isinstance(message, channels.Links):
            self._links(message)
        elif isinstance(message, channels.Restored):
            self._restored(message)

    def _on_ros(self, record: RobotInput) -> None:
        self.result.inputs += 1
        if self.core.on_ros(record.topic, record.value) and not self.exact and self.clock.ready:
            self._tick()

    def _on_datagram(self, data: bytes) -> None:
        """A datagram in, through the live link's own protocol (its duplicates and
        restarts are the executive's to tell, as live)."""
        self.result.inputs += 1
        received = self.endpoint.receive(data, self._peer, self.clock.now())
        if received.message is not None:
            self.core.on_event(received.message)
            if not self.exact and self.clock.ready:
                self._tick()

    def _expect_datagram(self, record: FrontendOut) -> None:
        if record.seq in self._seqs:
            return  # a resend
        self._seqs.add(record.seq)
        self.result.frontend_commands += 1
        message = record.message
        self._expect(
            Command(
                record.t, FRONTEND_OUT, plain({"type": message.type, **message_fields(message)})
            )
        )

    def _expect(self, command: Command) -> None:
        self._last_expected = command
        self._expected.append(command)
        self._compare()

    def _bad(self, topic: str, t: float, reason: str) -> None:
        self.reader.tally.add(Bad(t, topic, reason))

    def _prime(self, primed: Primed) -> None:
        """A recorded ``/frog_bt/primer``: what the live executive carried into this file
        from before it (:mod:`frog_bt.live.rotation`)."""
        for received in primed.inputs:  # (one that did not decode is a Bad record)
            inp = self.core.table.get(received.topic)
            if inp is not None:
                self.core.inputs.add(inp, received.value, received.t)
        primer = primed.primer
        if primer.frontend_ready:
            self.core.board.set(keys.FRONTEND_READY, True)
        for raw in primer.frontend_in:  # seen live: their resends are duplicates
            self.endpoint.receive(raw.encode(), self._peer, self.clock.now())
        self._seqs.update(primer.frontend_out_seqs)
        if primer.staff is not None:  # beside the tree: decisions, the alert book
            self.staff.take_up(primer.staff)

    def _blame(self, blame: channels.Blame) -> None:
        """A recorded ``/frog_bt/blame``: the node that sent the command just recorded."""
        last = self._last_expected
        if last is None:
            return
        if blame.channel == last.channel or (
            last.channel == FRONTEND_OUT and last.payload.get("type") == blame.channel
        ):
            last.node = blame.node
            last.reads = dict(blame.reads)

    def _operator(self, t: float, recorded: channels.Operator) -> None:
        """A recorded operator command: applied again here, between the same two ticks, as
        the executive applied it (``ack_alert`` to the alert book, the others to the
        tree); a different answer is a divergence like a different command."""
        try:
            command = OperatorCommand(recorded.command)
        except ValueError:
            self._bad(OPERATOR, t, f"unknown command {recorded.command!r}")
            return
        self.result.operator_commands += 1
        answer = self.staff.apply(command, recorded.id, recorded.by)
        about = {"id": recorded.id} if recorded.id else {}
        self._last_expected = Command(
            t,
            OPERATOR,
            {"command": recorded.command, **about, "ok": recorded.ok, "did": recorded.text},
            node=STAFF,
        )
        self._expected.append(self._last_expected)
        self._got.append(
            Command(
                self.clock.now(),
                OPERATOR,
                {"command": command.value, **about, "ok": answer.ok, "did": answer.text},
                node=STAFF,
            )
        )
        self._compare()

    # ------------------------------------------------------------ beside the tree

    def _compared_alert(self, kind: str) -> bool:
        return self._alerts_compared and (self._links_known or kind not in LINK_ALERTS)

    def _expect_alert(self, t: float, alert: channels.Alert) -> None:
        """A recorded alert change: compared with the replayed alert book's, in order."""
        self.said.recorded(t, alert)
        if self._compared_alert(alert.kind):
            self.result.alerts += 1
            self._expected.append(alert_command(t, alert))
            self._compare()

    def _on_alert(self, t: float, alert: channels.Alert) -> None:
        """A change of the replayed alert book: to the observers, and compared."""
        self.said.replayed(t, alert)
        if self.observers:
            self.observers.emit(AlertChanged(t, alert))
        if self._compared_alert(alert.kind):
            self._got.append(alert_command(t, alert))
            self._compare()

    def _links(self, recorded: channels.Links) -> None:
        """A recorded change of the links' states, noted as the executive noted it."""
        self.recorded_links = Links(recorded.rosbridge, recorded.frontend, recorded.clock)
        if self.clock.ready:
            self.staff.links_changed(self.clock.now())

    def _restored(self, recorded: channels.Restored) -> None:
        """What the recorded executive took up at start-up (a restart): its checkpoint's
        resume point and the staff's decisions, taken up here before the first tick."""
        resume, decided = decisions.taken_up(recorded)
        self.core.board.set(keys.RESUME, resume)
        self.staff.restore(decided)

    # ------------------------------------------------------------ time and ticks

    def _advance(self, t: float) -> None:
        """Move the clock to ``t``; without recorded ticks, tick as the live loop would."""
        clock = self.clock
        if not clock.ready:
            clock.set(t)
            self.core.setup()
            if not self.exact:  # the link came up before the clock: the loop ticks at once
                self._next_tick = clock.now() + self.period
                self._tick()
            return
        if self.exact or t < self._next_tick:
            clock.set(t)
            return
        if self.sim_time:  # the clock jumps: one periodic tick at the new time
            clock.set(t)
            self._periodic(t)
            self._tick()
            return
        while self._next_tick <= t:  # wall-clock recording: ticks at their deadlines
            clock.set(self._next_tick)
            self._periodic(self._next_tick)
            self._tick()
        clock.set(t)

    def _periodic(self, now: float) -> None:
        """The live periodic task's next deadline after waking at ``now``."""
        while self._next_tick <= now:
            self._next_tick = max(self._next_tick + self.period, now)
            if self._next_tick <= now:
                self._next_tick = now + self.period

    def _tick(self) -> None:
        if self.result.divergence is None:
            self.core.tick()

    def _after_tick(self) -> None:
        self.staff.after_tick()


def _datagram_in(record: Record) -> bytes | None:
    """The datagram from the front end a record is (an event, an ack, or one that did not
    decode); None for any other record."""
    if isinstance(record, FrontendIn) or (
        isinstance(record, FrontendAck) and record.direction == "in"
    ):
        return record.raw
    if isinstance(record, Bad) and record.channel == FRONTEND_IN:
        return record.raw
    return None
