"""The one fast path into py_trees: a tick that costs the active path, not the tree.

``BehaviourTree.tick`` runs the pre-tick handlers, ticks the root (visiting each
node it reaches with the non-full visitors), walks the *whole* tree for the
"full" visitors — even when there are none, a cost that grows with the tour —
then runs the post-tick handlers and counts the tick. Without visitors,
:func:`tick` does the same minus that walk. ``tests/tree/test_ticking.py``
pins the equivalence: it fails if py_trees changes what a tick does.
"""

from __future__ import annotations

import py_trees

Behaviour = py_trees.behaviour.Behaviour


def tick(bt: py_trees.trees.BehaviourTree) -> list[Behaviour]:
    """Tick ``bt`` once as ``bt.tick()`` would; the nodes the tick reached."""
    if bt.visitors:
        bt.tick()
        return list(bt.root.iterate())
    for handler in bt.pre_tick_handlers:
        handler(bt)
    ticked = list(bt.root.tick())
    for handler in bt.post_tick_handlers:
        handler(bt)
    bt.count += 1
    return ticked
