"""aeroexec.trees

Each name is imported from its module when first used (``aeroexec.lazy``): the table of mission formats
(``aeroexec.trees.formats``), which ``aeroexec --help`` lists, loads no reader and no YAML.
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["TreeDocument", "TreeFormatError", "TreeNode", "load_mission_tree", "read_mission_tree"]
__getattr__ = lazy_names(__name__, {"load_mission_tree": "mission_file", "read_mission_tree": "mission_file",
                                    "TreeDocument": "model", "TreeFormatError": "model", "TreeNode": "model"})

if TYPE_CHECKING:
    from aeroexec.trees.mission_file import load_mission_tree, read_mission_tree
    from aeroexec.trees.model import TreeDocument, TreeFormatError, TreeNode
