"""rosbridge v2 over WebSocket: sans-I/O protocol plus a thin asyncio client."""
