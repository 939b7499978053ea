"""Every leaf and scope a tree file can name; importing this package registers them all."""

from frog_bt.behaviours import (
    docking,
    engagement,
    location,
    navigation,
    operator,
    projector,
    recruit,
    safety,
    tour,
    visit,
)

__all__ = ["docking", "engagement", "location", "navigation", "operator", "projector",
           "recruit", "safety", "tour", "visit"]
