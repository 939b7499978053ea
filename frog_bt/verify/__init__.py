"""Trees you can prove: every run of the code that runs, under every answer of the world.

:mod:`.real` builds nothing of its own: it ticks the tree the loader built, in a real
core, with only the world abstracted (what each node type declares on its class,
:mod:`frog_bt.tree.world`), enumerating every choice of the world at every tick and
hashing each state it reaches, breadth first (:mod:`.explore`: the graph, the steps);
:mod:`.model` numbers the tree's nodes for the properties (:mod:`.properties`, the
designer's in :mod:`.designer`), checked on the transitions and the graph, and
:mod:`.report` prints what holds or the shortest run that breaks it. :mod:`.coverage`
counts what recorded tours ran.
"""
