"""Compliance: each safety rule of a run, held or violated, when, and the contingency taken, from its events
(``safety_watch``, ``safety_violated``, ``safety_triggered``, ``safety_met``, ``safety_restored``)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Compliance:
    """One rule over a run: ``held`` unless it was violated (a ``within`` rule met in time held)."""

    rule: str
    text: str = ""
    where: str = ""
    contingency: str = ""
    events: list[tuple[float, str, str]] = field(default_factory=list)  # (time, kind, detail)

    @property
    def held(self) -> bool:
        return not any(kind == "safety_violated" for _, kind, _ in self.events)


def compliance(records: Iterable[dict[str, Any]]) -> list[Compliance]:
    """The rules a run watched (from its event log's records), in the order they were declared."""
    rules: dict[str, Compliance] = {}
    for record in records:
        kind = record.get("kind", "")
        if not kind.startswith("safety_"):
            continue
        data = record.get("data", record)
        if kind == "safety_watch":
            for rule in data.get("rules", []):
                rules[rule["rule"]] = Compliance(rule["rule"], rule.get("text", ""), rule.get("where", ""),
                                                 rule.get("contingency", ""))
            continue
        name = data.get("rule")
        if name is not None:
            rules.setdefault(name, Compliance(name)).events.append((float(record.get("time", 0.0)), kind,
                                                                    record.get("detail", "")))
    return list(rules.values())


__all__ = ["Compliance", "compliance"]
