"""Reading a behavior catalog file (paper Appendix B) into descriptors, with file and line for every problem.

A catalog written for another system is refused in one line naming its format: the dialects recognise theirs
through the entry-point group ``aeroexec.catalog_dialects`` (``(root: yaml.Node) -> str | None``: Aerostack's
Sirocco and Auster/Libeccio catalogs).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from aeroexec.engine.catalog.arguments import VALUE_TYPES, ArgumentDescriptor, format_value
from aeroexec.engine.catalog.descriptors import (
    CATEGORIES,
    DELIBERATIVE,
    GOAL_BASED,
    HIGHER,
    LOWER,
    MOTIONS,
    RECURRENT,
    BehaviorDescriptor,
    CapabilityDescriptor,
    Phenomenon,
    PredicateDeclaration,
    ReactiveRule,
    Transition,
)
from aeroexec.engine.catalog.safety_rules import SafetyRule, read_safety_rules
from aeroexec.engine.catalog.vocabulary import VocabularySections
from aeroexec.engine.yaml_nodes import NodeReader, suggestion

from aeroexec.lazy import lazy_module
from aeroexec.plugins import installed_plugins

if TYPE_CHECKING:
    import yaml
    from aeroexec.beliefs import BeliefMemory, Rule
else:  # PyYAML is imported when a text is read, not with this module (a catalog or world kept parsed reads none)
    yaml = lazy_module("yaml")

SECTIONS = ("default_behavior_values", "behavior_descriptors", "behavior_lists", "reactive_activation",
            "capability_descriptors", "behavior_transitions", "phenomena", "predicates", "vehicle_limits", "rules",
            "safety_rules")
#: The vehicle's documented limits a catalog may give (``vehicle_limits:``) and name in its ranges.
VEHICLE_LIMITS = {"max_altitude": "m above (or below) home", "max_distance": "m from home, horizontally",
                  "max_speed": "m/s horizontally", "max_flight_time": "s a full battery keeps the vehicle flying"}
WORLD = "WORLD"  # allowed_values of a place: in the world's bounds (the vehicle's reach without a world)
BEHAVIOR_KEYS = ("behavior", "category", "timeout", "incompatible_lists", "capabilities", "required_capabilities",
                 "incompatibilities", "arguments", "preconditions", "description", "one_of", "ROS_service_calls",
                 "motion", "duration", "beside")
ARGUMENT_KEYS = ("argument", "allowed_values", "dimensions", "type", "required", "default", "description",
                 "aliases")
TRANSITION_KEYS = ("behavior", "behaviors", "physical_phenomenon", "argument", "argument_value",
                   "initial_state", "final_state")


@dataclass
class CatalogContent:
    """Everything a catalog file says, before cross-references are checked."""

    default_timeout: float = 15.0
    default_category: str = GOAL_BASED
    behaviors: dict[str, BehaviorDescriptor] = field(default_factory=dict)
    lists: dict[str, tuple[str, ...]] = field(default_factory=dict)
    reactive: list[ReactiveRule] = field(default_factory=list)
    safety_rules: list[SafetyRule] = field(default_factory=list)
    capabilities: dict[str, CapabilityDescriptor] = field(default_factory=dict)
    transitions: list[Transition] = field(default_factory=list)
    phenomena: dict[str, Phenomenon] = field(default_factory=dict)
    predicates: dict[str, PredicateDeclaration] = field(default_factory=dict)
    rules: list[Rule] = field(default_factory=list)
    vehicle_limits: dict[str, float] = field(default_factory=dict)
    # where each name was written, for the cross-reference checks
    references: list[tuple[str, str, str, yaml.Node]] = field(default_factory=list)


#: The entry-point group of the recognisers of catalogs written for other systems.
CATALOG_DIALECTS = "aeroexec.catalog_dialects"


@functools.cache
def _recognisers() -> tuple[Any, ...]:
    return tuple(recogniser for _, recogniser in installed_plugins(CATALOG_DIALECTS) if callable(recogniser))


def catalog_dialect(root: yaml.Node) -> str | None:
    """One line naming the format of a catalog written for another system (a dialect's); None for Appendix B's."""
    return next((line for recognise in _recognisers() if (line := recognise(root))), None)


def _peek(node: yaml.Node, key: str) -> str:
    """The value of ``key`` in a mapping node, to name it in messages before it is read."""
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            if getattr(key_node, "value", None) == key and isinstance(value_node, yaml.ScalarNode):
                return str(value_node.value)
    return "?"


class CatalogReader(VocabularySections):
    """Reads one catalog document section by section into a :class:`CatalogContent`."""

    def __init__(self, reader: NodeReader) -> None:
        self.r = reader
        self.content = CatalogContent()
        self._vocabulary: BeliefMemory | None = None

    def read(self) -> CatalogContent:
        root = self.r.root
        if root is None:
            if not self.r.problems:
                self.r.error(None, "the catalog is empty")
            return self.content
        dialect = catalog_dialect(root)
        if dialect is not None:
            self.r.error(root, dialect)
            return self.content
        sections = self.r.mapping(root, "the catalog", SECTIONS) or {}
        # predicates and rules first: preconditions and conditions are checked against them
        order = ("vehicle_limits", "default_behavior_values", "predicates", "rules", "behavior_lists",
                 "capability_descriptors", "behavior_descriptors", "phenomena", "reactive_activation",
                 "behavior_transitions", "safety_rules")
        for name in order:
            if name in sections:
                getattr(self, "_" + name)(sections[name][1])
        return self.content

    # -- sections ---------------------------------------------------------------
    def _default_behavior_values(self, node: yaml.Node) -> None:
        entries = self.r.mapping(node, "default_behavior_values", ("timeout", "category")) or {}
        if "timeout" in entries:
            timeout = self.r.number(entries["timeout"][1], "the default timeout", positive=True)
            self.content.default_timeout = timeout if timeout is not None else self.content.default_timeout
        if "category" in entries:
            self.content.default_category = self._category(entries["category"][1]) or GOAL_BASED

    def _vehicle_limits(self, node: yaml.Node) -> None:
        entries = self.r.mapping(node, "vehicle_limits", tuple(VEHICLE_LIMITS)) or {}
        for name, (_, value) in entries.items():
            limit = self.r.number(value, f"the vehicle limit {name} ({VEHICLE_LIMITS[name]})", positive=True)
            if limit is not None:
                self.content.vehicle_limits[name] = limit

    def _bound(self, node: yaml.Node, what: str) -> float | None:
        """A bound of a range: a number, or the name of a vehicle limit (``-max_distance`` for its negative)."""
        if self.r.is_number(node):
            return self.r.number(node, what)
        name = self.r.text(node, what) or ""
        sign, key = (-1.0, name[1:]) if name.startswith("-") else (1.0, name)
        if key in self.content.vehicle_limits:
            return sign * self.content.vehicle_limits[key]
        known = ", ".join(sorted(self.content.vehicle_limits)) or "none: the catalog has no vehicle_limits"
        self.r.error(node, f"{what} is {name!r}: a number or a vehicle limit ({known})"
                           f"{suggestion(key, self.content.vehicle_limits)}")
        return None

    def _behavior_lists(self, node: yaml.Node) -> None:
        for item in self.r.sequence(node, "behavior_lists") or ():
            e = self.r.mapping(item, "a behavior list", ("list", "name", "behaviors"))
            if e is not None and "name" in e and "list" not in e:  # early Levant names a list with name:
                e["list"] = e.pop("name")
            if e is None or not self._required(e, item, "list", "a behavior list"):
                continue
            name = self.r.text(e["list"][1], "list")
            if name in self.content.lists:
                self.r.error(item, f"the behavior list {name} is given twice")
                continue
            members = self.r.names(e["behaviors"][1], f"the behaviors of list {name}") if "behaviors" in e else []
            for member, member_node in members:
                self.content.references.append(("list_member", member, name, member_node))
            if name is not None:
                self.content.lists[name] = tuple(m for m, _ in members)

    def _capability_descriptors(self, node: yaml.Node) -> None:
        keys = ("capability", "process_sequence", "incompatible_capabilities", "permanent_active",
                "alternative_processes")
        for item in self.r.sequence(node, "capability_descriptors") or ():
            e = self.r.mapping(item, "a capability descriptor", keys)
            if e is None or not self._required(e, item, "capability", "a capability descriptor"):
                continue
            name = self.r.text(e["capability"][1], "capability")
            if name in self.content.capabilities:
                self.r.error(item, f"the capability {name} is described twice (first at line "
                                   f"{self.content.capabilities[name].line})")
                continue
            processes = self.r.names(e["process_sequence"][1], f"process_sequence of {name}") \
                if "process_sequence" in e else []
            incompatible = self.r.names(e["incompatible_capabilities"][1], f"incompatible_capabilities of {name}") \
                if "incompatible_capabilities" in e else []
            for other, other_node in incompatible:
                self.content.references.append(("capability", other, f"capability {name}", other_node))
            permanent = "permanent_active" in e and self.r.flag(e["permanent_active"][1], "permanent_active")
            alternatives = {}
            if "alternative_processes" in e:
                pairs = self.r.mapping(e["alternative_processes"][1], f"alternative_processes of {name}") or {}
                for process, (key_node, value_node) in pairs.items():
                    if process not in {p for p, _ in processes}:
                        self.r.error(key_node, f"capability {name}: {process} is not in its process_sequence")
                    alternative = self.r.text(value_node, f"the alternative to {process}")
                    if alternative is not None:
                        alternatives[process] = alternative
            if name is not None:
                self.content.capabilities[name] = CapabilityDescriptor(
                    name, tuple(p for p, _ in processes), tuple(c for c, _ in incompatible), bool(permanent),
                    alternatives, item.start_mark.line + 1)

    def _behavior_descriptors(self, node: yaml.Node) -> None:
        for item in self.r.sequence(node, "behavior_descriptors") or ():
            behavior = self._behavior(item)
            if behavior is None:
                continue
            if behavior.name in self.content.behaviors:
                first = self.content.behaviors[behavior.name].line
                self.r.error(item, f"the behavior {behavior.name} is described twice (first at line {first})")
                continue
            self.content.behaviors[behavior.name] = behavior

    def _phenomena(self, node: yaml.Node) -> None:
        for item in self.r.sequence(node, "phenomena") or ():
            e = self.r.mapping(item, "a phenomenon", ("phenomenon", "states", "initial_state"))
            if e is None or not self._required(e, item, ("phenomenon", "states", "initial_state"), "a phenomenon"):
                continue
            name = self.r.text(e["phenomenon"][1], "phenomenon")
            states = tuple(s for s, _ in self.r.names(e["states"][1], f"the states of {name}"))
            initial = self.r.text(e["initial_state"][1], "initial_state")
            if initial is not None and initial not in states:
                self.r.error(e["initial_state"][1], f"the initial state {initial} of {name} is not one of its states"
                                                    f"{suggestion(initial, states)}")
            elif name is not None:
                self.content.phenomena[name] = Phenomenon(name, states, initial, item.start_mark.line + 1)

    def _reactive_activation(self, node: yaml.Node) -> None:
        keys = ("behavior", "condition", "priority", "arguments")
        for item in self.r.sequence(node, "reactive_activation") or ():
            e = self.r.mapping(item, "a reactive activation", keys)
            if e is None or not self._required(e, item, "behavior", "a reactive activation"):
                continue
            name = self.r.text(e["behavior"][1], "behavior")
            self.content.references.append(("reactive", name, "reactive_activation", e["behavior"][1]))
            priority = LOWER
            if "priority" in e:
                priority = self.r.text(e["priority"][1], "priority")
                if priority not in (LOWER, HIGHER):
                    self.r.error(e["priority"][1], f"the priority of the reactive activation of {name} must be "
                                                   f"lower or higher, not {priority}")
                    continue
            condition = self._expression(e["condition"][1], f"the condition of {name}") if "condition" in e else None
            arguments = {}
            if "arguments" in e:
                args = self.r.mapping(e["arguments"][1], f"the arguments of the reactive activation of {name}") or {}
                arguments = {key: self.r.value(value) for key, (_, value) in args.items()}
            if name is not None:
                self.content.reactive.append(ReactiveRule(name, condition, priority, arguments,
                                                          item.start_mark.line + 1))

    def _safety_rules(self, node: yaml.Node) -> None:
        found = read_safety_rules(self.r, node, self._memory())
        self.r.problems += found.problems
        self.content.safety_rules = found.rules

    def _behavior_transitions(self, node: yaml.Node) -> None:
        aliases = {"phenomenon": "physical_phenomenon"}  # Figure 8 writes both
        for item in self.r.sequence(node, "behavior_transitions") or ():
            e = self.r.mapping(item, "a behavior transition", TRANSITION_KEYS, aliases)
            if e is None:
                continue
            if ("behavior" in e) == ("behaviors" in e):
                self.r.error(item, "a behavior transition needs behavior (one name) or behaviors (a list)")
                continue
            if not self._required(e, item, ("physical_phenomenon", "initial_state", "final_state"),
                                  "a behavior transition"):
                continue
            names = self.r.names(e.get("behavior", e.get("behaviors"))[1], "behaviors")
            for name, name_node in names:
                self.content.references.append(("transition", name, "behavior_transitions", name_node))
            phenomenon = self.r.text(e["physical_phenomenon"][1], "physical_phenomenon")
            initial = tuple(s for s, _ in self.r.names(e["initial_state"][1], "initial_state"))
            final = self.r.text(e["final_state"][1], "final_state")
            argument = self.r.text(e["argument"][1], "argument") if "argument" in e else None
            value = self.r.text(e["argument_value"][1], "argument_value") if "argument_value" in e else None
            if (argument is None) != (value is None):
                self.r.error(item, "a transition for an argument needs both argument and argument_value")
                continue
            if phenomenon is None or final is None or not initial:
                continue
            transition = Transition(tuple(n for n, _ in names), phenomenon, initial, final, argument, value,
                                    item.start_mark.line + 1)
            self.content.transitions.append(transition)

    # -- a behavior ---------------------------------------------------------------
    def _behavior(self, item: yaml.Node) -> BehaviorDescriptor | None:
        e = self.r.mapping(item, f"behavior {_peek(item, 'behavior')}", BEHAVIOR_KEYS, {"recurrent": "category"})
        if e is None or not self._required(e, item, "behavior", "a behavior descriptor"):
            return None
        name = self.r.text(e["behavior"][1], "behavior")
        if name is None:
            return None
        category = self.content.default_category
        if "category" in e:
            node = e["category"][1]
            if isinstance(node, yaml.ScalarNode) and self.r.value(node) is True:  # Appendix B: "recurrent: yes"
                category = RECURRENT
            else:
                category = self._category(node) or category
        timeout = self.content.default_timeout if category in (GOAL_BASED, DELIBERATIVE) else None
        if "timeout" in e:
            timeout = self.r.number(e["timeout"][1], f"the timeout of {name}", positive=True) or timeout
        lists = [pair for key in ("incompatible_lists", "incompatibilities") if key in e  # early Levant's spelling
                 for pair in self.r.names(e[key][1], key)]
        for list_name, node in lists:
            self.content.references.append(("list", list_name, name, node))
        capabilities = [pair for key in ("capabilities", "required_capabilities") if key in e  # Levant's spelling
                        for pair in self.r.names(e[key][1], key)]
        for capability, node in capabilities:
            self.content.references.append(("capability", capability, f"behavior {name}", node))
        arguments: dict[str, ArgumentDescriptor] = {}
        for arg_node in (self.r.sequence(e["arguments"][1], f"the arguments of {name}") or ()) \
                if "arguments" in e else ():
            argument = self._argument(arg_node, name)
            if argument is not None and argument.name in arguments:
                self.r.error(arg_node, f"the argument {argument.name} of behavior {name} is described twice")
            elif argument is not None:
                arguments[argument.name] = argument
        one_of = []
        for group_node in (self.r.sequence(e["one_of"][1], "one_of") or ()) if "one_of" in e else ():
            group = self.r.names(group_node, "a one_of group")
            for arg, arg_node in group:
                if arg not in arguments:
                    self.r.error(arg_node, f"one_of names {arg}, which is not an argument of {name}"
                                           f"{suggestion(arg, arguments)}")
            one_of.append(tuple(a for a, _ in group))
        preconditions = self._expression(e["preconditions"][1], f"the preconditions of {name}") \
            if "preconditions" in e else None
        calls = self.r.names(e["ROS_service_calls"][1], "ROS_service_calls") if "ROS_service_calls" in e else []
        return BehaviorDescriptor(
            name, category, timeout, tuple(n for n, _ in lists), tuple(c for c, _ in capabilities), arguments,
            tuple(one_of), preconditions, self._description(e), tuple(c for c, _ in calls), item.start_mark.line + 1,
            **self._timing(e, name, arguments))

    def _timing(self, e: dict, name: str, arguments: dict[str, ArgumentDescriptor]) -> dict[str, Any]:
        """A behavior's motion (``motion:``), time in place (``duration:`` seconds, or the argument saying so) and
        whether it runs beside the flight (``beside: yes``): read by the route estimate."""
        found: dict[str, Any] = {}
        if "motion" in e:
            motion = self.r.text(e["motion"][1], f"the motion of {name}")
            if motion is not None and motion not in MOTIONS:
                self.r.error(e["motion"][1], f"the motion of {name} must be one of {', '.join(MOTIONS)}, not "
                                             f"{motion!r}{suggestion(motion, MOTIONS)}")
            elif motion is not None:
                found["motion"] = motion
        if "duration" in e:
            node = e["duration"][1]
            if isinstance(node, yaml.ScalarNode) and isinstance(self.r.value(node), str):
                if node.value in arguments:
                    found["duration"] = node.value
                else:
                    self.r.error(node, f"the duration of {name} must be seconds or one of its arguments, not "
                                       f"{node.value!r}{suggestion(node.value, arguments)}")
            else:
                seconds = self.r.number(node, f"the duration of {name}")
                if seconds is not None and seconds < 0:
                    self.r.error(node, f"the duration of {name} must be at least 0 seconds, not {seconds:g}")
                elif seconds is not None:
                    found["duration"] = float(seconds)
        if "beside" in e:
            beside = self.r.flag(e["beside"][1], f"beside of {name}")
            if beside is not None:
                found["beside"] = beside
        return found

    def _argument(self, node: yaml.Node, behavior: str) -> ArgumentDescriptor | None:
        e = self.r.mapping(node, f"argument {_peek(node, 'argument')} of {behavior}", ARGUMENT_KEYS,
                           {"dimension": "dimensions"})
        if e is None or not self._required(e, node, "argument", f"an argument of {behavior}"):
            return None
        name = self.r.text(e["argument"][1], "argument")
        what = f"argument {name} of {behavior}"
        spec: dict[str, Any] = {"name": name, "line": node.start_mark.line + 1, "description": self._description(e)}
        if "allowed_values" in e:
            spec.update(self._allowed(e["allowed_values"][1], what))
        if "type" in e:
            value_type = self.r.text(e["type"][1], f"the type of {what}")
            if value_type not in VALUE_TYPES:
                self.r.error(e["type"][1], f"the type {value_type} of {what} is not one of {', '.join(VALUE_TYPES)}")
            else:
                spec["value_type"] = value_type
        if spec.get("in_world"):
            spec.setdefault("value_type", "POINT")
        if "dimensions" in e:
            spec["dimensions"] = self.r.integer(e["dimensions"][1], f"the dimensions of {what}", minimum=1) or 1
        elif spec.get("value_type") == "POINT" or (spec.get("in_world") and spec.get("value_type") != "PATH"):
            spec["dimensions"] = 3
        if "required" in e:
            spec["required"] = bool(self.r.flag(e["required"][1], f"required of {what}"))
        if "aliases" in e:
            spec["aliases"] = tuple(a for a, _ in self.r.names(e["aliases"][1], f"the aliases of {what}"))
        if name is None:
            return None
        argument = ArgumentDescriptor(**spec)
        if "default" in e:
            node = e["default"][1]
            # an enumeration keeps the text as written: YAML 1.1 would read ON or yes as true
            default = node.value if argument.choices and isinstance(node, yaml.ScalarNode) else self.r.value(node)
            if not argument.accepts(default):
                self.r.error(e["default"][1], f"the default {format_value(default)} of {what} is not allowed "
                                              f"({argument.expected()} is expected)")
            else:
                argument = ArgumentDescriptor(**{**spec, "default": default})
        return argument

    def _allowed(self, node: yaml.Node, what: str) -> dict[str, Any]:
        if isinstance(node, yaml.ScalarNode):
            name = self.r.text(node, f"allowed_values of {what}")
            if name in VALUE_TYPES:
                return {"value_type": name}
            if name == WORLD:
                limits = self.content.vehicle_limits
                reach = (limits["max_distance"], limits["max_altitude"]) if {"max_distance", "max_altitude"} <= \
                    limits.keys() else None
                return {"in_world": True, "reach": reach}
            self.r.error(node, f"allowed_values of {what} must be a range [min, max], a list of values, {WORLD} or a "
                               f"type ({', '.join(VALUE_TYPES)}), not {name}{suggestion(name or '', VALUE_TYPES)}")
            return {}
        items = self.r.sequence(node, f"allowed_values of {what}")
        if not items:
            if items is not None:
                self.r.error(node, f"allowed_values of {what} is empty")
            return {}
        limits = self.content.vehicle_limits
        named = [isinstance(i, yaml.ScalarNode) and str(i.value).lstrip("-") in limits for i in items]
        if len(items) == 2 and (any(self.r.is_number(i) for i in items) or all(named)):  # a range: its bounds
            low, high = (self._bound(i, f"a bound of the range of {what}") for i in items)
            if low is None or high is None:
                return {}
            if low > high:
                self.r.error(node, f"the range of {what} has its minimum {low:g} above its maximum {high:g}")
                return {}
            return {"minimum": low, "maximum": high}
        choices = []
        for item in items:
            text = self.r.text(item, f"a value of {what}")
            if text is not None and text in choices:
                self.r.error(item, f"the value {text} of {what} is listed twice")
            elif text is not None:
                choices.append(text)
        return {"choices": tuple(choices)}

    # -- pieces -------------------------------------------------------------------
    def _category(self, node: yaml.Node) -> str | None:
        category = self.r.text(node, "category")
        if category is not None and category not in CATEGORIES:
            self.r.error(node, f"the category {category} is not one of {', '.join(CATEGORIES)}"
                               f"{suggestion(category, CATEGORIES)}")
            return None
        return category

    def _description(self, entries: dict) -> str:
        if "description" not in entries:
            return ""
        return self.r.text(entries["description"][1], "description") or ""

    def _required(self, entries: dict, node: yaml.Node, keys: str | tuple[str, ...], what: str) -> bool:
        missing = [k for k in ((keys,) if isinstance(keys, str) else keys) if k not in entries]
        for key in missing:
            self.r.error(node, f"{what} needs the key {key}")
        return not missing
