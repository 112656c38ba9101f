"""The belief management system (paper section 5): language, memory, updaters.

Each name is imported from its module when first used (``aeroexec.lazy``): a reader of a catalog kept parsed, or of
a flat belief, needs the terms and expressions, not the memory and the rules engine behind it (~15 ms of a start).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

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
__getattr__ = lazy_names(__name__, {
    "BeliefError": "errors",
    "BeliefSyntaxError": "errors",
    "EvaluationRefused": "errors",
    "RuleError": "errors",
    "RuleProblem": "errors",
    "UnknownPredicateError": "errors",
    "Comparison": "expression",
    "Conjunction": "expression",
    "Goal": "expression",
    "Negation": "expression",
    "Rule": "expression",
    "BeliefChange": "memory",
    "BeliefMemory": "memory",
    "parse_belief": "parser",
    "parse_expression": "parser",
    "parse_rules": "parser",
    "parse_term": "parser",
    "read_rules": "parser",
    "Proof": "rules.proofs",
    "ListTerm": "terms",
    "Struct": "terms",
    "Var": "terms",
    "format_term": "terms",
    "term": "terms",
    "to_python": "terms",
    "BeliefUpdater": "updater",
    "FunctionUpdater": "updater",
    "publish": "updater",
})

if TYPE_CHECKING:
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
