"""Images of the simulated world: what the drone's camera sees (flat-shaded, painter's algorithm) and a top-down map.

The camera view projects the world's solids (boxes and cylinders cut into tiles of at most :data:`TILE` meters, so
that sorting polygons by depth orders them well), its ArUco markers (a black-bordered 4 x 4 bit pattern of their id,
drawn right after the surface they are stuck on), colored objects, the moving platform and a checkered ground onto
a sky gradient, far to near, with Pillow. The scene's polygons are built once per :class:`World` and projected with
numpy on each frame. :mod:`.topview` draws the world from above with the drone's trail.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from aeroexec.drones.sim.camera import Camera
from aeroexec.drones.sim.shapes import Box, Cylinder
from aeroexec.drones.sim.world import Marker, World, WorldObject
from PIL import Image, ImageDraw

Vector = tuple[float, float, float]
RGB = tuple[int, int, int]

TILE = 2.0  # m: faces of solids are cut into tiles no larger than this
NEAR = 0.05  # m: the near clipping plane
FAR = 200.0  # m: nothing farther is drawn
FOG_DISTANCE = 150.0  # m: at this distance a surface has the horizon's color
MARKER_SIZE = 0.5  # m: side of a marker's black square (its white quiet zone adds a cell each side)
DECK_RADIUS = 0.75  # m: the moving platform's deck, unless the world says otherwise
DECK_MARKER_SIZE = 1.0  # m: side of the marker on the deck
CYLINDER_SIDES = 16

SKY_TOP: RGB = (110, 160, 225)
HORIZON: RGB = (205, 220, 235)
GROUND: RGB = (118, 140, 96)
GROUND_TILE: RGB = (132, 155, 108)
BOX_COLOR: RGB = (170, 165, 155)
CYLINDER_COLOR: RGB = (150, 150, 160)
TREE_COLOR: RGB = (62, 118, 52)
PLATFORM_COLOR: RGB = (70, 90, 130)
WHITE: RGB = (245, 245, 245)
BLACK: RGB = (15, 15, 15)

#: The colors objects may have (other names get a color of their own from the name).
COLORS: dict[str, RGB] = {
    "red": (210, 40, 35), "green": (40, 170, 60), "blue": (35, 75, 210), "yellow": (235, 205, 35),
    "orange": (240, 130, 30), "purple": (130, 50, 160), "white": WHITE, "black": BLACK,
    "gray": (128, 128, 128), "grey": (128, 128, 128), "brown": (125, 80, 40), "pink": (240, 140, 180),
    "cyan": (40, 200, 210), "magenta": (210, 40, 200),
}

_LIGHT = np.array([0.35, 0.5, 0.8]) / np.linalg.norm([0.35, 0.5, 0.8])  # toward the sun


def color_of(name: str) -> RGB:
    """The RGB of a color name; unknown names get a stable color from their letters."""
    known = COLORS.get(name.lower())
    if known is not None:
        return known
    h = sum((i + 1) * ord(c) for i, c in enumerate(name))
    return (60 + h * 37 % 180, 60 + h * 91 % 180, 60 + h * 53 % 180)


def marker_bits(marker_id: int) -> list[bool]:
    """The 16 cells (row by row) of a marker's inner 4 x 4 pattern: the id's 10 bits, then 6 check bits."""
    bits = [bool(marker_id >> i & 1) for i in range(10)]
    check = (marker_id * 37 + 11) % 64
    return bits + [bool(check >> i & 1) for i in range(6)]


@dataclass
class _Scene:
    """Polygons in world coordinates; ``anchors`` order a decal right after the surface tiles it lies on."""

    vertices: list[np.ndarray] = field(default_factory=list)
    colors: list[RGB] = field(default_factory=list)
    normals: list[Vector | None] = field(default_factory=list)  # None: seen from both sides
    anchors: list[tuple[int, ...]] = field(default_factory=list)
    orders: list[int] = field(default_factory=list)  # 0 surface, 1 decal, 2 decal detail
    ground: list[bool] = field(default_factory=list)  # drawn first, in the ground layer

    def add(self, points: Sequence[Sequence[float]], color: RGB, normal: Vector | None = None, *,
            anchor: tuple[int, ...] | None = None, order: int = 0, ground: bool = False, shade: bool = True) -> int:
        index = len(self.vertices)
        if shade and normal is not None:
            light = 0.6 + 0.4 * max(0.0, float(np.dot(normal, _LIGHT)))
            color = tuple(min(255, int(c * light + 0.5)) for c in color)  # type: ignore[assignment]
        self.vertices.append(np.asarray(points, dtype=float))
        self.colors.append(color)
        self.normals.append(normal)
        self.anchors.append(anchor if anchor else (index,))
        self.orders.append(order)
        self.ground.append(ground)
        return index

    def pack(self) -> _Packed:
        return _Packed(self)


class _Packed:
    """The scene as flat numpy arrays, ready to project."""

    def __init__(self, scene: _Scene) -> None:
        counts = [len(v) for v in scene.vertices]
        self.count = len(counts)
        self.offsets = np.concatenate([[0], np.cumsum(counts)]).astype(int)
        self.points = np.concatenate(scene.vertices) if counts else np.zeros((0, 3))
        self.centroids = np.array([v.mean(axis=0) for v in scene.vertices]) if counts else np.zeros((0, 3))
        self.normals = np.array([n if n is not None else (0.0, 0.0, 0.0) for n in scene.normals], dtype=float)
        self.two_sided = np.array([n is None for n in scene.normals], dtype=bool)
        self.colors = np.array(scene.colors, dtype=float).reshape(-1, 3)
        width = max((len(a) for a in scene.anchors), default=1)
        self.anchors = np.array([a + a[-1:] * (width - len(a)) for a in scene.anchors], dtype=int).reshape(-1, width)
        self.orders = np.array(scene.orders, dtype=int)
        self.ground = np.array(scene.ground, dtype=bool)


# --- building the scene ---------------------------------------------------------------------------

def _splits(low: float, high: float) -> np.ndarray:
    n = max(1, math.ceil((high - low) / TILE - 1e-9))
    return np.linspace(low, high, n + 1)


def _add_box(scene: _Scene, lower: Sequence[float], upper: Sequence[float], color: RGB,
             *, skip_bottom: bool = True) -> list[int]:
    """The faces of an axis-aligned box, cut into tiles; returns their polygon indices."""
    indices = []
    for axis in range(3):
        a, b = [k for k in range(3) if k != axis]
        for side, value in ((-1.0, lower[axis]), (1.0, upper[axis])):
            if axis == 2 and side < 0 and (skip_bottom or value <= 0.0):
                continue
            normal = [0.0, 0.0, 0.0]
            normal[axis] = side
            for u0, u1 in zip(_splits(lower[a], upper[a])[:-1], _splits(lower[a], upper[a])[1:], strict=True):
                for v0, v1 in zip(_splits(lower[b], upper[b])[:-1], _splits(lower[b], upper[b])[1:], strict=True):
                    corners = []
                    for u, v in ((u0, v0), (u1, v0), (u1, v1), (u0, v1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis], p[a], p[b] = value, u, v
                        corners.append(p)
                    indices.append(scene.add(corners, color, tuple(normal)))  # type: ignore[arg-type]
    return indices


def _add_prism(scene: _Scene, center: Sequence[float], radius: float, base: float, top: float, color: RGB,
               sides: int = CYLINDER_SIDES, apex: bool = False) -> list[int]:
    """A vertical cylinder as a prism (or a cone with ``apex``), sides cut into tiles; returns polygon indices."""
    cx, cy = center
    angles = np.linspace(0.0, 2.0 * math.pi, sides + 1)
    ring = [(cx + radius * math.cos(t), cy + radius * math.sin(t)) for t in angles]
    indices = []
    if apex:
        for (x0, y0), (x1, y1), t0, t1 in zip(ring, ring[1:], angles, angles[1:], strict=False):
            mid = (t0 + t1) / 2.0
            slope = radius / max(top - base, 1e-6)
            n = np.array([math.cos(mid), math.sin(mid), slope])
            n /= np.linalg.norm(n)
            indices.append(scene.add([(x0, y0, base), (x1, y1, base), (cx, cy, top)], color, tuple(n)))
        return indices
    heights = _splits(base, top)
    for (x0, y0), (x1, y1), t0, t1 in zip(ring, ring[1:], angles, angles[1:], strict=False):
        mid = (t0 + t1) / 2.0
        normal = (math.cos(mid), math.sin(mid), 0.0)
        for z0, z1 in zip(heights[:-1], heights[1:], strict=True):
            indices.append(scene.add([(x0, y0, z0), (x1, y1, z0), (x1, y1, z1), (x0, y0, z1)], color, normal))
    indices.append(scene.add([(x, y, top) for x, y in ring[:-1]], color, (0.0, 0.0, 1.0)))
    return indices


def _plane_axes(normal: Vector) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning the plane of ``normal``: right and up as seen from its front."""
    n = np.asarray(normal, dtype=float)
    if abs(n[2]) > 0.99:
        right = np.array([1.0, 0.0, 0.0])
    else:
        right = np.cross([0.0, 0.0, 1.0], n)
        right /= np.linalg.norm(right)
    return right, np.cross(n, right)


def _add_marker(scene: _Scene, marker_id: int, position: Sequence[float], normal: Vector, size: float,
                anchor: tuple[int, ...] | None, ground: bool = False) -> None:
    """A marker: white quiet zone, black square and its white bit cells, drawn after the ``anchor`` tiles."""
    center = np.asarray(position, dtype=float)
    right, up = _plane_axes(normal)
    cell = size / 6.0

    def square(x0: float, y0: float, x1: float, y1: float) -> list[np.ndarray]:
        return [center + right * x + up * y for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]

    half = size / 2.0
    quiet = scene.add(square(-half - cell, -half - cell, half + cell, half + cell), WHITE, normal, anchor=anchor,
                      order=1, ground=ground, shade=False)
    anchor = anchor or (quiet,)
    scene.add(square(-half, -half, half, half), BLACK, normal, anchor=anchor, order=2, ground=ground, shade=False)
    for index, bit in enumerate(marker_bits(marker_id)):
        if bit:
            row, col = divmod(index, 4)
            x0, y1 = -half + (col + 1) * cell, half - (row + 1) * cell
            scene.add(square(x0, y1 - cell, x0 + cell, y1), WHITE, normal, anchor=anchor, order=3,
                      ground=ground, shade=False)


def _surface_under(scene: _Scene, surfaces: list[int], point: Sequence[float], normal: Vector,
                   reach: float) -> tuple[int, ...] | None:
    """The tiles of the solid face that a marker at ``point`` facing ``normal`` is stuck on (those within
    ``reach`` of it), or None when it is on no face."""
    p = np.asarray(point, dtype=float)
    found: list[tuple[float, int]] = []
    for index in surfaces:
        n = scene.normals[index]
        if n is None or float(np.dot(n, normal)) < 0.9:
            continue
        corners = scene.vertices[index]
        gap = abs(float(np.dot(p - corners[0], n)))
        if gap >= 0.25:
            continue
        on_plane = p - np.asarray(n) * float(np.dot(p - corners[0], n))
        low, high = corners.min(axis=0) - reach, corners.max(axis=0) + reach
        if np.all(on_plane >= low) and np.all(on_plane <= high):
            found.append((gap, index))
    if not found:
        return None
    best = min(gap for gap, _ in found)
    return tuple(index for gap, index in found if gap <= best + 1e-6)


def _add_object(scene: _Scene, obj: WorldObject) -> None:
    x, y, z = obj.position
    half = min(max(z, 0.1), 1.0)  # objects rest on the ground: their center height is half their size
    color = color_of(obj.color)
    base = max(z - half, 0.0)
    if obj.shape in ("sphere", "ball"):
        # a sphere as an octagonal prism capped by pyramids: round enough at camera range
        _add_prism(scene, (x, y), half, z - half * 0.4, z + half * 0.4, color, sides=10)
        _add_prism(scene, (x, y), half * 0.75, base, z - half * 0.4, color, sides=10)
    elif obj.shape == "cone":
        _add_prism(scene, (x, y), half * 0.8, base, base + 2.0 * half, color, apex=True)
    elif obj.shape in ("cylinder", "barrel"):
        _add_prism(scene, (x, y), half * 0.7, base, base + 2.0 * half, color, sides=12)
    else:
        _add_box(scene, (x - half, y - half, base), (x + half, y + half, base + 2.0 * half), color)


def _static_scene(world: World) -> _Scene:
    scene = _Scene()
    lo, hi = world.bounds.lower, world.bounds.upper
    # the ground: a checkerboard over the bounds (the background is plain ground around it)
    step = max(2.0, math.ceil(max(hi[0] - lo[0], hi[1] - lo[1]) / 12.0))
    xs = np.arange(lo[0], hi[0] + 1e-9, step)
    ys = np.arange(lo[1], hi[1] + 1e-9, step)
    for i, (x0, x1) in enumerate(zip(xs[:-1], xs[1:], strict=True)):
        for j, (y0, y1) in enumerate(zip(ys[:-1], ys[1:], strict=True)):
            if (i + j) % 2 == 0:
                scene.add([(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)], GROUND_TILE,
                          (0.0, 0.0, 1.0), ground=True, shade=False)
    surfaces: list[int] = []
    for obstacle in world.obstacles:
        if isinstance(obstacle, Box):
            surfaces += _add_box(scene, obstacle.lower, obstacle.upper, BOX_COLOR, skip_bottom=obstacle.lower[2] <= 0)
        elif isinstance(obstacle, Cylinder):
            color = TREE_COLOR if "tree" in obstacle.name.lower() else CYLINDER_COLOR
            surfaces += _add_prism(scene, obstacle.center, obstacle.radius, obstacle.base, obstacle.top, color)
    for marker in world.markers:
        _add_world_marker(scene, surfaces, marker)
    for obj in world.objects:
        _add_object(scene, obj)
    return scene


def _add_world_marker(scene: _Scene, surfaces: list[int], marker: Marker) -> None:
    normal = tuple(float(v) for v in marker.normal)
    on_ground = marker.position[2] < 0.1 and normal[2] > 0.9
    reach = MARKER_SIZE * 0.75  # half the marker with its quiet zone
    anchor = None if on_ground else _surface_under(scene, surfaces, marker.position, normal, reach)  # type: ignore[arg-type]
    _add_marker(scene, marker.id, marker.position, normal, MARKER_SIZE, anchor, ground=on_ground)  # type: ignore[arg-type]


def _platform_scene(world: World, time: float) -> _Scene | None:
    platform = world.platform
    if platform is None:
        return None
    scene = _Scene()
    x, y, z = platform.position(time)
    top = max(z, 0.05)
    radius = float(getattr(platform, "deck_radius", DECK_RADIUS))
    faces = _add_prism(scene, (x, y), radius, 0.0, top, PLATFORM_COLOR)
    if platform.marker_id is not None:
        _add_marker(scene, platform.marker_id, (x, y, top + 0.01), (0.0, 0.0, 1.0), min(DECK_MARKER_SIZE, radius),
                    (faces[-1],))
    return scene


# --- projecting ------------------------------------------------------------------------------------

def _clip_near(points: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman against the plane depth >= NEAR; points are (depth, right, up) rows."""
    out = []
    count = len(points)
    for k in range(count):
        a, b = points[k], points[(k + 1) % count]
        a_in, b_in = a[0] >= NEAR, b[0] >= NEAR
        if a_in:
            out.append(a)
        if a_in != b_in:
            t = (NEAR - a[0]) / (b[0] - a[0])
            out.append(a + (b - a) * t)
    return np.array(out) if out else np.zeros((0, 3))


class SceneRenderer:
    """Renders one world: its static polygons are built once; the platform is placed at each frame's time."""

    def __init__(self, world: World) -> None:
        self.world = world
        self._static = _static_scene(world)
        self._packed = self._static.pack()
        self._backgrounds: dict[tuple, np.ndarray] = {}

    def _background(self, width: int, height: int, camera: Camera) -> np.ndarray:
        key = (width, height, camera.vfov, camera.pitch)
        image = self._backgrounds.get(key)
        if image is None:
            fy = (height / 2.0) / math.tan(math.radians(camera.vfov) / 2.0)
            horizon = height / 2.0 + fy * math.tan(math.radians(camera.pitch))  # row of the horizon
            rows = np.arange(height, dtype=float)[:, None]
            t = np.clip(rows / max(horizon, 1.0), 0.0, 1.0)
            sky = np.array(SKY_TOP) * (1 - t) + np.array(HORIZON) * t
            far_ground = np.array(GROUND) * 0.7 + np.array(HORIZON) * 0.3
            column = np.where(rows < horizon, sky, far_ground)
            image = np.repeat(column[:, None, :], width, axis=1).astype(np.uint8)
            self._backgrounds[key] = image
        return image

    def render(self, position: Vector, yaw: float, camera: Camera, time: float = 0.0,
               width: int = 320, height: int = 240) -> Image.Image:
        """The camera's view from ``position`` with ``yaw`` degrees at ``time``, as an RGB Pillow image."""
        packed = self._packed
        platform = _platform_scene(self.world, time)
        if platform is not None and platform.vertices:
            combined = _Scene(*(list(getattr(self._static, f)) for f in
                                ("vertices", "colors", "normals", "anchors", "orders", "ground")))
            shift = len(combined.vertices)
            combined.vertices += platform.vertices
            combined.colors += platform.colors
            combined.normals += platform.normals
            combined.anchors += [tuple(a + shift for a in anchor) for anchor in platform.anchors]
            combined.orders += platform.orders
            combined.ground += platform.ground
            packed = combined.pack()
        image = Image.fromarray(self._background(width, height, camera), "RGB")
        if packed.count == 0:
            return image
        eye = np.asarray(position, dtype=float)
        forward, left, up = (np.asarray(a) for a in camera.axes(yaw))
        basis = np.stack([forward, -left, up])  # rows: depth, right, up
        cam = (packed.points - eye) @ basis.T
        cent = packed.centroids - eye
        facing = packed.two_sided | (np.einsum("ij,ij->i", packed.normals, cent) < 0.0)
        distance = np.linalg.norm(cent, axis=1)
        fx = (width / 2.0) / math.tan(math.radians(camera.hfov) / 2.0)
        fy = (height / 2.0) / math.tan(math.radians(camera.vfov) / 2.0)
        fog = np.clip(distance / FOG_DISTANCE, 0.0, 1.0)[:, None]
        colors = (packed.colors * (1.0 - fog) + np.array(HORIZON) * fog).astype(int)
        offsets = packed.offsets
        max_depth = np.maximum.reduceat(cam[:, 0], offsets[:-1]) if len(cam) else np.zeros(0)
        candidates = np.nonzero(facing & (max_depth > NEAR) & (distance < FAR))[0]
        ground_first = ~packed.ground[candidates]
        key_depth = np.where(packed.ground[candidates], 0.0, -distance[packed.anchors[candidates]].min(axis=1))
        order = np.lexsort((packed.orders[candidates], key_depth, ground_first))
        draw = ImageDraw.Draw(image)
        cx, cy = width / 2.0, height / 2.0
        for index in candidates[order]:
            pts = cam[offsets[index]:offsets[index + 1]]
            if pts[:, 0].min() < NEAR:
                pts = _clip_near(pts)
                if len(pts) < 3:
                    continue
            u = cx + fx * pts[:, 1] / pts[:, 0]
            v = cy - fy * pts[:, 2] / pts[:, 0]
            if u.max() < 0 or u.min() > width or v.max() < 0 or v.min() > height:
                continue
            np.clip(u, -4 * width, 5 * width, out=u)
            np.clip(v, -4 * height, 5 * height, out=v)
            draw.polygon(np.column_stack((u, v)).ravel().tolist(), fill=tuple(colors[index]))
        return image


def to_png(image: Image.Image, compress_level: int = 1) -> bytes:
    """PNG bytes of an image (fast compression by default)."""
    buffer = io.BytesIO()
    image.save(buffer, "PNG", compress_level=compress_level)
    return buffer.getvalue()


def render_camera(world: World, position: Vector, yaw: float, camera: Camera | None = None, time: float = 0.0,
                  width: int = 320, height: int = 240) -> Image.Image:
    """One camera view of ``world`` (builds the scene each call: keep a :class:`SceneRenderer` for many frames)."""
    return SceneRenderer(world).render(position, yaw, camera or Camera.from_settings(world.camera), time,
                                       width, height)


__all__ = ["COLORS", "SceneRenderer", "color_of", "marker_bits", "render_camera", "to_png"]
