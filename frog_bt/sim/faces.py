"""Scripted engagement of a visitor's face, as the ICL face data stream reports it.

Profiles (scenario ``visitors[].faces``), one sample per ``/ICL_FaceDataStream``
message, deterministic for a given seed and visitor id:

* ``engaged``: engagement in [0.2, 0.9], 1 m away, facing;
* ``bored``: engagement in [-0.9, -0.2];
* ``mixed``: a sine of amplitude 0.7 and a 4-second period (at 10 Hz);
* ``far``: engaged values, but 3.5 m away (beyond the near limit);
* ``not_facing``: engaged values, but ``facing`` false;
* a list of numbers: those engagement values, cycled.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from frog_bt.model.ros import Face

NEAR_DISTANCE = 1.0  # metres
FAR_DISTANCE = 3.5
MIXED_PERIOD = 40  # samples (4 s at 10 Hz)


@dataclass(slots=True)
class EngagementScript:
    """Produces the face samples of one visitor."""

    profile: str | tuple[float, ...]
    visitor_id: int
    seed: int = 0
    index: int = 0
    _rng: random.Random | None = None

    def __post_init__(self) -> None:
        self._rng = random.Random(f"{self.seed}:{self.visitor_id}")

    def sample(self) -> Face:
        """The next face sample (and advance)."""
        k = self.index
        self.index += 1
        assert self._rng is not None
        distance, facing = NEAR_DISTANCE, True
        if isinstance(self.profile, tuple):
            engagement = self.profile[k % len(self.profile)]
        elif self.profile == "bored":
            engagement = self._rng.uniform(-0.9, -0.2)
        elif self.profile == "mixed":
            engagement = 0.7 * math.sin(2.0 * math.pi * (k + 0.5) / MIXED_PERIOD)
        else:
            engagement = self._rng.uniform(0.2, 0.9)
            if self.profile == "far":
                distance = FAR_DISTANCE
            elif self.profile == "not_facing":
                facing = False
        return Face(self.visitor_id, round(engagement, 3), distance, facing)
