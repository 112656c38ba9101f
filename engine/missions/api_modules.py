"""The modules a Python mission may take the mission API from, their functions, and how the checker reads them.

``aeroexec.engine.api`` (the paper's Table 8, every alias it offers), and Aerostack's
``executive_engine_api`` (Levant) and ``mission_execution_control`` (Sirocco): each function is checked as
the API function it stands for.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable

from aeroexec.engine import api

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
#: Aerostack's mission modules: each function -> the API function it is checked as.
LEVANT_FUNCTIONS: dict[str, str] = {
    "executeBehavior": "execute_behavior", "activateBehavior": "activate_behavior",
    "inhibitBehavior": "inhibit_behavior", "deactivateBehavior": "inhibit_behavior",
    "isActiveBehavior": "is_active_behavior", "consultPlanner": "ask_behavior",
    "addBelief": "add_belief", "assertBelief": "add_belief", "removeBelief": "remove_belief",
    "retractBelief": "remove_belief", "consultBelief": "consult_belief", "queryBelief": "consult_belief",
    "trueBelief": "true_belief",
}
SIROCCO_FUNCTIONS: dict[str, str] = {
    "executeTask": "execute_behavior", "startTask": "activate_behavior", "stopTask": "inhibit_behavior",
    "consultPlanner": "ask_behavior", "addBelief": "add_belief", "removeBelief": "remove_belief",
    "queryBelief": "consult_belief", "trueBelief": "true_belief",
}
#: every module a mission may take the API from -> its functions by name -> the API function they are checked as
API_MODULES: dict[str, dict[str, str]] = {
    "aeroexec.engine.api": API_FUNCTIONS,
    "executive_engine_api": LEVANT_FUNCTIONS,
    "mission_execution_control": SIROCCO_FUNCTIONS,
}
#: Aerostack's modules, where a behavior may be stopped by the uid its activation returned
AEROSTACK_MODULES = frozenset({"executive_engine_api", "mission_execution_control"})


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
                if alias.name == "*" and node.module in API_MODULES:
                    if node.module == "aeroexec.engine.api":
                        bindings.update({n: f"{node.module}.{n}" for n in getattr(api, "__all__", ())})
                    bindings.update({n: f"{node.module}.{n}" for n in API_MODULES[node.module]})
                elif alias.name != "*":
                    bindings[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    return bindings


def offers(module: str, name: str) -> bool:
    return hasattr(api, name) if module == "aeroexec.engine.api" else name in API_MODULES[module]


def module_label(module: str) -> str:
    return f" {module}" if module in AEROSTACK_MODULES else ""


__all__ = ["AEROSTACK_MODULES", "API_FUNCTIONS", "API_MODULES", "BELIEF", "NAME_ONLY", "RUN", "SEQUENCE",
           "api_bindings", "module_label", "offers"]
