"""Safety rules as the operator writes them: a condition in the belief language, a temporal form (``always``,
``never``, ``within T s after`` a trigger), a contingency (``hold``, ``return``, ``land``, a named subtree or
mission function, or a plugin's: each read by its entry in :mod:`aeroexec.engine.catalog.contingencies`) and a
priority; read from a YAML list with the file and line of every problem.

One rule is one YAML record::

    - rule: return_margin                     # its name, in events and reports
      always: return_margin(self, ?m), ?m >= 20
      contingency: return                     # hold | return [home] | land | subtree ID | call FUNCTION
      priority: 10                            # higher wins when several are broken at once (default 0)
    - rule: link_loss
      within: 30                              # seconds
      after: communication(wireless, lost)    # the trigger
      ensure: flight_state(self, landed)      # what must hold by then
      contingency: land

The same list is read from a catalog's ``safety_rules:`` section (rules for every mission), a rules file given
on the command line, a tree file's ``<SafetyRules>`` element (XML) or ``safety_rules:`` key (YAML), and a Python
mission's ``SAFETY_RULES`` string.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from aeroexec.beliefs import BeliefError, Conjunction
from aeroexec.engine.catalog.contingencies import Contingency, ContingencyNames, contingency_syntax, parse_contingency
from aeroexec.engine.errors import Problem
from aeroexec.engine.yaml_nodes import NodeReader

from aeroexec.lazy import lazy_module

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    import yaml
    from aeroexec.beliefs import BeliefMemory
else:  # PyYAML is imported when a text is read, not with this module (a catalog or world kept parsed reads none)
    yaml = lazy_module("yaml")

ALWAYS, NEVER, WITHIN = "always", "never", "within"
RULE_KEYS = ("rule", ALWAYS, NEVER, WITHIN, "after", "ensure", "contingency", "priority", "description")


@dataclass(frozen=True)
class SafetyRule:
    """One safety rule. ``condition`` is what ``always`` must hold, what ``never`` may hold, or what must hold
    ``within`` seconds ``after`` the trigger."""

    name: str
    form: str  # always | never | within
    condition: Conjunction
    contingency: Contingency
    priority: int = 0
    within: float | None = None
    trigger: Conjunction | None = None
    description: str = ""
    file: str = ""
    line: int = 0

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}" if self.line else self.file

    @property
    def text(self) -> str:
        """The rule in one line, as written."""
        if self.form == WITHIN:
            return f"within {self.within:g} s after {self.trigger.text}: {self.condition.text}"
        return f"{self.form} {self.condition.text}"

    @property
    def predicates(self) -> frozenset[tuple[str, int]]:
        found = self.condition.predicates
        return found | self.trigger.predicates if self.trigger is not None else found


@dataclass
class RuleSet:
    """Rules read from one or more places, and every problem found reading them."""

    rules: list[SafetyRule] = field(default_factory=list)
    problems: list[Problem] = field(default_factory=list)

    @property
    def errors(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "error"]

    def extend(self, other: RuleSet) -> RuleSet:
        known = {rule.name: rule for rule in self.rules}
        for rule in other.rules:
            if rule.name in known:
                self.problems.append(Problem("error", f"safety rule {rule.name} is defined twice (first at "
                                                      f"{known[rule.name].where})", rule.file, rule.line))
                continue
            known[rule.name] = rule
            self.rules.append(rule)
        self.problems += other.problems
        return self


def read_safety_rules(reader: NodeReader, node: yaml.Node | None, vocabulary: BeliefMemory, line_offset: int = 0,
               subtrees: Iterable[str] | None = None, functions: Iterable[str] | None = None) -> RuleSet:
    """The rules of a YAML list ``node`` (composed by ``reader``), their conditions checked against
    ``vocabulary``; ``subtrees``/``functions``, when given, are the names a named contingency may take.
    ``line_offset`` places the list in a larger file (a tree's section, a Python string)."""
    before = len(reader.problems)
    found = RuleSet()
    if node is not None:
        for item in reader.sequence(node, "safety_rules") or ():
            rule = _rule(reader, item, vocabulary, subtrees, functions)
            if rule is not None:
                found.extend(RuleSet([rule]))
    problems = reader.problems[before:]
    del reader.problems[before:]
    found.problems = [Problem(p.severity, p.message, p.file, p.line + line_offset if p.line else p.line)
                      for p in [*problems, *found.problems]]
    if line_offset:
        found.rules = [_moved(rule, line_offset) for rule in found.rules]
    return found


def read_safety_rules_text(text: str, file: str, vocabulary: BeliefMemory, line_offset: int = 0,
                    subtrees: Iterable[str] | None = None, functions: Iterable[str] | None = None) -> RuleSet:
    """The rules of a YAML text: a list of rules, or a mapping with the key ``safety_rules``."""
    reader = NodeReader(text, file)
    found = RuleSet(problems=_offset(reader.problems, line_offset))
    reader.problems = []
    root = reader.root
    if root is not None and root.tag == "tag:yaml.org,2002:map":
        entries = reader.mapping(root, "the rules file", ("safety_rules",)) or {}
        root = entries["safety_rules"][1] if "safety_rules" in entries else None
        found.problems += _offset(reader.problems, line_offset)
        reader.problems = []
    return found.extend(read_safety_rules(reader, root, vocabulary, line_offset, subtrees, functions))


def _offset(problems: list[Problem], offset: int) -> list[Problem]:
    return [Problem(p.severity, p.message, p.file, p.line + offset if p.line else p.line) for p in problems]


def _moved(rule: SafetyRule, offset: int) -> SafetyRule:
    from dataclasses import replace

    return replace(rule, line=rule.line + offset)


def _rule(r: NodeReader, item: yaml.Node, vocabulary: BeliefMemory, subtrees: Iterable[str] | None,
          functions: Iterable[str] | None) -> SafetyRule | None:
    e = r.mapping(item, "a safety rule", RULE_KEYS)
    if e is None:
        return None
    line = item.start_mark.line + 1
    if "rule" not in e:
        r.error(item, "a safety rule needs the key rule (its name)")
        return None
    name = r.text(e["rule"][1], "the name of a safety rule")
    if not name:
        return None
    forms = [form for form in (ALWAYS, NEVER, WITHIN) if form in e]
    if len(forms) != 1:
        r.error(item, f"safety rule {name}: give exactly one of always, never, within"
                      + (f" (not {' and '.join(forms)})" if forms else ""))
        return None
    form = forms[0]
    within = trigger = None
    if form == WITHIN:
        within = r.number(e[WITHIN][1], f"safety rule {name}: within (seconds)", positive=True)
        for key in ("after", "ensure"):
            if key not in e:
                r.error(item, f"safety rule {name}: within needs the key {key}")
        if within is None or "after" not in e or "ensure" not in e:
            return None
        trigger = _condition(r, e["after"][1], vocabulary, f"safety rule {name}: after")
        condition = _condition(r, e["ensure"][1], vocabulary, f"safety rule {name}: ensure")
        if trigger is None:
            return None
    else:
        for key in ("after", "ensure"):
            if key in e:
                r.error(e[key][0], f"safety rule {name}: {key} goes with within, not {form}")
        condition = _condition(r, e[form][1], vocabulary, f"safety rule {name}: {form}")
    if "contingency" not in e:
        r.error(item, f"safety rule {name} needs the key contingency (one of {contingency_syntax()})")
        return None
    contingency = _contingency(r, e["contingency"][1], name, subtrees, functions)
    priority = 0
    if "priority" in e:
        priority = r.integer(e["priority"][1], f"safety rule {name}: priority", minimum=-1000)
    description = r.text(e["description"][1], "description") or "" if "description" in e else ""
    if condition is None or contingency is None or priority is None:
        return None
    return SafetyRule(name, form, condition, contingency, priority, within, trigger, description, r.file, line)


def _condition(r: NodeReader, node: yaml.Node, vocabulary: BeliefMemory, what: str) -> Conjunction | None:
    text = r.text(node, what)
    if not text:
        return None
    try:
        return vocabulary.check(text)
    except BeliefError as exc:
        r.error(node, f"{what}: {exc.message}")
        return None


def _contingency(r: NodeReader, node: yaml.Node, rule: str, subtrees: Iterable[str] | None,
                 functions: Iterable[str] | None) -> Contingency | None:
    """The rule's contingency, read by its entry in the table of contingencies; what is wrong, at its line."""
    text = r.text(node, f"safety rule {rule}: contingency")
    if text is None:
        return None
    names = ContingencyNames(None if subtrees is None else frozenset(subtrees),
                             None if functions is None else frozenset(functions))
    found = parse_contingency(text, names)
    if isinstance(found, str):
        r.error(node, f"safety rule {rule}: {found}")
        return None
    return found


def rule_vocabulary(predicates: Mapping[str, int]) -> BeliefMemory:
    """A memory that checks conditions against ``predicates`` (name -> arity) without storing anything."""
    from aeroexec.beliefs import BeliefMemory  # here: reading rules needs it, not a catalog kept parsed

    return BeliefMemory(predicates=dict(predicates))


__all__ = ["ALWAYS", "NEVER", "WITHIN", "Contingency", "RuleSet", "SafetyRule", "read_safety_rules",
           "read_safety_rules_text", "rule_vocabulary"]
