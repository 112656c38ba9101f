"""The simulated cameras: what markers, objects and platform a drone sees from where it is.

The camera looks along the drone's yaw, tilted by its mounting pitch; a thing is seen when it lies within
both fields of view and the range, with no obstacle in the way. Markers are seen only from their front.
The drone also has a bottom camera looking straight down (:meth:`Camera.downward`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from aeroexec.drones.interface import Observation
from aeroexec.drones.sim.world import CameraSettings, World

Vector = tuple[float, float, float]

_SURFACE_CLEARANCE = 0.05  # m: a line of sight ends this short of its target (markers sit on surfaces)
DOWNWARD_FOV = 80.0  # degrees: the bottom camera's fields of view (with the front one's, no gap below)


def _dot(a: Vector, b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@dataclass(frozen=True)
class Camera:
    """A forward camera: horizontal and vertical fields of view (degrees), range (m), mounting pitch (degrees).

    ``max_marker_angle`` is how obliquely (degrees from its face's normal) a marker can still be read.
    """

    hfov: float = 80.0
    vfov: float = 60.0
    range: float = 12.0
    pitch: float = -20.0
    max_marker_angle: float = 75.0

    @classmethod
    def from_settings(cls, settings: CameraSettings) -> Camera:
        return cls(hfov=settings.hfov, vfov=settings.vfov, range=settings.range, pitch=settings.pitch)

    @classmethod
    def downward(cls, settings: CameraSettings) -> Camera:
        """The bottom camera (looking straight down, ``DOWNWARD_FOV`` wide) that landing and alignment use."""
        return cls(hfov=DOWNWARD_FOV, vfov=DOWNWARD_FOV, range=settings.range, pitch=-90.0)

    def axes(self, yaw: float) -> tuple[Vector, Vector, Vector]:
        """(forward, left, up) unit vectors of the camera on a drone with ``yaw`` degrees."""
        y, p = math.radians(yaw), math.radians(self.pitch)
        forward = (math.cos(p) * math.cos(y), math.cos(p) * math.sin(y), math.sin(p))
        left = (-math.sin(y), math.cos(y), 0.0)
        up = (-math.sin(p) * math.cos(y), -math.sin(p) * math.sin(y), math.cos(p))
        return forward, left, up

    def in_view(self, position: Vector, yaw: float, point: Vector) -> bool:
        """Whether ``point`` is within the fields of view and range (occlusion not considered)."""
        rel = (point[0] - position[0], point[1] - position[1], point[2] - position[2])
        distance = math.sqrt(_dot(rel, rel))
        if distance > self.range or distance < 1e-6:
            return False
        forward, left, up = self.axes(yaw)
        depth = _dot(rel, forward)
        if depth <= 0.0:
            return False
        horizontal = math.degrees(math.atan2(abs(_dot(rel, left)), depth))
        vertical = math.degrees(math.atan2(abs(_dot(rel, up)), depth))
        return horizontal <= self.hfov / 2.0 and vertical <= self.vfov / 2.0

    def visible(self, world: World, position: Vector, yaw: float, point: Vector) -> bool:
        """In view and in sight: no obstacle between the camera and ``point``."""
        if not self.in_view(position, yaw, point):
            return False
        distance = math.dist(position, point)
        f = max(distance - _SURFACE_CLEARANCE, 0.0) / distance
        end = tuple(p + (q - p) * f for p, q in zip(position, point, strict=True))
        return world.segment_clear(position, end)  # type: ignore[arg-type]

    def faces(self, normal: Vector, marker_position: Vector, position: Vector) -> bool:
        """Whether a marker whose face looks along ``normal`` shows its front to ``position``."""
        rel = tuple(p - m for p, m in zip(position, marker_position, strict=True))
        distance = math.sqrt(_dot(rel, rel))  # type: ignore[arg-type]
        if distance < 1e-6:
            return False
        cos_angle = _dot(normal, rel) / distance  # type: ignore[arg-type]
        return cos_angle >= math.cos(math.radians(self.max_marker_angle))

    def observe(self, world: World, position: Vector, yaw: float, time: float) -> list[Observation]:
        """Everything seen from ``position`` with ``yaw`` at ``time``, nearest first."""
        seen: list[Observation] = []
        for marker in world.markers:
            if self.faces(marker.normal, marker.position, position) and self.visible(
                world, position, yaw, marker.position
            ):
                seen.append(Observation("marker", marker.name, marker.position, marker_id=marker.id,
                                        distance=math.dist(position, marker.position)))
        for obj in world.objects:
            if self.visible(world, position, yaw, obj.position):
                seen.append(Observation("object", obj.name, obj.position, color=obj.color, shape=obj.shape,
                                        distance=math.dist(position, obj.position)))
        platform = world.platform
        if platform is not None:
            where = platform.position(time)
            if self.visible(world, position, yaw, where):
                distance = math.dist(position, where)
                seen.append(Observation("object", platform.name, where, shape="platform", distance=distance))
                if platform.marker_id is not None and self.faces((0.0, 0.0, 1.0), where, position):
                    seen.append(Observation("marker", f"marker_{platform.marker_id}", where,
                                            marker_id=platform.marker_id, distance=distance))
        seen.sort(key=lambda o: (o.distance, o.kind, o.name))
        return seen


def merge_observations(*views: list[Observation]) -> list[Observation]:
    """What several cameras see together: each thing once (its nearest sighting), nearest first."""
    best: dict[tuple[str, str], Observation] = {}
    for view in views:
        for o in view:
            key = (o.kind, o.name)
            if key not in best or o.distance < best[key].distance:
                best[key] = o
    return sorted(best.values(), key=lambda o: (o.distance, o.kind, o.name))
