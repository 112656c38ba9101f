"""The belief management system (paper section 5): language, memory, updaters."""

from .errors import BeliefError, BeliefSyntaxError, UnknownPredicateError
from .expression import Comparison, Conjunction, Goal, Negation
from .memory import BeliefChange, BeliefMemory
from .parser import parse_belief, parse_expression, parse_term
from .terms import ListTerm, Struct, Var, format_term, term, to_python

__all__ = [
    "BeliefChange",
    "BeliefError",
    "BeliefMemory",
    "BeliefSyntaxError",
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
