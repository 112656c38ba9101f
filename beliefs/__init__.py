"""The belief management system (paper section 5): language, memory, updaters."""

from .errors import BeliefError, BeliefSyntaxError, UnknownPredicateError
from .expression import Comparison, Conjunction, Goal, Negation
from .memory import BeliefChange, BeliefMemory
from .parser import parse_belief, parse_expression, parse_term
from .terms import ListTerm, Struct, Var, format_term, term, to_python
from .updater import BeliefUpdater, FunctionUpdater, publish

__all__ = [
    "BeliefChange",
    "BeliefError",
    "BeliefMemory",
    "BeliefSyntaxError",
    "BeliefUpdater",
    "FunctionUpdater",
    "publish",
    "Comparison",
    "Conjunction",
    "Goal",
    "ListTerm",
    "Negation",
    "Struct",
    "UnknownPredicateError",
    "Var",
    "format_term",
    "parse_belief",
    "parse_expression",
    "parse_term",
    "term",
    "to_python",
]
