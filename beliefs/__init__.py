"""The belief management system (paper section 5): language, memory, updaters."""

from aeroexec.beliefs.errors import (
    BeliefError,
    BeliefSyntaxError,
    EvaluationRefused,
    RuleError,
    RuleProblem,
    UnknownPredicateError,
)
from aeroexec.beliefs.expression import Comparison, Conjunction, Goal, Negation, Rule
from aeroexec.beliefs.memory import BeliefChange, BeliefMemory
from aeroexec.beliefs.parser import parse_belief, parse_expression, parse_rules, parse_term, read_rules
from aeroexec.beliefs.rules.proofs import Proof
from aeroexec.beliefs.terms import ListTerm, Struct, Var, format_term, term, to_python
from aeroexec.beliefs.updater import BeliefUpdater, FunctionUpdater, publish

__all__ = [
    "BeliefChange",
    "BeliefError",
    "BeliefMemory",
    "BeliefSyntaxError",
    "BeliefUpdater",
    "EvaluationRefused",
    "FunctionUpdater",
    "publish",
    "Comparison",
    "Conjunction",
    "Goal",
    "ListTerm",
    "Negation",
    "Proof",
    "Rule",
    "RuleError",
    "RuleProblem",
    "Struct",
    "UnknownPredicateError",
    "Var",
    "format_term",
    "parse_belief",
    "parse_expression",
    "parse_rules",
    "parse_term",
    "read_rules",
    "term",
    "to_python",
]
