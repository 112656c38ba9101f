"""A world as the console's map draws it: bounds, obstacles, markers, objects and the moving platform (JSON)."""

from __future__ import annotations

from typing import Any


def _r(values: Any) -> list[float]:
    return [round(float(v), 2) for v in values]


def world_map(world: Any) -> dict[str, Any] | None:
    """The top-down map of a :class:`~aeroexec.drones.sim.World` (None without a world: a real drone's run)."""
    if world is None:
        return None
    obstacles = []
    for o in world.obstacles:
        if hasattr(o, "radius"):
            obstacles.append({"shape": "cylinder", "name": o.name, "center": _r(o.center), "radius": o.radius,
                              "top": round(o.base + o.height, 2)})
        else:
            obstacles.append({"shape": "box", "name": o.name, "lower": _r(o.lower), "upper": _r(o.upper)})
    platform = None
    if world.platform is not None:
        platform = {"name": world.platform.name, "path": [_r(p) for p in world.platform.path],
                    "radius": world.platform.deck_radius}
    home = getattr(world, "home", None)
    return {"name": world.name, "home": [round(float(v), 7) for v in home] if home else None,
            "bounds": {"lower": _r(world.bounds.lower), "upper": _r(world.bounds.upper)},
            "obstacles": obstacles,
            "markers": [{"id": m.id, "position": _r(m.position)} for m in world.markers],
            "objects": [{"name": o.name, "color": o.color, "shape": o.shape, "position": _r(o.position)}
                        for o in world.objects],
            "platform": platform}
