"""The DO_ and CONDITION_ items of a mission as behaviors: settings the flights after them take (a speed, a point to
look at), conditions (a delay, a yaw, a change of altitude, a distance before the next waypoint), DO_JUMP, and the
behaviors that run beside the items (a camera triggered every N meters or seconds, a video). A mixin of the item
converter (:mod:`aeroexec.trees.items.behaviors`), which places the items and builds the nodes.
"""

from __future__ import annotations

import math

from aeroexec.drones.angles import wrap180
from aeroexec.engine.errors import WRONG_VALUE
from aeroexec.trees.items.model import MissionItem
from aeroexec.trees.items.structure import Jump, Span, Step
from aeroexec.trees.model import TreeNode


def text(*values: float) -> str:
    """Numbers as port text: two decimals at most, no trailing zeros (``"10, -5.25, 0"``)."""

    def one(value: float) -> str:
        written = f"{value:.2f}".rstrip("0").rstrip(".")
        return "0" if written in ("-0", "") else written

    return ", ".join(one(v) for v in values)


class CommandItems:
    """The handlers of the DO_ and CONDITION_ items (``_<name>``), on the converter's state."""

    def _condition_delay(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self.node("WAIT", item, "delay", DURATION=text(max(params[0], 0.0)))

    def _condition_change_alt(self, item: MissionItem, params: tuple[float, ...]) -> None:
        alt = self.altitude(item)
        if alt is not None and self.position is not None:
            self.go_to(item, "change altitude", self.here(alt))

    def _condition_distance(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[0] > 0:
            self.distance_before = params[0]

    def _condition_yaw(self, item: MissionItem, params: tuple[float, ...]) -> None:
        angle, relative = params[0], params[3] != 0
        if math.isnan(angle):
            self.problem(item, "CONDITION_YAW without an angle (param1)")
            return
        if relative:
            turn = math.fmod(angle, 360.0) * (-1.0 if params[2] >= 0 else 1.0)  # MAVLink: clockwise positive
            self.node("ROTATE", item, "yaw", RELATIVE_ANGLE=text(turn))
        else:
            self.node("ROTATE", item, "yaw", ANGLE=text(wrap180(90.0 - angle)))

    def _do_jump(self, item: MissionItem, params: tuple[float, ...]) -> None:
        target = int(params[0]) if not math.isnan(params[0]) else -1
        target = self.jump_ids.get(target, target) if self.jump_ids else target
        repeat = int(params[1]) if not math.isnan(params[1]) else 0
        self.entries.append(Jump(item.seq, target, repeat, item.line))

    def _do_change_speed(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[0] in (2, 3):
            self.problem(item, "DO_CHANGE_SPEED of the climb or descent rate: the vehicle keeps its own",
                         severity="warning")
        elif params[1] == -2 or params[1] == 0 and self.mission.ardupilot:
            self.speed = None
        elif params[1] > 0:
            self.speed = params[1]
        elif params[1] != -1:
            self.problem(item, f"DO_CHANGE_SPEED to {text(params[1])} m/s", kind=WRONG_VALUE)

    def _do_set_roi_location(self, item: MissionItem, params: tuple[float, ...]) -> None:
        where = self.place(item)
        if where is None:
            self.problem(item, f"{item.name} without a latitude and longitude")
        if not where:
            return
        self.roi = where[1]
        if self.position is not None:
            self.node("LOOK_AT_A_POINT", item, item.name.removeprefix("DO_"), COORDINATES=where[1])

    def _do_set_roi(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if self.mission.ardupilot:  # ArduPilot reads the location: a place is where to look, none is no ROI
            if item.has_position():
                self._do_set_roi_location(item, params)
            else:
                self.roi = None
        elif params[0] == 3:
            self._do_set_roi_location(item, params)
        elif params[0] == 0:
            self.roi = None
        else:
            self.problem(item, f"DO_SET_ROI in MAV_ROI mode {params[0]:g}: only a location (3) or none (0) has a "
                               f"behavior")

    def _nav_roi(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self._do_set_roi(item, params)

    def _do_set_roi_none(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self.roi = None

    def _do_digicam_control(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[4] == 1:
            self.node("TAKE_PHOTO", item, "photo")
        else:
            self.problem(item, "DO_DIGICAM_CONTROL without a shot (param5 is not 1): nothing to do",
                         severity="warning")

    def span(self, item: MissionItem, key: str, behavior: str | None, **ports: str) -> None:
        node = None if behavior is None else TreeNode(behavior, f"item {item.seq} {behavior}", dict(ports), [],
                                                      self.file, item.line)
        if self.nodes:
            self.emit(Step(item.seq, self.nodes), item)
            self.nodes = []
        self.emit(Span(item.seq, key, node, item.line), item)

    def _do_set_cam_trigg_dist(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[2] == 1:
            self.node("TAKE_PHOTO", item, "photo")
        if params[0] > 0:
            self.span(item, "camera", "TRIGGER_CAMERA", DISTANCE=text(params[0]))
        else:
            self.span(item, "camera", None)

    def _do_set_cam_trigg_interval(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[0] > 0:
            self.span(item, "camera", "TRIGGER_CAMERA", INTERVAL=text(params[0] / 1000.0))
        else:
            self.span(item, "camera", None)

    def _image_start_capture(self, item: MissionItem, params: tuple[float, ...]) -> None:
        interval, count = params[1], params[2]
        if count == 1 or not interval > 0:
            self.node("TAKE_PHOTO", item, "photo")
        else:
            ports = {"INTERVAL": text(interval)} | ({"COUNT": text(count)} if count > 1 else {})
            self.span(item, "camera", "TRIGGER_CAMERA", **ports)

    def _image_stop_capture(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self.span(item, "camera", None)

    def _video_start_capture(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self.span(item, "video", "RECORD_VIDEO")

    def _video_stop_capture(self, item: MissionItem, params: tuple[float, ...]) -> None:
        self.span(item, "video", None)

    def _do_gripper(self, item: MissionItem, params: tuple[float, ...]) -> None:
        if params[1] == 0:
            self.node("DROP_ITEM", item, "release")
        else:
            self.problem(item, "DO_GRIPPER grab: the simulated gripper holds its payload from the start",
                         severity="warning")
