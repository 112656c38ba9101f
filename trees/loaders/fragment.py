"""A piece of a mission written by the operator for a change in flight: BehaviorTree.CPP XML (one or more elements,
as they would stand inside a ``<Sequence>``) or one behavior as ``BEHAVIOR PORT=VALUE ...``::

    <GO_TO_POINT COORDINATES="10, 0, 5" SPEED="2"/><WAIT DURATION="3"/>
    GO_TO_POINT COORDINATES="geo:47.3977,8.5456,20" name="look again"

Its nodes are named ``file`` (``change 3``) at their line, so what verification says of them points there.
"""

from __future__ import annotations

import re
import shlex

from aeroexec.trees.loaders.xml_loader import read_xml
from aeroexec.trees.model import TreeFormatError, TreeNode

MAX_FRAGMENT = 64 * 1024  # characters: what one command line carries
_TYPE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_WRAPPER = "__change__"


def read_fragment(text: str, file: str) -> list[TreeNode]:
    """The nodes of a fragment (see the module); :class:`TreeFormatError` says what cannot be read, with its line."""
    if len(text) > MAX_FRAGMENT:
        raise TreeFormatError([(file, 1, f"the fragment has {len(text)} characters, more than {MAX_FRAGMENT}")])
    stripped = text.strip()
    if not stripped:
        raise TreeFormatError([(file, 1, "the fragment is empty: give BehaviorTree.CPP XML or BEHAVIOR PORT=VALUE")])
    if stripped.startswith("<"):
        return _xml(stripped, file)
    return [_behavior(stripped, file)]


def _xml(text: str, file: str) -> list[TreeNode]:
    # the wrapper shares the fragment's first line, so the lines of its nodes are the fragment's own
    wrapped = (f'<root BTCPP_format="4" main_tree_to_execute="{_WRAPPER}"><BehaviorTree ID="{_WRAPPER}">'
               f'<Sequence name="{_WRAPPER}">{text}</Sequence></BehaviorTree></root>')
    document = read_xml(wrapped, file)
    if set(document.trees) != {_WRAPPER}:
        raise TreeFormatError([(file, 1, "a fragment holds nodes, not <BehaviorTree> definitions")])
    nodes = document.trees[_WRAPPER].children
    if not nodes:
        raise TreeFormatError([(file, 1, "the fragment holds no node")])
    return nodes


def _behavior(text: str, file: str) -> TreeNode:
    try:
        words = shlex.split(text)
    except ValueError as error:
        raise TreeFormatError([(file, 1, f"the fragment cannot be read: {error}")]) from None
    kind, ports, name = words[0], {}, ""
    if not _TYPE.match(kind):
        raise TreeFormatError([(file, 1, f"{kind!r} is not a node type (BEHAVIOR PORT=VALUE ..., or XML)")])
    for word in words[1:]:
        key, equals, value = word.partition("=")
        if not equals or not _TYPE.match(key.strip()):
            raise TreeFormatError([(file, 1, f"{word!r} is not PORT=VALUE")])
        if key.strip() == "name":
            name = value.strip()
        else:
            ports[key.strip()] = value.strip()
    return TreeNode(kind, name or kind, ports, [], file, 1, named=bool(name))


__all__ = ["MAX_FRAGMENT", "read_fragment"]
