"""Aerostack registered with the core, as another package would be (pyproject.toml's entry points): its YAML
``nodes:`` missions in the table of mission formats, its mission modules served under the names missions import
them by, and their functions in the static check. (Its ``nodes:`` form and its catalogs' recogniser are entry points
of their own: ``aeroexec.yaml_forms``, ``aeroexec.catalog_dialects``.)"""

from __future__ import annotations

from aeroexec.dialects.aerostack.api_modules import API_MODULES
from aeroexec.dialects.aerostack.formats import FORMATS
from aeroexec.engine.missions.dialect_checks import DialectChecks
from aeroexec.engine.missions.standins import StandIns

_HERE = "aeroexec.dialects.aerostack"

IMPORTS = StandIns(names={name: f"{_HERE}.{name}" for name in API_MODULES})
CHECKS = DialectChecks(api_modules=API_MODULES)

__all__ = ["CHECKS", "FORMATS", "IMPORTS"]
