"""MAVLink mission items: QGroundControl plans (``.plan``, both item forms, survey/corridor/structure scans, the
geofence and rally points), QGroundControl's legacy ``.mission`` and ``QGC WPL 110`` files (Mission Planner,
MAVProxy, ArduPilot's autotest) read into one item model, mapped to the catalog's behaviors as a tree, and a tree
that is a sequence of items written back as a ``.plan`` or ``.waypoints``.
"""

from aeroexec.trees.items.behaviors import PlanDocument, items_document
from aeroexec.trees.items.model import ItemMission, MissionItem
from aeroexec.trees.items.readers import ITEM_EXTENSIONS, is_item_file, read_item_mission

__all__ = ["ITEM_EXTENSIONS", "ItemMission", "MissionItem", "PlanDocument", "is_item_file", "items_document",
           "read_item_mission"]
