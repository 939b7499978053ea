"""Every leaf type a tree file can name; importing this package registers them all."""

from frog_bt.behaviours import docking, navigation, recruit, tour, visit

__all__ = ["docking", "navigation", "recruit", "tour", "visit"]
