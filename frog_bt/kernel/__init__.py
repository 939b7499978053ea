"""The kernel every tour runs on: the one clock, the typed keys, the blackboard, the
run-time context (services only) and the robot actions. Nothing here does I/O or knows
how a tour is executed (that is :mod:`frog_bt.runtime`)."""
