"""Which files of ``missions/`` are fleets: a fleet file (top-level ``fleet:``) and the missions its drones fly.

They run with ``aeroexec fleet`` (their missions wait for the other drones), not alone with ``aeroexec run``.
"""

from pathlib import Path

import yaml


def fleet_files(folder: Path) -> set[str]:
    """The names of the fleet files in ``folder``."""
    return {f.name for f in folder.glob("*.yaml")
            if isinstance(data := yaml.safe_load(f.read_text()), dict) and "fleet" in data}


def fleet_parts(folder: Path) -> set[str]:
    """The names of the fleet files in ``folder`` and of the missions their drones fly."""
    parts = fleet_files(folder)
    for name in list(parts):
        parts |= {str(d["mission"]) for d in yaml.safe_load((folder / name).read_text()).get("drones", [])}
    return parts
