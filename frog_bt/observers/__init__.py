"""Live observers of a running core: the MCAP recorder and its rotation, the tour summary,
the link states and the status line. They attach to a core's taps and keep their work off
the tick path (rerun telemetry, the other live observer, is :mod:`frog_bt.telemetry`)."""
