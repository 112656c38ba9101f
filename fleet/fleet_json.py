"""``fleet.json`` in a fleet run's output folder: the fleet's name, endpoints, token, the operator's certificate and
the fleet's drones, for ``aeroexec ctl --fleet NAME --run DIR``."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from aeroexec.engine.supervision.output import DEFAULT_BASE

FLEET_FILE = "fleet.json"
TOKEN_VARIABLE = "AEROEXEC_FLEET_TOKEN"


def write_fleet_file(folder: Path, fleet: str, endpoints: list[str], token: str,
                     operator: Path | None = None, drones: Iterable[str] = ()) -> Path:
    """What ``aeroexec ctl --fleet NAME --run DIR`` needs (readable by the user only): the fleet's endpoints, token,
    the operator's certificate when this machine holds it, and the fleet's drones (each expected to answer)."""
    path = folder / FLEET_FILE
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    data: dict[str, Any] = {"fleet": fleet, "endpoints": endpoints, "token": token, "pid": os.getpid(),
                            "drones": sorted(drones)}
    if operator is not None:
        data["credentials"] = str(Path(operator).resolve())
    with os.fdopen(fd, "w") as file:
        json.dump(data, file)
    return path


def read_fleet_file(fleet: str, folder: str | None = None) -> dict[str, Any]:
    """The newest ``fleet.json`` of ``fleet`` (under ``folder`` or the default output base); ValueError if none."""
    files = [Path(folder) / FLEET_FILE] if folder else sorted(DEFAULT_BASE.glob(f"**/{FLEET_FILE}"),
                                                               key=lambda p: p.stat().st_mtime, reverse=True)
    for path in files:
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        if isinstance(data, dict) and data.get("fleet") == fleet:
            return data
    raise ValueError(f"no running fleet {fleet} found{' in ' + folder if folder else ''}: give --connect ENDPOINT "
                     f"and --token T (or {TOKEN_VARIABLE}) and --credentials, or --run DIR")
