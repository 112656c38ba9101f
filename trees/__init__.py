"""aeroexec.trees"""

from aeroexec.trees.mission_file import load_mission_tree as load_mission_tree
from aeroexec.trees.mission_file import read_mission_tree as read_mission_tree
from aeroexec.trees.model import TreeDocument as TreeDocument
from aeroexec.trees.model import TreeFormatError as TreeFormatError
from aeroexec.trees.model import TreeNode as TreeNode
