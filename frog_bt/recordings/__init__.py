"""Recordings as files: reading MCAP (whole or cut short), the one decoder of their
channels, and commands compared in domain terms. Below the engine: the simulator reads
them too."""
