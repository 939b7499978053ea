"""The ROS topics of CONTRACT §1: default names and their (fixed) types.

Names are configuration (``config/site.yaml`` ``topics:`` may rename them);
types and meanings are not.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Topic:
    name: str
    type: str


# role -> default topic; roles are what the code refers to.
INPUTS: dict[str, Topic] = {
    "pose": Topic("/FROG_pose", "geometry_msgs/PoseStamped"),
    "response": Topic("/FROG_response", "std_msgs/Int32"),
    "docking_state": Topic("/docking/state", "std_msgs/String"),
    "diagnostic": Topic("/diagnostic", "diagnostic_msgs/DiagnosticArray"),
    "persons": Topic("/UvA_PersonDetectionAndPose", "frog_msgs/PersonDetections"),
    "faces": Topic("/ICL_FaceDataStream", "frog_msgs/FaceData"),
    "people": Topic("/PeopleUPO", "frog_msgs/TrackedPeople"),
}
CLOCK = Topic("/clock", "rosgraph_msgs/Clock")
OUTPUTS: dict[str, Topic] = {
    "goto": Topic("/GotoWayPoint", "geometry_msgs/PoseStamped"),
    "approach": Topic("/ApproachPeopleFar", "std_msgs/Int32"),
    "icl": Topic("/ICL_command", "std_msgs/String"),
    "dock": Topic("/docking/dock", "std_msgs/String"),
}

# /FROG_response codes
ACTIVE, SUCCEEDED, FAILED, ABORTED = 1, 2, 3, 4
DOCKING_STATES = ("docked", "undocking", "undocked", "docking", "failed")

DEFAULT_ROSBRIDGE_URL = "ws://127.0.0.1:9090"
DEFAULT_FRONTEND = ("127.0.0.1", 5005)  # where the front end listens
DEFAULT_LISTEN = ("127.0.0.1", 5006)  # where the executive listens
