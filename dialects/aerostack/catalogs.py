"""Behavior catalogs written for other Aerostack versions, recognised so they are refused in one line naming them.

Levant's ``behavior_catalog.yaml`` is the paper's Appendix B format and is read; Sirocco's (``system:``,
``precedence_constraints``, ``exclusivity_constraints``) and Auster/Libeccio's (``behaviors:`` and ``tasks:``)
are not.
"""

from __future__ import annotations

import yaml


def _has_key(node: yaml.Node, key: str) -> bool:
    return isinstance(node, yaml.MappingNode) and any(getattr(k, "value", None) == key for k, _ in node.value)


def catalog_dialect(root: yaml.Node) -> str | None:
    """One line naming the format of a catalog written for another Aerostack version; None for Appendix B's."""
    if not isinstance(root, yaml.MappingNode):
        return None
    keys = {getattr(k, "value", None) for k, _ in root.value}
    items = [item for k, v in root.value if getattr(k, "value", None) == "behavior_descriptors"
             and isinstance(v, yaml.SequenceNode) for item in v.value]
    if (keys & {"precedence_constraints", "exclusivity_constraints"} and "tasks" not in keys) or any(
            _has_key(item, "system") for item in items):
        return ("This is an Aerostack Sirocco behavior catalog (behavior_descriptors with system:, "
                "precedence_constraints, exclusivity_constraints): aeroexec reads the paper's Appendix B format "
                "(Aerostack Levant's), with incompatible_lists, capabilities and behavior_lists")
    if {"behaviors", "tasks"} <= keys:
        return ("This is an Aerostack Auster/Libeccio behavior catalog (behaviors: and tasks:): aeroexec reads the "
                "paper's Appendix B format (Aerostack Levant's), with behavior_descriptors")
    return None


__all__ = ["catalog_dialect"]
