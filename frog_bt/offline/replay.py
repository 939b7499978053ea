"""Re-run the tree offline on a recording's inputs, on the recording's clock.

:class:`Replay` reads an MCAP recording (:mod:`frog_bt.live.recording`) in log-time
order and feeds a fresh :class:`~frog_bt.engine.core.Core` on a
:class:`~frog_bt.clock.ManualClock` that takes the recorded times. The recording is read
through the one decoder of recordings (:class:`~frog_bt.recordings.reader.Reader`), which
gives back the executive's events: each :class:`~frog_bt.model.events.RobotInput` goes to
``Core.on_ros``; each :class:`~frog_bt.model.events.FrontendIn` (the reader takes the
``/frontend/in`` datagrams through the front-end protocol's
:class:`~frog_bt.frontend.protocol.Endpoint`, so duplicates are suppressed exactly as
live) to ``Core.on_event``; ``/clock`` moves the clock (under sim time what arrived
before the first ``/clock`` is fed with the clock not yet ready, as live). A message
that does not decode (a damaged robot input, command, datagram or one of our own) is
counted and reported in :attr:`ReplayResult.bad`, never dropped silently; live, the
executive did not act on it either.

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
from frog_bt.config import Site
from frog_bt.engine.belief import Judgement
from frog_bt.engine.core import Core
from frog_bt.engine.operator import Command as OperatorCommand
from frog_bt.model import keys
from frog_bt.model.alert import Alert
from frog_bt.model.channels import (
    ALERT,
    FRONTEND_IN,
    FRONTEND_OUT,
    LINKS,
    OPERATOR,
    TICK,
    Restored,
    from_ns,
)
from frog_bt.model.events import (
    AlertChanged,
    Blamed,
    Datagram,
    Doubted,
    FrontendIn,
    FrontendOut,
    LinksChanged,
    OperatorDone,
    RobotCommand,
    RobotInput,
    Ticked,
)
from frog_bt.model.frontend import FrontendMessage, message_fields
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
from frog_bt.recordings.reader import Bad, Item, Primed, Reader
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
        self._expected: deque[Command] = deque()
        self._got: deque[Command] = deque()
        self._last_expected: Command | None = None
        # observers: ("recorded" | "replayed", command) and the divergence (the viewer)
        self.on_command: list[Callable[[str, Command], None]] = []
        self.on_divergence: list[Callable[[Divergence], None]] = []
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

    def _publish(self, topic: str, msg: dict[str, Any], urgent: bool = False) -> None:
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
        payload = _payload(message)
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
        for t, item in self.reader.read_all(self.files):  # a lead-in first, if any
            if parted and not isinstance(item, Blamed):
                break  # the blame of the diverging command, recorded after it, is read
            self._on_item(t, item)
            if parted:
                break
            result.covered = t
            if progress is not None:
                progress(t)
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

    def _on_item(self, t: float, item: Item) -> None:
        match item:
            case RobotInput(topic=CLOCK.name, value=value):
                if self.sim_time and isinstance(value, float):
                    self._advance(value)  # /clock: the time it carries
                return
            case Bad(channel=CLOCK.name):
                return  # live, a malformed /clock does not move the clock either
        if self.clock.ready or not self.sim_time:
            self._advance(t)
        match item:
            case RobotInput():
                self.result.inputs += 1
                if self.core.on_ros(item.topic, item.value) and not self.exact:
                    self._tick_now()
            case Datagram(direction="in"):
                self.result.inputs += 1  # a bad one too: live, the link acked it if it could
            case FrontendIn(message=message):
                self.core.on_event(message)  # new: the reader's endpoint, as the live link's
                if not self.exact:
                    self._tick_now()
            case FrontendOut(message=message):
                self.result.frontend_commands += 1
                self._expect(Command(t, FRONTEND_OUT, _payload(message)))
            case RobotCommand():
                self.result.ros_commands += 1
                self._expect(Command(t, item.topic, without_stamp(item.msg)))
            case Ticked():
                if self.exact:
                    self._tick()
            case Blamed():
                self._blame(item)
            case OperatorDone():
                self._operator(t, item)
            case Doubted(why=why):
                self.doubts["recorded"].append((t, why))
            case AlertChanged(alert=alert):
                self._expect_alert(t, alert)
            case LinksChanged(links=links):
                self._links(links)
            case Restored():
                self._restored(item)
            case Primed():
                self._prime(item)

    def _tick_now(self) -> None:
        """Without recorded ticks: the tick an input calls for, once the clock runs."""
        if self.clock.ready:
            self._tick()

    def _expect(self, command: Command) -> None:
        self._last_expected = command
        self._expected.append(command)
        self._compare()

    def _bad(self, topic: str, t: float, reason: str) -> None:
        self.reader.tally.add(Bad(t, topic, reason))

    def _prime(self, primed: Primed) -> None:
        """A recorded ``/frog_bt/primer``: what the live executive carried into this file
        from before it (:mod:`frog_bt.live.rotation`; its datagrams in and seqs out primed
        the reader: their resends are not new)."""
        for received in primed.inputs:  # (one that did not decode is a Bad item)
            inp = self.core.table.get(received.topic)
            if inp is not None:
                self.core.inputs.add(inp, received.value, received.t)
        primer = primed.primer
        if primer.frontend_ready:
            self.core.board.set(keys.FRONTEND_READY, True)
        if primer.staff is not None:  # beside the tree: decisions, the alert book
            self.staff.take_up(primer.staff)

    def _blame(self, blame: Blamed) -> None:
        """A recorded ``/frog_bt/blame``: the node that sent the command just recorded."""
        last = self._last_expected
        if last is None:
            return
        if blame.channel == last.channel or (
            last.channel == FRONTEND_OUT and last.payload.get("type") == blame.channel
        ):
            last.node = blame.node
            last.reads = dict(blame.reads)

    def _operator(self, t: float, recorded: OperatorDone) -> None:
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

    def _expect_alert(self, t: float, alert: Alert) -> None:
        """A recorded alert change: compared with the replayed alert book's, in order."""
        self.said.recorded(t, alert)
        if self._compared_alert(alert.kind):
            self.result.alerts += 1
            self._expected.append(alert_command(t, alert))
            self._compare()

    def _on_alert(self, t: float, alert: Alert) -> None:
        """A change of the replayed alert book: to the observers, and compared."""
        self.said.replayed(t, alert)
        if self.observers:
            self.observers.emit(AlertChanged(t, alert))
        if self._compared_alert(alert.kind):
            self._got.append(alert_command(t, alert))
            self._compare()

    def _links(self, recorded: Links) -> None:
        """A recorded change of the links' states, noted as the executive noted it."""
        self.recorded_links = recorded
        if self.clock.ready:
            self.staff.links_changed(self.clock.now())

    def _restored(self, recorded: Restored) -> None:
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


def _payload(message: FrontendMessage) -> dict[str, Any]:
    """A front-end command as replay compares it: its type and fields (``seq`` left out)."""
    payload: dict[str, Any] = plain({"type": message.type, **message_fields(message)})
    return payload
