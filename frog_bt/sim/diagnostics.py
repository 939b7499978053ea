"""Electronics as ``/diagnostic`` reports them: the battery and scripted faults.

The battery drains at ``drain_per_hour`` percent per hour while off the dock
and charges at ``charge_per_hour`` on it (clamped to 0..100). Each scripted
fault is a status at level 2 (ERROR) or 3 (STALE) from its ``at`` time on, for
``duration`` seconds or for good.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from frog_bt.model.ros import DiagnosticStatus, KeyValue
from frog_bt.sim.scenario import BatterySpec, FaultSpec


class Battery:
    """Battery charge in percent, stepped by ``dt``."""

    def __init__(self, spec: BatterySpec) -> None:
        self.spec = spec
        self.percentage = spec.start

    def step(self, dt: float, docked: bool) -> None:
        rate = self.spec.charge_per_hour if docked else -self.spec.drain_per_hour
        self.percentage = min(100.0, max(0.0, self.percentage + rate * dt / 3600.0))

    def status(self) -> DiagnosticStatus:
        return DiagnosticStatus(
            0, "battery", "", "frog", (KeyValue("percentage", f"{self.percentage:.1f}"),)
        )


def active_faults(
    faults: Iterable[FaultSpec],
    elapsed: float,
    arrivals: Mapping[str, float] | None = None,
    fixed_at: float | None = None,
) -> list[DiagnosticStatus]:
    """Statuses of the faults active ``elapsed`` seconds after the scenario start;
    ``arrivals``: when the robot first arrived at each scenario POI (``on_arrival``);
    ``fixed_at``: when a person fixed every fault then reported (a rehearsal's hands)."""
    t = elapsed + 1e-9  # a step time of 2.9999999 is 3
    out = []
    for f in faults:
        start = f.at if f.at is not None else (arrivals or {}).get(f.on_arrival or "")
        if start is not None and fixed_at is not None and start <= fixed_at:
            continue
        if start is not None and start <= t and (f.duration is None or t < start + f.duration):
            out.append(DiagnosticStatus(f.level, f.name, f.text, "frog"))
    return out
