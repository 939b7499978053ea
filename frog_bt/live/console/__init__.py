"""The operator's console: see the robot, steer it, hear when it needs help.

:mod:`.server` serves the page and the JSON API (CONTRACT §7) in the executive's own
event loop (aiohttp, the ``console`` extra); :mod:`.state` builds what it shows,
:mod:`.day` tallies the day, :mod:`.alerts` decides when the robot asks for help and
:mod:`.webhooks` tells people's phones. Operator commands reach the tree through
:mod:`frog_bt.runtime.staff` and :mod:`frog_bt.engine.operator`. Docs: docs/CONSOLE.md.
"""
