"""What the robot is doing, as one plain sentence for staff ("Driving to the Hunting
Courtyard"), from the tree's running path and a few board values. Sans-I/O: nodes in,
a :class:`~frog_bt.i18n.Msg` out; no tree, no clock, no sockets.

The deepest node on the running path that says something wins: the leaf at work
(``Navigate``, ``PlayContent``, ``SeekVisitor``...), else the scope around it. The tree's
own path stays available to the robot team behind the page's *details* control.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from frog_bt.engine.walk import running_path
from frog_bt.i18n import Msg
from frog_bt.model import keys

if TYPE_CHECKING:
    from frog_bt.engine.core import Core


@dataclass(frozen=True, slots=True)
class Step:
    """One node of the running path: its type and the parameters a sentence needs."""

    kind: str  # the leaf or composite type: Navigate, PlayContent, Docking, ...
    poi: str | None = None  # Navigate, PlayContent, ...: the POI or variant
    action: str | None = None  # Docking: dock or undock
    event: str | None = None  # WaitEvent: the front-end event waited for


@dataclass(frozen=True, slots=True)
class Situation:
    """What the sentence also depends on (board values and the site)."""

    paused: bool = False
    in_service: bool = True
    needs_help: bool = False
    going_home: bool = False  # the tour is ending: home, low battery, a fault
    dock: str = "SHOP"
    recruit_at: str = "POI0"


def of(node: object) -> Step:
    """A :class:`Step` from a tree node (its type name and ``params``, when it has them)."""
    params = getattr(node, "params", None)
    return Step(
        type(node).__name__,
        getattr(params, "poi", None),
        getattr(params, "action", None),
        getattr(params, "event", None),
    )


def phrase(path: Sequence[Step], now: Situation, names: Callable[[str], str] = str) -> Msg:
    """The plain sentence for the running ``path`` (root first)."""
    if now.needs_help:
        return Msg("Waiting for a person to help")
    if now.paused:
        return Msg("Paused by staff")
    for step in reversed(path):
        said = _say(step, now, names)
        if said is not None:
            return said
    if not now.in_service:
        return Msg("Out of service, on its charger")
    return Msg("Waiting for the next tour")


def _say(step: Step, now: Situation, names: Callable[[str], str]) -> Msg | None:
    kind, poi = step.kind, step.poi
    if kind == "AskForHelp":
        return Msg("Waiting for a person to help")
    if kind == "Docking":
        return Msg("Leaving the charger") if step.action == "undock" else Msg("Docking")
    if kind in ("Navigate", "GuidedDrive") and poi is not None:
        if poi == now.dock or now.going_home:
            return Msg("Driving back to the charger")
        return Msg("Driving to {stop}", stop=names(poi))
    if kind == "PlayContent" and poi is not None:
        return Msg("Playing the {stop} story", stop=names(poi))
    if kind == "SeekVisitor":
        return Msg("Looking for a visitor")
    if kind == "ApproachVisitor":
        return Msg("Going up to a visitor")
    if kind in ("StartIntroduction", "AskTour", "WaitAnswer"):
        return Msg("Introducing itself to a visitor")
    if kind == "WaitFrontendIdle":
        return Msg("Waiting for the next tour")
    if kind == "WaitInService":
        return Msg("Out of service, on its charger")
    if kind == "VisitorFollows":
        return Msg("Checking that the visitor follows")
    if kind == "WaitEvent" and step.event == "finish_introduction":
        return Msg("Introducing itself to a visitor")
    return None


def doing(core: Core) -> Msg:
    """What the robot is doing now, as one plain sentence (the console and the status
    line say it in the site's language)."""
    board = core.board
    site = core.site
    return phrase(
        [of(node) for node in running_path(core.root)],
        Situation(
            paused=bool(board.get(keys.PAUSED)),
            in_service=board.get(keys.IN_SERVICE) is not False,
            needs_help=board.get(keys.HELP) is not None,
            going_home=board.get(keys.HOME) is not None or board.get(keys.ABORT_REASON) is not None,
            dock=site.tour.dock,
            recruit_at=site.tour.recruit_at,
        ),
        site.name,
    )
