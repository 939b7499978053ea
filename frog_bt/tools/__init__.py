"""Offline tools over trees and recorded tours: render a tree, read, replay and batch-replay
recordings. Live observers of a running tour are :mod:`frog_bt.observers`."""
