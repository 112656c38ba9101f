"""The behavior catalog and the behavior specialist (paper §4.3, Appendix B).

What behaviors exist, with their arguments, incompatibilities, capabilities,
reactive rules and phenomena; the specialist checks requests (WRONG_FORMAT,
WRONG_VALUE) and sequences (WRONG_SEQUENCE) against it.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["BehaviorCatalog", "BehaviorSpecialist", "CatalogError", "default_catalog", "default_catalog_path",
           "load_catalog", "parse_catalog"]
__getattr__ = lazy_names(__name__, {"BehaviorCatalog": "behavior_catalog", "CatalogError": "behavior_catalog",
                                    "default_catalog": "behavior_catalog", "default_catalog_path": "behavior_catalog",
                                    "load_catalog": "behavior_catalog", "parse_catalog": "behavior_catalog",
                                    "BehaviorSpecialist": "specialist"})

if TYPE_CHECKING:
    from aeroexec.engine.catalog.behavior_catalog import (
        BehaviorCatalog,
        CatalogError,
        default_catalog,
        default_catalog_path,
        load_catalog,
        parse_catalog,
    )
    from aeroexec.engine.catalog.specialist import BehaviorSpecialist
