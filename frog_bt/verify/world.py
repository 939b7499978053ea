"""The world as the properties read it, the labels of choices and the events properties
watch.

A state, as the properties see it, is the tree's (each node running or not, with its
action out or not) and the world's: a tuple indexed by the constants below, read from
the real tree's board and the explorer's robot (:meth:`.real.Real.world_view`).
"""

from __future__ import annotations

import enum

from frog_bt.tree.world import Role as Role  # where it is declared, with the leaves

# World slots (an index into the world tuple).
STARTED = 0  # /tour_state is started
ABORT = 1  # /abort_reason latched (MustAbort .. ClearAbort)
HOME = 2  # the operator's home (or a pause that ran out) is pending
PAUSED = 3  # /paused
IN_SERVICE = 4  # /in_service
DOCKED = 5  # the robot is on its charger
SKIPPED = 6  # /skipped: the POI being skipped, or None
HOMING = 7  # since home was asked: the dock sequence (or a person's help) was reached


class By(enum.Enum):
    """Who decides a choice. A loop of ticks in which only the robot decided (no person,
    front end or operator did anything) is a loop the robot is stuck in."""

    ROBOT = "robot"  # the robot's own outcome (navigation, docking), or time running out
    WORLD = "world"  # a person, the front end, the operator, the diagnostics
    QUIET = "quiet"  # nothing happened (no command, no fault): the default


class Event(enum.Enum):
    """What happened in a tick that a property watches."""

    DRIVE = "drive goal sent"
    APPROACH = "approach sent"
    CONTENT = "content started"
    SPEAK = "visitor addressed"
    UNDOCK = "undock sent"
    DOCK = "dock sent"
    TOUR_STARTED = "tour started"
    RETRY = "retry"
    HELP = "help asked"
