"""The camera component of the simulated MAVLink vehicle (``aeroexec sim --camera``), as a MAVLink camera speaks:
its own heartbeat (component 100, ``MAV_TYPE_CAMERA``), ``MAV_CMD_IMAGE_START_CAPTURE`` acknowledged and answered
with ``CAMERA_IMAGE_CAPTURED`` (the photo is the simulator's camera image, kept in ``images`` and, with a folder, saved
as ``image_N.png``), ``MAV_CMD_REQUEST_MESSAGE`` for ``CAMERA_INFORMATION``. Without it the vehicle has no camera, as
a PX4 or ArduPilot SITL has none."""

from __future__ import annotations

import logging
from pathlib import Path

from pymavlink.dialects.v20 import common as mavlink

logger = logging.getLogger(__name__)

COMPONENT = mavlink.MAV_COMP_ID_CAMERA  # 100
_INFORMATION = mavlink.MAVLINK_MSG_ID_CAMERA_INFORMATION


class CameraComponent:
    """The camera of ``vehicle`` (a :class:`MavlinkVehicle`), writing to ``writer`` (the vehicle's link): ``handle``
    a message addressed to it, ``heartbeat`` once a second."""

    def __init__(self, vehicle, writer, folder: Path | None = None) -> None:
        self._vehicle = vehicle
        self.mav = mavlink.MAVLink(writer, srcSystem=vehicle.system_id, srcComponent=COMPONENT)
        self.folder = folder
        self.images: list[int] = []  # the sizes (bytes) of the photos taken, in order

    def heartbeat(self) -> None:
        self.mav.heartbeat_send(mavlink.MAV_TYPE_CAMERA, mavlink.MAV_AUTOPILOT_INVALID, 0, 0, mavlink.MAV_STATE_ACTIVE)

    def handle(self, msg) -> bool:
        """Act on a message addressed to the camera; False for one it does not take."""
        if msg.get_type() not in ("COMMAND_LONG", "COMMAND_INT"):
            return False
        source = (msg.get_srcSystem(), msg.get_srcComponent())
        command = msg.command
        if command == mavlink.MAV_CMD_IMAGE_START_CAPTURE:
            self._capture(command, source)
        elif command == mavlink.MAV_CMD_REQUEST_MESSAGE and int(msg.param1) == _INFORMATION:
            self._ack(command, mavlink.MAV_RESULT_ACCEPTED, source)
            self.mav.camera_information_send(self._ms(), b"aeroexec".ljust(32, b"\0"), b"simulated".ljust(32, b"\0"),
                                             1, 0.0, 0.0, 640, 480, 0,
                                             mavlink.CAMERA_CAP_FLAGS_CAPTURE_IMAGE, 0, b"")
        else:
            self._ack(command, mavlink.MAV_RESULT_UNSUPPORTED, source)
        return True

    def _capture(self, command: int, source: tuple[int, int]) -> None:
        image = self._vehicle.drone.capture_image()
        if not image:
            self._ack(command, mavlink.MAV_RESULT_FAILED, source)
            return
        self._ack(command, mavlink.MAV_RESULT_ACCEPTED, source)
        self.images.append(len(image))
        index = len(self.images)
        url = b""
        if self.folder is not None:
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
                path = self.folder / f"image_{index}.png"
                path.write_bytes(image)
                url = str(path).encode()[:205]
            except OSError as error:
                logger.warning("the simulated camera could not save image %d: %s", index, error)
        tel = self._vehicle.latest
        lat, lon, alt = self._vehicle.drone.world.to_geodetic(tel.position)
        self.mav.camera_image_captured_send(self._ms(), 0, 0, int(lat * 1e7), int(lon * 1e7), int(alt * 1000),
                                            int(tel.position[2] * 1000), [1.0, 0.0, 0.0, 0.0], index - 1, 1, url)
        logger.info("simulated camera: image %d taken", index)

    def _ack(self, command: int, result: int, source: tuple[int, int]) -> None:
        self.mav.command_ack_send(command, result, 0, 0, source[0], source[1])

    def _ms(self) -> int:
        return int(self._vehicle.latest.time * 1000) & 0xFFFFFFFF


__all__ = ["COMPONENT", "CameraComponent"]
