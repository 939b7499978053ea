"""roslibpy against the simulator, as a script (Twisted's reactor runs once per process).

``python roslibpy_client.py PORT``: connects to ws://127.0.0.1:PORT, subscribes
to /FROG_response and /FROG_pose, advertises /GotoWayPoint and sends a goal one
metre from where the robot is, then waits for the responses. Prints
``{"codes": [...], "start": {...}}`` and exits 0 when they are 1 then 2.
"""

from __future__ import annotations

import json
import sys
import threading
from typing import Any

import roslibpy


def main(port: int) -> int:
    ros = roslibpy.Ros(host="127.0.0.1", port=port)
    ros.run(timeout=10)
    start: dict[str, float] = {}
    codes: list[int] = []
    have_pose, finished = threading.Event(), threading.Event()

    def on_pose(msg: dict[str, Any]) -> None:
        if not have_pose.is_set():
            start.update(msg["pose"]["position"])
            have_pose.set()

    def on_response(msg: dict[str, Any]) -> None:
        codes.append(msg["data"])
        if msg["data"] != 1:
            finished.set()

    # /FROG_response first: once a pose arrives, the server has both subscriptions.
    roslibpy.Topic(ros, "/FROG_response", "std_msgs/Int32").subscribe(on_response)
    roslibpy.Topic(ros, "/FROG_pose", "geometry_msgs/PoseStamped").subscribe(on_pose)
    ok = have_pose.wait(10)
    if ok:
        goal = roslibpy.Topic(ros, "/GotoWayPoint", "geometry_msgs/PoseStamped")
        goal.advertise()
        goal.publish(
            roslibpy.Message(
                {
                    "header": {"seq": 0, "stamp": {"secs": 0, "nsecs": 0}, "frame_id": "map"},
                    "pose": {
                        "position": {"x": start["x"] + 1.0, "y": start["y"], "z": 0.0},
                        "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
                    },
                }
            )
        )
        ok = finished.wait(20)
    print(json.dumps({"codes": codes, "start": start}), flush=True)
    try:
        ros.terminate()
    except Exception as exc:  # closing is best effort; the verdict is already printed
        print(f"terminate: {exc!r}", file=sys.stderr)
    return 0 if ok and codes == [1, 2] else 1


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1])))
