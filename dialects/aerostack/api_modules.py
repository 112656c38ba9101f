"""Aerostack's mission modules as the static check reads them: each function and the API function
(:mod:`aeroexec.engine.api`) it is checked as (``executive_engine_api``: Levant; ``mission_execution_control``:
Sirocco)."""

from __future__ import annotations

#: Levant's ``executive_engine_api``: each function -> the API function it is checked as.
LEVANT_FUNCTIONS: dict[str, str] = {
    "executeBehavior": "execute_behavior", "activateBehavior": "activate_behavior",
    "inhibitBehavior": "inhibit_behavior", "deactivateBehavior": "inhibit_behavior",
    "isActiveBehavior": "is_active_behavior", "consultPlanner": "ask_behavior",
    "addBelief": "add_belief", "assertBelief": "add_belief", "removeBelief": "remove_belief",
    "retractBelief": "remove_belief", "consultBelief": "consult_belief", "queryBelief": "consult_belief",
    "trueBelief": "true_belief",
}
#: Sirocco's ``mission_execution_control``.
SIROCCO_FUNCTIONS: dict[str, str] = {
    "executeTask": "execute_behavior", "startTask": "activate_behavior", "stopTask": "inhibit_behavior",
    "consultPlanner": "ask_behavior", "addBelief": "add_belief", "removeBelief": "remove_belief",
    "queryBelief": "consult_belief", "trueBelief": "true_belief",
}
#: Aerostack's modules, as missions import them -> their functions
API_MODULES: dict[str, dict[str, str]] = {
    "executive_engine_api": LEVANT_FUNCTIONS,
    "mission_execution_control": SIROCCO_FUNCTIONS,
}

__all__ = ["API_MODULES", "LEVANT_FUNCTIONS", "SIROCCO_FUNCTIONS"]
