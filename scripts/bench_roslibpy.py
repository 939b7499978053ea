"""roslibpy receiving what the executive receives: the same subscriptions, a counter per message.

Runs in a process of its own (roslibpy runs Twisted's reactor in a thread). Answers
``stats`` on stdin with ``{"event": "stats", "received": N, "t": monotonic}``;
closing stdin ends it. The callbacks only count: roslibpy hands them the decoded
JSON ``msg`` (the executive also checks and types each message and caches it).

    .venv/bin/python scripts/bench_roslibpy.py --port 9090
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from typing import Any


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, required=True)
    args = p.parse_args()
    import roslibpy

    from frog_bt.model.wire import INPUTS

    received = 0
    lock = threading.Lock()

    def count(_msg: Any) -> None:
        nonlocal received
        with lock:
            received += 1

    ros = roslibpy.Ros(host=args.host, port=args.port)
    ros.run(timeout=20)
    topics = [roslibpy.Topic(ros, t.name, t.type) for t in INPUTS.values()]
    for topic in topics:
        topic.subscribe(count)
    for line in sys.stdin:
        if line.strip() == "stats":
            with lock:
                n = received
            sys.stdout.write(
                json.dumps({"event": "stats", "received": n, "t": time.monotonic()}) + "\n"
            )
            sys.stdout.flush()
    ros.terminate()


if __name__ == "__main__":
    main()
