"""Trees you can prove: every run of a tour tree under every outcome of its leaves.

:mod:`.model` compiles a tree built by the loader into numbered nodes, each leaf with
its abstraction (:mod:`.abstraction`); :mod:`.tick` ticks that model as py_trees ticks
the real one, asking an oracle for every leaf outcome and environment input;
:mod:`.explore` enumerates those choices breadth-first over hashed states; the
properties (:mod:`.properties`, the designer's in :mod:`.designer`) are checked on the
transitions and the graph, and :mod:`.report` prints what holds or the shortest run that
breaks it. :mod:`.coverage` counts what recorded tours ran.
"""
