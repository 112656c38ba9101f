"""Runtime assurance: the operator's safety rules watched every tick (monitors), the contingencies they take, the
predicates computed from the vehicle model (``battery_to_home``...), and the checks a rule allows before flight.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["SafetyMonitor", "SafetyPredicates"]
__getattr__ = lazy_names(__name__, {"SafetyMonitor": "monitor", "SafetyPredicates": "predicates"})

if TYPE_CHECKING:
    from aeroexec.engine.safety.monitor import SafetyMonitor
    from aeroexec.engine.safety.predicates import SafetyPredicates
