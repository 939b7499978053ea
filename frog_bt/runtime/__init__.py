"""The run-time: the I/O-free core, the online executive around it, the blackboard
snapshot, the one clock, checkpoints, the run-time context and robot actions."""
