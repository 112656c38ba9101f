"""The behavior catalog and the behavior specialist (paper §4.3, Appendix B).

What behaviors exist, with their arguments, incompatibilities, capabilities,
reactive rules and phenomena; the specialist checks requests (WRONG_FORMAT,
WRONG_VALUE) and sequences (WRONG_SEQUENCE) against it.
"""

from aeroexec.engine.catalog.behavior_catalog import (
    BehaviorCatalog,
    CatalogError,
    default_catalog,
    default_catalog_path,
    load_catalog,
    parse_catalog,
)
from aeroexec.engine.catalog.specialist import BehaviorSpecialist

__all__ = [
    "BehaviorCatalog",
    "BehaviorSpecialist",
    "CatalogError",
    "default_catalog",
    "default_catalog_path",
    "load_catalog",
    "parse_catalog",
]
