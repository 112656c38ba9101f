"""Occupancy mapping from a camera: a 3D voxel map of what was seen free or occupied, and its images.

Pure geometry and numpy (no engine state). With an obstacle map (the simulated world, or any map answering
``distance_to_obstacle``) each scan casts the camera's rays through the map's solids: voxels a ray crosses are
seen free, the voxel where it stops on a solid is seen occupied, and rays end on the ground or at the camera's
range. Without one, only what perception recognizes (markers, objects) is mapped. Images: a top view (unknown
gray, free white, occupied black, landmarks drawn) and a height map (the top of what was seen occupied).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from aeroexec.engine.planning.grid import split_block
from PIL import Image, ImageColor, ImageDraw

logger = logging.getLogger(__name__)

Point = tuple[float, float, float]

UNKNOWN, FREE, OCCUPIED = 0, 1, 2
_SHADES = np.array([(128, 128, 128), (238, 238, 238), (25, 25, 25)], dtype=np.uint8)


@dataclass(frozen=True)
class CameraModel:
    """What the scan needs of a camera: fields of view and mounting pitch (degrees), range (m), rays per scan."""

    hfov: float = 80.0
    vfov: float = 60.0
    range: float = 12.0
    pitch: float = -20.0
    columns: int = 48
    rows: int = 36

    @classmethod
    def of(cls, settings: Any, **overrides: Any) -> CameraModel:
        """From any object with ``hfov``, ``vfov``, ``range`` and ``pitch`` (the simulated world's camera)."""
        base = cls(**overrides)
        if settings is None:
            return base
        return cls(hfov=float(getattr(settings, "hfov", base.hfov)), vfov=float(getattr(settings, "vfov", base.vfov)),
                   range=float(getattr(settings, "range", base.range)),
                   pitch=float(getattr(settings, "pitch", base.pitch)), columns=base.columns, rows=base.rows)

    def rays(self, yaw: float) -> np.ndarray:
        """Unit directions (rows x columns, 3) across both fields of view, for a drone heading ``yaw`` degrees."""
        y, p = math.radians(yaw), math.radians(self.pitch)
        forward = np.array([math.cos(p) * math.cos(y), math.cos(p) * math.sin(y), math.sin(p)])
        left = np.array([-math.sin(y), math.cos(y), 0.0])
        up = np.array([-math.sin(p) * math.cos(y), -math.sin(p) * math.sin(y), math.cos(p)])
        h = np.tan(np.radians(np.linspace(-self.hfov / 2.0, self.hfov / 2.0, self.columns)))
        v = np.tan(np.radians(np.linspace(-self.vfov / 2.0, self.vfov / 2.0, self.rows)))
        dirs = forward[None, None, :] + h[None, :, None] * left[None, None, :] + v[:, None, None] * up[None, None, :]
        return (dirs / np.linalg.norm(dirs, axis=2, keepdims=True)).reshape(-1, 3)


def solid_voxels(obstacles: Any, lower: Point, shape: tuple[int, int, int], resolution: float) -> np.ndarray:
    """Voxels whose centers lie inside an obstacle (bool array, x by y by z).

    Boxes (``center``, ``size``) and vertical cylinders (``center`` x/y, ``radius``, ``height``, ``base``) listed
    in ``obstacles.obstacles`` are rasterized at once; any other map is classified by its distance function,
    splitting blocks until the (1-Lipschitz) distance decides.
    """
    solids = getattr(obstacles, "obstacles", None)
    centers = [lo + (np.arange(n) + 0.5) * resolution for lo, n in zip(lower, shape, strict=True)]
    occupied = np.zeros(shape, dtype=bool)
    if solids is not None and all(_rasterizable(o) for o in solids):
        xs, ys, zs = centers
        for o in solids:
            if getattr(o, "size", None) is not None:
                c, s = o.center, o.size
                mx = np.abs(xs - c[0]) <= s[0] / 2.0
                my = np.abs(ys - c[1]) <= s[1] / 2.0
                mz = np.abs(zs - c[2]) <= s[2] / 2.0
                occupied |= mx[:, None, None] & my[None, :, None] & mz[None, None, :]
            else:
                base = float(getattr(o, "base", 0.0))
                inside = (xs[:, None] - o.center[0]) ** 2 + (ys[None, :] - o.center[1]) ** 2 <= o.radius ** 2
                mz = (zs >= base) & (zs <= base + o.height)
                occupied |= inside[:, :, None] & mz[None, None, :]
        return occupied
    _classify(obstacles, lower, shape, resolution, occupied)
    return occupied


def _rasterizable(obstacle: Any) -> bool:
    center = getattr(obstacle, "center", None)
    if center is None:
        return False
    if getattr(obstacle, "size", None) is not None:
        return len(center) == 3
    return all(getattr(obstacle, a, None) is not None for a in ("radius", "height")) and len(center) == 2


def _classify(obstacles: Any, lower: Point, shape: tuple[int, int, int], resolution: float, out: np.ndarray) -> None:
    r = resolution
    stack = [(0, shape[0], 0, shape[1], 0, shape[2])]
    while stack:
        i0, i1, j0, j1, k0, k1 = stack.pop()
        center = tuple(lo + (a + b) / 2.0 * r for lo, a, b in zip(lower, (i0, j0, k0), (i1, j1, k1), strict=True))
        reach = r / 2.0 * math.sqrt((i1 - i0 - 1) ** 2 + (j1 - j0 - 1) ** 2 + (k1 - k0 - 1) ** 2)
        d = obstacles.distance_to_obstacle(center)
        if d > reach:
            continue  # every center of the block is outside
        if i1 - i0 == j1 - j0 == k1 - k0 == 1:
            out[i0, j0, k0] = d <= 0.0
            continue
        stack.extend(split_block(i0, i1, j0, j1, k0, k1))


@dataclass
class Landmark:
    """Something recognized on the map: a marker (``label`` its code) or an object (``color``)."""

    name: str
    kind: str
    position: Point
    label: str = ""
    color: str | None = None


class OccupancyMap:
    """What a camera saw of a box of the world, voxel by voxel: unknown, seen free, or seen occupied."""

    def __init__(self, lower: Point, upper: Point, resolution: float = 0.5, obstacles: Any = None) -> None:
        self.lower, self.upper, self.resolution = lower, upper, resolution
        self.shape = tuple(max(1, math.ceil((hi - lo) / resolution - 1e-9))
                           for lo, hi in zip(lower, upper, strict=True))
        self.seen_free = np.zeros(self.shape, dtype=bool)
        self.seen_occupied = np.zeros(self.shape, dtype=bool)
        self.solid = solid_voxels(obstacles, lower, self.shape, resolution) if obstacles is not None else None  # type: ignore[arg-type]
        self.landmarks: dict[str, Landmark] = {}
        self.trail: list[Point] = []
        self.scans = 0

    # -- indexing ----------------------------------------------------------------------------------
    def index(self, point: Sequence[float]) -> tuple[int, int, int] | None:
        """The voxel holding ``point``, or None outside the map."""
        ijk = tuple(int(math.floor((p - lo) / self.resolution)) for p, lo in zip(point, self.lower, strict=True))
        if all(0 <= c < n for c, n in zip(ijk, self.shape, strict=True)):
            return ijk  # type: ignore[return-value]
        return None

    def state(self, x: float, y: float) -> int:
        """UNKNOWN, FREE or OCCUPIED of the map column at (x, y) (the top view)."""
        ij = self.index((x, y, self.lower[2]))
        return UNKNOWN if ij is None else int(self.top_view()[ij[0], ij[1]])

    # -- integrating -------------------------------------------------------------------------------
    def scan(self, origin: Sequence[float], yaw: float, camera: CameraModel) -> int:
        """Cast the camera's rays from ``origin``; returns how many ended on a solid. Needs an obstacle map."""
        self.trail.append(tuple(float(v) for v in origin))  # type: ignore[arg-type]
        self.scans += 1
        if self.solid is None:
            return 0
        step = self.resolution / 2.0
        count = max(1, int(camera.range / step))
        t = (np.arange(count) + 0.5) * step
        dirs = camera.rays(yaw)
        points = np.asarray(origin, dtype=float)[None, None, :] + dirs[:, None, :] * t[None, :, None]
        idx = np.floor((points - np.asarray(self.lower)) / self.resolution).astype(int)
        shape = np.asarray(self.shape)
        inside = np.all((idx >= 0) & (idx < shape), axis=2) & (points[:, :, 2] >= 0.0)
        clipped = np.clip(idx, 0, shape - 1)
        solid = self.solid[clipped[..., 0], clipped[..., 1], clipped[..., 2]] & inside
        # a ray ends at its first solid sample, or where it leaves the map or meets the ground
        stop_solid = np.where(solid.any(axis=1), solid.argmax(axis=1), count)
        stop_out = np.where((~inside).any(axis=1), (~inside).argmax(axis=1), count)
        stop = np.minimum(stop_solid, stop_out)
        before = np.arange(count)[None, :] < stop[:, None]
        free = clipped[before]
        self.seen_free[free[:, 0], free[:, 1], free[:, 2]] = True
        hit = stop_solid < stop_out
        rays = np.nonzero(hit)[0]
        cells = clipped[rays, stop_solid[rays]]
        self.seen_occupied[cells[:, 0], cells[:, 1], cells[:, 2]] = True
        return int(hit.sum())

    def observe(self, observations: Sequence[Any]) -> None:
        """Mark what perception recognizes (``name``, ``kind``, ``position``, ``marker_id``, ``color``) occupied."""
        for o in observations:
            position = tuple(float(v) for v in o.position)
            label = str(o.marker_id) if getattr(o, "marker_id", None) is not None else ""
            self.landmarks[o.name] = Landmark(o.name, o.kind, position, label, getattr(o, "color", None))  # type: ignore[arg-type]
            ijk = self.index(position)
            if ijk is not None:
                self.seen_occupied[ijk] = True

    # -- views -------------------------------------------------------------------------------------
    def top_view(self) -> np.ndarray:
        """UNKNOWN / FREE / OCCUPIED per (x, y) column: occupied when anything in it was seen occupied."""
        view = np.full(self.shape[:2], UNKNOWN, dtype=np.uint8)
        view[self.seen_free.any(axis=2)] = FREE
        view[self.seen_occupied.any(axis=2)] = OCCUPIED
        return view

    def height_map(self) -> np.ndarray:
        """The top (m) of what was seen occupied in each column; NaN where nothing was."""
        any_occupied = self.seen_occupied.any(axis=2)
        top = self.shape[2] - 1 - np.argmax(self.seen_occupied[:, :, ::-1], axis=2)
        heights = self.lower[2] + (top + 1) * self.resolution
        return np.where(any_occupied, heights, np.nan)

    def _canvas(self, rgb: np.ndarray, scale: int) -> Image.Image:
        # arrays are x by y; images are rows from north (high y) to south, columns from west to east
        image = Image.fromarray(np.ascontiguousarray(np.transpose(rgb, (1, 0, 2))[::-1]), "RGB")
        return image.resize((image.width * scale, image.height * scale), Image.NEAREST)

    def _pixel(self, x: float, y: float, scale: int) -> tuple[float, float]:
        return ((x - self.lower[0]) / self.resolution * scale,
                (self.lower[1] + self.shape[1] * self.resolution - y) / self.resolution * scale)

    def _decorate(self, image: Image.Image, scale: int) -> Image.Image:
        draw = ImageDraw.Draw(image)
        trail = [self._pixel(p[0], p[1], scale) for p in self.trail]
        if len(trail) > 1:
            draw.line(trail, fill=(30, 90, 230), width=2)
        if trail:
            u, v = trail[-1]
            draw.ellipse([u - 4, v - 4, u + 4, v + 4], fill=(220, 30, 30))
        for mark in self.landmarks.values():
            u, v = self._pixel(mark.position[0], mark.position[1], scale)
            if mark.kind == "marker":
                draw.rectangle([u - 3, v - 3, u + 3, v + 3], fill=(0, 90, 255), outline=(255, 255, 255))
                draw.text((u + 4, v - 11), mark.label, fill=(0, 60, 200))
            else:
                try:
                    color = ImageColor.getrgb(mark.color or "gray")
                except ValueError:
                    color = (200, 0, 200)
                draw.ellipse([u - 4, v - 4, u + 4, v + 4], fill=color, outline=(0, 0, 0))
        return image

    def top_image(self, scale: int = 4) -> Image.Image:
        """The top view as an image (north up, ``scale`` pixels per voxel) with the trail and landmarks."""
        return self._decorate(self._canvas(_SHADES[self.top_view()], scale), scale)

    def height_image(self, scale: int = 4) -> Image.Image:
        """The height map as an image: unknown gray, seen free white, occupied from yellow (low) to red (high)."""
        heights = self.height_map()
        span = max(self.upper[2] - self.lower[2], 1e-6)
        f = np.clip((np.nan_to_num(heights, nan=0.0) - self.lower[2]) / span, 0.0, 1.0)
        rgb = _SHADES[self.top_view()].copy()
        occupied = ~np.isnan(heights)
        ramp = np.stack([np.full_like(f, 230), 220 * (1.0 - f), 40 * (1.0 - f)], axis=2).astype(np.uint8)
        rgb[occupied] = ramp[occupied]
        return self._decorate(self._canvas(rgb, scale), scale)

    def counts(self) -> dict[str, int]:
        """How many columns of the top view are unknown, free and occupied."""
        view = self.top_view()
        return {"unknown": int((view == UNKNOWN).sum()), "free": int((view == FREE).sum()),
                "occupied": int((view == OCCUPIED).sum())}


__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "CameraModel", "Landmark", "OccupancyMap", "solid_voxels"]
