"""The simulated world from above: obstacles shaded by height, markers with their ids, objects, the moving
platform and the drone's trail, as a Pillow image (north up)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from aeroexec.drones.sim.render import (
    BLACK,
    BOX_COLOR,
    CYLINDER_COLOR,
    DECK_RADIUS,
    GROUND,
    GROUND_TILE,
    PLATFORM_COLOR,
    RGB,
    TREE_COLOR,
    WHITE,
    color_of,
)
from aeroexec.drones.sim.shapes import Box, Cylinder
from aeroexec.drones.sim.world import World
from PIL import Image, ImageDraw


def render_map(world: World, trail: Iterable[Sequence[float]] = (), time: float = 0.0,
               scale: float = 8.0, yaw: float | None = None) -> Image.Image:
    """The world from above (north up, ``scale`` pixels per meter) with the drone's ``trail`` and, when given,
    its heading ``yaw`` drawn at the trail's last point."""
    lo, hi = world.bounds.lower, world.bounds.upper
    width, height = max(1, round((hi[0] - lo[0]) * scale)), max(1, round((hi[1] - lo[1]) * scale))
    span = max(hi[2] - lo[2], 1e-6)
    image = Image.new("RGB", (width, height), GROUND)
    draw = ImageDraw.Draw(image)

    def px(x: float, y: float) -> tuple[float, float]:
        return (x - lo[0]) * scale, (hi[1] - y) * scale

    for x in range(math.ceil(lo[0] / 5) * 5, int(hi[0]) + 1, 5):
        draw.line([px(x, lo[1]), px(x, hi[1])], fill=GROUND_TILE)
    for y in range(math.ceil(lo[1] / 5) * 5, int(hi[1]) + 1, 5):
        draw.line([px(lo[0], y), px(hi[0], y)], fill=GROUND_TILE)

    def tall(color: RGB, top: float) -> RGB:
        f = 1.0 - 0.5 * min(max(top / span, 0.0), 1.0)  # taller is darker
        return tuple(int(c * f) for c in color)  # type: ignore[return-value]

    for obstacle in world.obstacles:
        if isinstance(obstacle, Box):
            (x0, y0, _), (x1, y1, top) = obstacle.lower, obstacle.upper
            draw.rectangle([px(x0, y1), px(x1, y0)], fill=tall(BOX_COLOR, top), outline=BLACK)
        elif isinstance(obstacle, Cylinder):
            (x, y), r = obstacle.center, obstacle.radius
            color = TREE_COLOR if "tree" in obstacle.name.lower() else CYLINDER_COLOR
            draw.ellipse([px(x - r, y + r), px(x + r, y - r)], fill=tall(color, obstacle.top), outline=BLACK)
    for obj in world.objects:
        x, y, _ = obj.position
        r = max(0.25, min(obj.position[2], 1.0))
        draw.ellipse([px(x - r, y + r), px(x + r, y - r)], fill=color_of(obj.color), outline=BLACK)
    if world.platform is not None:
        x, y, _ = world.platform.position(time)
        h = float(getattr(world.platform, "deck_radius", DECK_RADIUS))
        draw.ellipse([px(x - h, y + h), px(x + h, y - h)], fill=PLATFORM_COLOR, outline=WHITE)
    for marker in world.markers:
        x, y, _ = marker.position
        u, v = px(x, y)
        draw.rectangle([u - 3, v - 3, u + 3, v + 3], fill=BLACK, outline=WHITE)
        draw.text((u + 4, v - 10), str(marker.id), fill=WHITE)
    points = [px(p[0], p[1]) for p in trail]
    if len(points) > 1:
        draw.line(points, fill=(30, 60, 230), width=2)
    if points:
        u, v = points[-1]
        heading = math.radians(yaw if yaw is not None else 0.0)
        tip = (u + 9 * math.cos(heading), v - 9 * math.sin(heading))
        back = [(u + 5 * math.cos(heading + a), v - 5 * math.sin(heading + a)) for a in (2.5, -2.5)]
        draw.polygon([tip, back[0], back[1]], fill=(220, 30, 30), outline=BLACK)
    return image


__all__ = ["render_map"]
