"""BehaviorTree.CPP 4.10's rules for names in a tree file (its ``validateModelName`` and ``validatePortName``): what a
BehaviorTree ID, a SubTree ID, a node's element name and a SubTree model's port name may hold.

aeroexec reads such names all the same (BT.CPP 4.8 did); the loader records each refusal with its line, which
``verify`` reports as a warning and ``verify --strict-btcpp`` as an error, in BT.CPP's words.
"""

from __future__ import annotations

from aeroexec.trees.model import POSTCONDITIONS, PRECONDITIONS

#: Characters BT.CPP forbids in names (they break XML serialization or file paths); control characters too.
FORBIDDEN = " \t\n\r<>&\"'/\\:*?|."
RESERVED_ATTRIBUTES = ("name", "ID", "_autoremap", *PRECONDITIONS, *POSTCONDITIONS)


def forbidden_char(name: str) -> str | None:
    """BT.CPP's ``findForbiddenChar``: the first character a name may not hold (UTF-8 letters are allowed)."""
    return next((c for c in name if (ord(c) < 128 and (c in FORBIDDEN or ord(c) < 32 or ord(c) == 127))), None)


def _shown(char: str) -> str:
    return f"control character (ASCII {ord(char)})" if ord(char) < 32 or ord(char) == 127 else f"'{char}'"


def model_name_problem(name: str) -> str | None:
    """Why BT.CPP 4.10 refuses ``name`` as a tree ID or node type, None when it does not."""
    if not name:
        return "Model/Node type name cannot be empty"
    if name in ("Root", "root"):
        return "'Root' is a reserved name and cannot be used as a node type"
    char = forbidden_char(name)
    return f"Model name '{name}' contains forbidden character {_shown(char)}" if char is not None else None


def port_name_problem(name: str) -> str | None:
    """Why BT.CPP 4.10 refuses ``name`` as a port of a SubTree model, None when it does not."""
    if not name:
        return "Port name cannot be empty"
    if name[0].isdigit():
        return f"Port name '{name}' cannot start with a digit"
    char = forbidden_char(name)
    if char is not None:
        return f"Port name '{name}' contains forbidden character {_shown(char)}"
    return f"Port name '{name}' is a reserved attribute name" if name in RESERVED_ATTRIBUTES else None


def refused(problem: str) -> str:
    """The message aeroexec shows for a name BT.CPP 4.10 refuses."""
    return f"{problem} (BehaviorTree.CPP 4.10 refuses the file)"
