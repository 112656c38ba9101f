"""The behavior library for aerial robots (paper Appendix A): behavior processes and capability processes.

Every :class:`BehaviorProcess` subclass defined in a module of this package
with a ``behavior = "NAME"`` is registered: adding a behavior is its catalog
entry and its class (docs/adding-a-behavior.md). Capability processes are
listed by name in each module's ``*_PROCESSES`` mapping.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["aerial_behaviors", "aerial_module_index", "aerial_processes", "processes_of_module"]
__getattr__ = lazy_names(__name__, {"aerial_behaviors": "aerial", "aerial_module_index": "aerial",
                                    "aerial_processes": "aerial", "processes_of_module": "aerial"})

if TYPE_CHECKING:
    from aeroexec.engine.behaviors.aerial import (
        aerial_behaviors,
        aerial_module_index,
        aerial_processes,
        processes_of_module,
    )
