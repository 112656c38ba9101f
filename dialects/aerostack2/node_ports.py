"""Aerostack2's behavior-tree nodes by name and port (``as2_behavior_tree``).

What every XML mission is asked (does it use Aerostack2's nodes? which ground was it written for?) reads only these
names (:mod:`.tree_mapping`, :mod:`.ground`), so a mission without Aerostack2's nodes never imports the mapping
itself (:mod:`.tree_nodes`, with Aerostack2's behavior tables and the ROS checks behind it: ~15 ms of
``aeroexec verify``, ``bench/startup.py``).
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing is not imported at run time
if TYPE_CHECKING:
    from aeroexec.trees.model import TreeDocument

#: The ports of Aerostack2's nodes (``as2_behavior_tree``), besides those every action has.
PORTS: dict[str, tuple[str, ...]] = {
    "TakeOff": ("height", "speed"), "Land": ("speed",),
    "GoTo": ("pose", "max_speed", "yaw_mode", "yaw_angle", "frame_id"),
    "FollowPath": ("path", "speed", "yaw_mode", "frame_id", "path_topic_name"),
    "FollowReference": ("reference", "max_speed_x", "max_speed_y", "max_speed_z", "yaw_mode", "yaw_angle",
                        "frame_id"),
    "GoToGps": ("latitude", "longitude", "altitude", "max_speed", "yaw_mode", "yaw_angle"),
    "Arm": (), "Offboard": (), "Disarm": (), "IsFlying": ("topic_name",), "Echo": ("data",),
    "SendEvent": ("topic_name", "data"), "WaitForEvent": ("topic_name", "result"),
    "WaitForAlert": ("topic_name", "alert"), "SetOrigin": ("latitude", "longitude", "altitude"),
    "GetOrigin": ("latitude", "longitude", "altitude"), "GpsToCartesian": ("latitude", "longitude", "z", "out_pose"),
}


def is_aerostack2(document: TreeDocument) -> bool:
    """True when the document uses one of Aerostack2's nodes."""
    return any(node.type in PORTS for root in document.trees.values() for node in root.walk())


__all__ = ["PORTS", "is_aerostack2"]
