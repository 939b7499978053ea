"""The operator's console: see the robot, steer it, hear when it needs help.

:mod:`.server` is the aiohttp application (:func:`~.server.make_app`: the routes, the
console's state under typed keys, its lifetime) serving the page and the JSON API
(CONTRACT §7) in the executive's own event loop (the ``console`` extra); :mod:`.state`
builds what it shows, with the log lines of its own executive only; :mod:`.day` tallies
the day, :mod:`frog_bt.runtime.alerts` decides when the robot asks for help and
:mod:`.webhooks` tells people's phones. Operator commands reach the tree through
:mod:`frog_bt.runtime.staff` and :mod:`frog_bt.engine.operator`. Docs: docs/CONSOLE.md.
"""

CTL_AGENT = "frog-bt-ctl"  # the User-Agent of frog-bt ctl: its commands are recorded "by ctl"
