"""Perception (paper Table A.3, "understanding"): capability processes that turn what the camera sees into beliefs,
and the PAY_ATTENTION_TO_* behaviors that activate them.

While VISUAL_MARKERS_RECOGNITION runs, every marker in view gives ``object(marker_N, aruco)`` (and
``object(marker_N, marker)``, the class the paper's queries use),
``code(marker_N, N)``, ``position(marker_N, (x, y, z))`` and ``visible(marker_N)``; colors and shapes
likewise give ``object``, ``color``/``shape``, ``position`` and ``visible``. ``visible`` is retracted
when the thing leaves the view (the paper's null persistence); the rest is remembered.
"""

from __future__ import annotations

import abc

from aeroexec.beliefs import Struct
from aeroexec.drones import Observation
from aeroexec.engine.execution.process import BehaviorProcess
from aeroexec.engine.execution.resources import Process

PERIOD = 0.2  # s between two looks at the camera


class Recognizer(Process, abc.ABC):
    """A detector process: every period, the observations it recognizes become beliefs."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self._visible: dict[str, None] = {}  # in the order seen: replays do not depend on string hashing
        self._last: float | None = None

    @abc.abstractmethod
    def recognizes(self, observation: Observation) -> bool:
        """True for the observations this detector recognizes."""

    @abc.abstractmethod
    def beliefs(self, observation: Observation) -> list[Struct]:
        """What it believes about one of them (position and visibility are added for all)."""

    def step(self, now: float) -> None:
        if self._last is not None and now - self._last < PERIOD - 1e-9:
            return
        self._last = now
        memory = self.context.memory
        seen = [o for o in self.context.drone.observations() if self.recognizes(o)]
        names = dict.fromkeys(o.name for o in seen)
        for observation in seen:
            x, y, z = (round(v, 2) for v in observation.position)
            for belief in (*self.beliefs(observation), Struct("position", (observation.name, (x, y, z))),
                           Struct("visible", (observation.name,))):
                memory.add(belief)
        for gone in [name for name in self._visible if name not in names]:
            memory.remove(Struct("visible", (gone,)))
        self._visible = names

    def on_stop(self) -> None:
        for gone in self._visible:
            self.context.memory.remove(Struct("visible", (gone,)))
        self._visible = {}


class MarkerRecognizer(Recognizer):
    """aruco_detector: ArUco markers in view."""

    def recognizes(self, observation: Observation) -> bool:
        return observation.kind == "marker" and observation.marker_id is not None

    def beliefs(self, observation: Observation) -> list[Struct]:
        name = observation.name
        return [Struct("object", (name, "marker")), Struct("object", (name, "aruco")),
                Struct("code", (name, observation.marker_id))]


class ColorRecognizer(Recognizer):
    """color_detector: colored objects in view."""

    def recognizes(self, observation: Observation) -> bool:
        return observation.kind == "object" and observation.color is not None

    def beliefs(self, observation: Observation) -> list[Struct]:
        return [Struct("object", (observation.name, observation.shape or "thing")),
                Struct("color", (observation.name, observation.color))]


class ShapeRecognizer(Recognizer):
    """shape_detector: shaped objects in view."""

    def recognizes(self, observation: Observation) -> bool:
        return observation.kind == "object" and observation.shape is not None

    def beliefs(self, observation: Observation) -> list[Struct]:
        return [Struct("object", (observation.name, observation.shape)),
                Struct("shape", (observation.name, observation.shape))]


class PayAttention(BehaviorProcess):
    """A recurrent behavior whose work is done by the recognizer its capability runs."""


class PayAttentionToVisualMarkers(PayAttention):
    behavior = "PAY_ATTENTION_TO_VISUAL_MARKERS"


class PayAttentionToColors(PayAttention):
    behavior = "PAY_ATTENTION_TO_COLORS"


class PayAttentionToShapes(PayAttention):
    behavior = "PAY_ATTENTION_TO_SHAPES"


PERCEPTION_BEHAVIORS = [PayAttentionToVisualMarkers, PayAttentionToColors, PayAttentionToShapes]
PERCEPTION_PROCESSES = {"aruco_detector": MarkerRecognizer, "color_detector": ColorRecognizer,
                        "shape_detector": ShapeRecognizer}
