"""Execution: the I/O-free core that ticks a tree, the online executive around it, the
rehearsal (executive and simulator in one loop), hot reload (watch), checkpoints and the
process's memory settings. What they run on is :mod:`frog_bt.engine`."""
