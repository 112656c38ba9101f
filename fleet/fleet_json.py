"""``fleet.json`` in a fleet run's output folder: the fleet's name, endpoints, token and the operator's certificate,
for ``aeroexec ctl``."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from aeroexec.engine.supervision.output import DEFAULT_BASE

FLEET_FILE = "fleet.json"
TOKEN_VARIABLE = "AEROEXEC_FLEET_TOKEN"


def write_fleet_file(folder: Path, fleet: str, endpoints: list[str], token: str,
                     operator: Path | None = None) -> Path:
    """The fleet's endpoint, token and operator certificate for ``aeroexec ctl --fleet`` (readable by the user
    only)."""
    path = folder / FLEET_FILE
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    data = {"fleet": fleet, "endpoints": endpoints, "token": token, "pid": os.getpid()}
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
