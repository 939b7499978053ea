"""Engagement from the ICL face data stream (seed: "ICL FaceDataStream"), sans-I/O.

* A face sample is stored only while the face is near (``distance <= near``)
  and facing the robot.
* A sample is *engaged* when its level is in [0, 1] and not engaged in [-1, 0).
* The **meter** is the majority vote over each ``window`` (2 s): its level is
  the mean of the samples on the winning side (the mean of all of them on a
  tie), or None when the window holds no sample.
* The **decision** (tell more at a POI; the wording of ``ask_tour``) is the
  majority vote over the first and the last ``edge`` fraction (15%) of the
  samples stored from the start of the POI to the end of part a: ``ceil(edge·n)``
  samples from each end, each sample counted once. A tie gives ``on_tie``; no
  sample at all gives None (the caller applies its no-data rule).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

# Plain Python on purpose: the series are short (a 2 s window, a stop's samples), and
# the executive's process never imports numpy. A C extension imported mid-tour can be
# left half-initialised for good when the process runs out of descriptors at that
# moment ("cannot load module more than once per process"); the face stream then
# failed every tick and the tour stood still.


class FaceLike(Protocol):
    """What the maths reads of one face sample (the wire's ``Face`` has these)."""

    @property
    def engagement(self) -> float: ...
    @property
    def distance(self) -> float: ...
    @property
    def facing(self) -> bool: ...


def qualifies(face: FaceLike, near: float) -> bool:
    return face.facing and face.distance <= near


@dataclass(frozen=True, slots=True)
class Decision:
    """Outcome of a majority vote over the edge samples."""

    engaged: bool | None  # None: no data
    engaged_votes: int
    votes: int  # samples voting (first and last edge fraction)
    stored: int  # samples stored in all
    tie: bool = False

    def describe(self) -> str:
        if self.engaged is None:
            return "no face data"
        verdict = "engaged" if self.engaged else "not engaged"
        tie = " (tie)" if self.tie else ""
        return (
            f"{verdict}{tie}: {self.engaged_votes} of {self.votes} edge samples engaged, "
            f"{self.stored} stored"
        )


PAIRWISE_BLOCK = 128  # numpy's PW_BLOCKSIZE


def _pairwise(values: Sequence[float], lo: int, n: int) -> float:
    """numpy's pairwise summation of ``values[lo:lo + n]`` (``pairwise_sum_DOUBLE``):
    the same additions in the same order, so the same double."""
    if n < 8:
        total = 0.0
        for i in range(lo, lo + n):
            total += values[i]
        return total
    if n <= PAIRWISE_BLOCK:
        r = list(values[lo : lo + 8])
        i, end = 8, n - n % 8
        while i < end:
            for j in range(8):
                r[j] += values[lo + i + j]
            i += 8
        total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
        for k in range(lo + i, lo + n):
            total += values[k]
        return total
    half = n // 2
    half -= half % 8
    return _pairwise(values, lo, half) + _pairwise(values, lo + half, n - half)


def mean(values: Sequence[float]) -> float:
    """The mean of ``values`` (not empty) to the last bit as ``numpy.mean`` has it: the
    meter the front end gets, and the recordings replayed against it, stay identical to
    those made when this maths used numpy."""
    return _pairwise(values, 0, len(values)) / len(values)


def vote(levels: Sequence[float]) -> tuple[int, int]:
    """(engaged votes, not-engaged votes) of ``levels``."""
    engaged = sum(1 for level in levels if level >= 0.0)
    return engaged, len(levels) - engaged


def meter(levels: Sequence[float]) -> float | None:
    """The meter level for one window's samples (see the module docstring)."""
    if not levels:
        return None
    engaged, not_engaged = vote(levels)
    if engaged > not_engaged:
        side = [level for level in levels if level >= 0.0]
    elif not_engaged > engaged:
        side = [level for level in levels if level < 0.0]
    else:
        side = list(levels)
    return min(1.0, max(-1.0, mean(side)))


def edge_indices(n: int, edge: float) -> list[int]:
    """Indices of the first and last ``ceil(edge·n)`` of ``n`` samples, each once."""
    if n == 0:
        return []
    k = min(n, math.ceil(edge * n - 1e-9))
    return sorted({*range(k), *range(n - k, n)})


def decide(levels: Sequence[float], edge: float = 0.15, on_tie: bool = False) -> Decision:
    n = len(levels)
    if n == 0:
        return Decision(None, 0, 0, 0)
    chosen = [levels[i] for i in edge_indices(n, edge)]
    engaged, not_engaged = vote(chosen)
    if engaged == not_engaged:
        return Decision(on_tie, engaged, len(chosen), n, tie=True)
    return Decision(engaged > not_engaged, engaged, len(chosen), n)


class Samples:
    """Stored samples ``(t, level)`` of one engagement session, in arrival order."""

    def __init__(self) -> None:
        self._t: list[float] = []
        self._level: list[float] = []

    def add(self, t: float, level: float) -> None:
        self._t.append(t)
        self._level.append(level)

    def __len__(self) -> int:
        return len(self._t)

    def __repr__(self) -> str:
        levels = " ".join(f"{v:.2f}" for v in self._level[:8])
        more = " ..." if len(self._level) > 8 else ""
        return f"{len(self)} samples: {levels}{more}"

    def levels(self) -> tuple[float, ...]:
        return tuple(self._level)

    def window(self, start: float, end: float) -> tuple[float, ...]:
        """Levels of the samples with ``start < t <= end``."""
        return tuple(v for t, v in zip(self._t, self._level, strict=True) if start < t <= end)
