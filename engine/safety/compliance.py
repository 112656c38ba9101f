"""Compliance: each safety rule of a run, held or violated, when, and the contingency taken, from its events
(``safety_watch``, ``safety_violated``, ``safety_triggered``, ``safety_met``, ``safety_restored``); and the
monitors' status now, for the live view and the console (:class:`SafetyStatus`)."""

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


@dataclass(frozen=True)
class SafetyStatus:
    """The monitors now, as plain data: how many rules are watched, those violated now (rule, since when), the
    contingency in effect (rule, contingency, what it did), the ``within`` obligations open (rule, due by when)."""

    rules: int
    violated: tuple[tuple[str, float], ...] = ()
    in_effect: tuple[str, str, str] | None = None
    due: tuple[tuple[str, float], ...] = ()

    @property
    def level(self) -> str:
        """``violated`` (a rule is broken, or a contingency is in effect), ``due`` (an obligation is open), ``held``."""
        return "violated" if self.violated or self.in_effect else "due" if self.due else "held"

    def summary(self) -> str:
        """One line: ``safety: 4 rules held``, or what is violated, the contingency in effect and what is due."""
        if self.level == "held":
            return f"safety: {self.rules} rule{'s' if self.rules != 1 else ''} held"
        parts = []
        if self.violated:
            parts.append("violated " + ", ".join(f"{rule} (t={since:.1f} s)" for rule, since in self.violated))
        if self.in_effect:
            rule, contingency, action = self.in_effect
            parts.append(f"in effect: {rule} {contingency}, {action}")
        if self.due:
            parts.append("due: " + ", ".join(f"{rule} by t={by:.1f} s" for rule, by in self.due))
        return "safety: " + "; ".join(parts)

    def as_dict(self) -> dict[str, Any]:
        """For the console's snapshots (JSON)."""
        return {"rules": self.rules, "level": self.level, "summary": self.summary(),
                "violated": [list(v) for v in self.violated], "due": [list(d) for d in self.due],
                "in_effect": list(self.in_effect) if self.in_effect else None}


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


__all__ = ["Compliance", "SafetyStatus", "compliance"]
