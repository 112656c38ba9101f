"""Flying a collected mission as an operator would: ``aeroexec run FILE --plain`` in this process, its exit status,
what it printed and its event log."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from aeroexec.cli.main import main

DATA = Path(__file__).parent / "data"
SCRIPTS = DATA / "aerostack2_scripts"
TREES = DATA / "aerostack2_trees"
PLANS = DATA / "aerostack2_plans"
SIROCCO = DATA / "sirocco"
EMPTY_WORLD = DATA / "empty_world.yaml"


@dataclass
class Flight:
    status: int
    out: str
    err: str
    records: list[dict]

    def achieved(self) -> list[str]:
        """The behaviors that achieved their goal, in order (KEEP_HOVERING between requests left out)."""
        return [r["behavior"] for r in self.records
                if r["kind"] == "GOAL_ACHIEVED" and r["behavior"] != "KEEP_HOVERING"]

    def kinds(self, kind: str) -> list[dict]:
        return [r for r in self.records if r["kind"] == kind]


def world(folder: Path, lat: float, lon: float, alt: float = 0.0, name: str = "world.yaml") -> Path:
    """An empty world (ours) whose home is (lat, lon, alt)."""
    path = folder / name
    path.write_text(f"name: empty\nhome: {{lat: {lat}, lon: {lon}, alt: {alt}}}\n"
                    f"bounds: {{min: [-100, -100, 0], max: [100, 100, 30]}}\n")
    return path


def fly(path: Path, tmp_path: Path, capsys, *extra: str, world_file: Path | None = EMPTY_WORLD) -> Flight:
    out = tmp_path / f"out_{path.stem}"
    arguments = ["run", str(path), "--plain", "--output", str(out), *extra]
    if world_file is not None:
        arguments += ["--world", str(world_file)]
    status = main(arguments)
    captured = capsys.readouterr()
    log = out / "events.jsonl"
    records = [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []
    return Flight(status, captured.out, captured.err, records)
