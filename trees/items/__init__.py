"""MAVLink mission items: QGroundControl plans (``.plan``, both item forms, survey/corridor/structure scans, the
geofence and rally points), QGroundControl's legacy ``.mission`` and ``QGC WPL 110`` files (Mission Planner,
MAVProxy, ArduPilot's autotest) read into one item model, mapped to the catalog's behaviors as a tree, and a tree
that is a sequence of items written back as a ``.plan`` or ``.waypoints``.

Each name is imported from its module when first used (``aeroexec.lazy``): a command that only asks whether a file
is a plan loads no reader.
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["ItemMission", "MissionItem", "PlanDocument", "is_item_file", "items_document",
           "read_item_mission"]
__getattr__ = lazy_names(__name__, {"PlanDocument": "behaviors", "items_document": "behaviors",
                                    "ItemMission": "model", "MissionItem": "model",
                                    "is_item_file": "readers", "read_item_mission": "readers"})

if TYPE_CHECKING:
    from aeroexec.trees.items.behaviors import PlanDocument, items_document
    from aeroexec.trees.items.model import ItemMission, MissionItem
    from aeroexec.trees.items.readers import is_item_file, read_item_mission
