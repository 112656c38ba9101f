"""aeroexec.trees"""

from .loader import MISSION_EXTENSIONS as MISSION_EXTENSIONS
from .loader import load_mission_tree as load_mission_tree
from .loader import read_mission_tree as read_mission_tree
from .model import TreeDocument as TreeDocument
from .model import TreeFormatError as TreeFormatError
from .model import TreeNode as TreeNode
