"""The modules a Python mission may take the mission API from, their functions, and how the checker reads them.

``aeroexec.engine.api`` (the paper's Table 8, every alias it offers), and the modules of the dialects' APIs
(:mod:`.dialect_checks`: Aerostack's ``executive_engine_api`` and ``mission_execution_control``): each function is
checked as the API function it stands for.
"""

from __future__ import annotations

import ast
import functools
from collections.abc import Iterable

from aeroexec.engine import api
from aeroexec.engine.missions import dialect_checks

RUN = frozenset({"execute_behavior", "ask_behavior", "activate_behavior"})
NAME_ONLY = frozenset({"inhibit_behavior", "is_active_behavior"})
SEQUENCE = RUN | {"inhibit_behavior"}  # the calls that change the phenomena's states
BELIEF = frozenset({"consult_belief", "true_belief", "add_belief", "remove_belief"})
_CANONICAL = (*RUN, *NAME_ONLY, *BELIEF, "wait", "now")
#: every spelling the API module offers -> its canonical function name
API_FUNCTIONS: dict[str, str] = {alias: canonical for canonical in _CANONICAL for alias, value in vars(api).items()
                                 if value is getattr(api, canonical)}
API_FUNCTIONS.update(run_behavior="execute_behavior", start_behavior="activate_behavior",  # Aerostack's conventions
                     stop_behavior="inhibit_behavior")
#: aeroexec's own mission API module
CORE = "aeroexec.engine.api"


@functools.cache
def api_modules() -> dict[str, dict[str, str]]:
    """Every module a mission may take the API from -> its functions by name -> the API function they are checked
    as: aeroexec's, then the dialects' (:mod:`.dialect_checks`)."""
    modules = {CORE: API_FUNCTIONS}
    for checks in dialect_checks.declared():
        modules.update({module: dict(functions) for module, functions in checks.api_modules.items()})
    return modules


def foreign(module: str) -> bool:
    """True for a dialect's API module (where a behavior may be stopped by the uid its activation returned)."""
    return module != CORE


def api_bindings(nodes: Iterable[ast.AST]) -> dict[str, str]:
    """Local name -> the dotted path it stands for, for every import among a program's ``nodes``."""
    bindings: dict[str, str] = {}
    for node in nodes:
        if isinstance(node, ast.Import):
            for alias in node.names:
                top = alias.name.split(".")[0]
                bindings[alias.asname or top] = alias.name if alias.asname else top
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            for alias in node.names:
                if alias.name == "*" and node.module in api_modules():
                    if node.module == CORE:
                        bindings.update({n: f"{node.module}.{n}" for n in getattr(api, "__all__", ())})
                    bindings.update({n: f"{node.module}.{n}" for n in api_modules()[node.module]})
                elif alias.name != "*":
                    bindings[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    return bindings


def offers(module: str, name: str) -> bool:
    return hasattr(api, name) if module == CORE else name in api_modules()[module]


def module_label(module: str) -> str:
    return f" {module}" if foreign(module) else ""


__all__ = ["API_FUNCTIONS", "BELIEF", "CORE", "NAME_ONLY", "RUN", "SEQUENCE", "api_bindings", "api_modules",
           "foreign", "module_label", "offers"]
