"""Live observers of a running executive: recording, console, telemetry, status line."""
