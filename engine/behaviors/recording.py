"""Data recording (paper Table A.3): TAKE_PHOTO, TRIGGER_CAMERA (photos every N meters or seconds), RECORD_VIDEO and
BUILD_MAP, with the ``video_recorder`` and
``map_builder`` capability processes that capture frames and scan the camera's view each period.

Files go to the run's output folder (``context.output_dir``; without one, ``aeroexec_output/<date-time>`` in the
working directory, chosen on first use): ``photo_N.png``, ``video_N/frame_NNNNN.png`` and ``video_N.gif``,
``map_N.png`` (and ``map_N_height.png`` for a 3D map). Beliefs: ``photo(self, File)``, ``video(self, File)``,
``map(self, File)``. A photo that cannot be written (a full disk) is not a failed behavior: what was written of it
is removed, the first is logged (``photo_not_saved``), and TAKE_PHOTO and TRIGGER_CAMERA go on, so a survey flies
on and lands as usual (the run then exits 6, its record incomplete). The recordings in progress live on the
behavior context, so the behavior (which opens and closes them) and its capability's process (which does the
periodic work) share them.

Settings read from ``EngineSettings.extra``: ``video_rate`` (frames per second, 2.0), ``video_gif_frames``
(most frames kept for the GIF, 240), ``map_resolution`` (m, 0.5), ``map_period`` (s between scans, 0.5),
``map_save_period`` (s between saves while building, 10.0), ``map_extent`` (m around home without map bounds, 50).
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from aeroexec.beliefs import Struct
from aeroexec.drones.interface import CAMERA_IMAGES, CAMERA_NONE, CAMERA_VEHICLE, CommandHandle
from aeroexec.engine.behaviors.manipulation import MANIPULATION_BEHAVIORS, MANIPULATION_PROCESSES
from aeroexec.engine.events import Outcome
from aeroexec.engine.execution.process import BehaviorContext, BehaviorProcess
from aeroexec.engine.execution.resources import Process
from aeroexec.engine.planning.path_planner import map_bounds
from aeroexec.engine.supervision.output import choose_output_folder

if TYPE_CHECKING:  # the map needs numpy, the thumbnails Pillow: imported when first used
    from aeroexec.engine.planning.mapping import OccupancyMap
    from PIL import Image

logger = logging.getLogger(__name__)

NO_IMAGE = "the drone gives no camera image (it has no camera this engine can read)"
GIF_SIZE = (320, 240)  # the GIF's frames are shrunk to fit this


def output_folder(context: BehaviorContext) -> Path:
    """The run's output folder, created if needed; chosen (and kept on the context) on first use without one."""
    if context.output_dir is None:
        context.output_dir = choose_output_folder()
        context.log.record("output_folder", detail=f"recordings go to {context.output_dir}")
    folder = Path(context.output_dir)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def next_path(folder: Path, stem: str, suffix: str) -> Path:
    """``folder/stem_N<suffix>`` with the first N (from 1) not taken by a file or a folder of that name."""
    n = 1
    while (folder / f"{stem}_{n}{suffix}").exists() or (folder / f"{stem}_{n}").exists():
        n += 1
    return folder / f"{stem}_{n}{suffix}"


def capture(context: BehaviorContext) -> tuple[bytes | None, str]:
    """The camera's image now (a PNG), or None and why not; a camera that raises is a camera that failed."""
    try:
        image = context.drone.capture_image()
    except Exception as exc:
        logger.exception("capture_image failed")
        return None, f"the camera failed: {type(exc).__name__}: {exc}"
    return (image, "") if image else (None, NO_IMAGE)


def _extra(context: BehaviorContext, key: str, default: float) -> float:
    return float(context.settings.extra.get(key, default))


def take_photo(process: BehaviorProcess) -> str:
    """The camera's image now saved as ``photo_N.png`` (``photo(self, File)``, a ``photo_taken`` event): why not,
    or "" when it was taken."""
    image, error = capture(process.context)
    if image is None:
        return error
    path: Path | None = None
    try:
        path = next_path(output_folder(process.context), "photo", ".png")
        path.write_bytes(image)
    except OSError as error:  # a full disk: the photo is lost, the flight goes on
        not_saved(process, path, error)
        return ""
    process.result = str(path)
    process.memory.add(Struct("photo", ("self", str(path))))
    process.context.log.record("photo_taken", process.name, str(path), bytes=len(image))
    return ""


def not_saved(process: BehaviorProcess, path: Path | None, error: OSError) -> None:
    """A photo that could not be written (a full disk): what was written of it is removed, the first is logged
    (``photo_not_saved``), the rest counted; the behavior goes on, so the flight goes on and lands as usual."""
    if path is not None:
        with contextlib.suppress(OSError):
            path.unlink(missing_ok=True)
    found = recordings(process.context)
    found.unsaved_photos += 1
    if found.unsaved_photos == 1:
        why = error.strerror or str(error)
        logger.warning("a photo could not be saved (%s): the flight goes on", why)
        process.context.log.record("photo_not_saved", process.name, f"the photo could not be saved ({why}): the "
                                   f"flight goes on; photos that cannot be saved are not logged again", error=why,
                                   file=str(path) if path is not None else None)


def camera_of(context: BehaviorContext) -> str:
    """Where the drone's photos come from (``Robot.photo_source``): its images, its own camera, or none."""
    source = getattr(context.drone, "photo_source", None)
    return source() if callable(source) else CAMERA_IMAGES


def skip_photo(process: BehaviorProcess) -> None:
    """A photo asked of a vehicle without a camera: skipped, the mission goes on; said once per activation
    (``photo_skipped``), counted in ``skipped``."""
    process.skipped = getattr(process, "skipped", 0) + 1
    if process.skipped == 1:
        process.context.log.record("photo_skipped", process.name, "the vehicle has no camera: the photo is skipped "
                                   "and the mission goes on (further photos of this behavior are skipped unsaid)")


def vehicle_photo(process: BehaviorProcess, handle: CommandHandle) -> str:
    """A photo the vehicle's camera was asked for, once its handle is done: said (``photo_taken``, ``photo(self,
    vehicle:N)``) and "", or why it was not taken."""
    if not handle.ok:
        return f"the vehicle's camera did not take the photo: {handle.reason}"
    found = recordings(process.context)
    found.vehicle_photos += 1
    name = f"vehicle:{found.vehicle_photos}"
    process.result = name
    process.memory.add(Struct("photo", ("self", name)))
    process.context.log.record("photo_taken", process.name, f"photo {found.vehicle_photos} taken by the vehicle's "
                               f"camera (kept on the vehicle)", camera="vehicle")
    return ""


class TakePhoto(BehaviorProcess):
    """TAKE_PHOTO: the camera's image now, as ``photo_N.png``; result and ``photo(self, File)`` name the file. A photo
    that cannot be saved (a full disk) is logged once and its goal is achieved without a file: the flight goes on.
    On a vehicle with its own camera (a MAVSDK vehicle's camera component) the vehicle takes it (``vehicle:N``); on
    one without a camera the photo is skipped, said in the log."""

    behavior = "TAKE_PHOTO"

    def on_start(self) -> None:
        self._error, self._handle = "", None
        camera = camera_of(self.context)
        if camera == CAMERA_NONE:
            skip_photo(self)
        elif camera == CAMERA_VEHICLE:
            self._handle = self.drone.take_photo()
        else:
            self._error = take_photo(self)

    def on_run(self) -> Outcome | None:
        if self._handle is not None:
            if not self._handle.done:
                return None
            self._error, self._handle = vehicle_photo(self, self._handle), None
        return self.fail(self._error) if self._error else Outcome.GOAL_ACHIEVED


class TriggerCamera(BehaviorProcess):
    """TRIGGER_CAMERA: a photo every DISTANCE meters the drone flies (or every INTERVAL seconds) until stopped, at
    most COUNT of them; the first when it starts counting. A photo the camera cannot take fails it. A vehicle with its
    own camera takes them (MAV_CMD_IMAGE_START_CAPTURE each time the distance is flown); one without skips them."""

    behavior = "TRIGGER_CAMERA"

    def on_start(self) -> None:
        self.camera = camera_of(self.context)
        self.pending: list[CommandHandle] = []  # photos asked of the vehicle's camera, not yet answered
        self.distance = self.arguments.get("DISTANCE")
        self.interval = self.arguments.get("INTERVAL")
        self.count = self.arguments.get("COUNT")
        self.taken = 0
        self.last = self.drone.telemetry().position
        self.travelled = 0.0
        self.shot_at = self.now()

    def on_run(self) -> Outcome | None:
        for handle in [h for h in self.pending if h.done]:  # the vehicle's camera answered
            self.pending.remove(handle)
            error = vehicle_photo(self, handle)
            if error:
                return self.fail(error)
        if self.count is not None and self.taken >= self.count:
            return None
        due = False
        if self.distance is not None:
            position = self.drone.telemetry().position
            self.travelled += math.dist(position, self.last)
            self.last = position
            due = self.travelled >= float(self.distance)
        elif self.now() - self.shot_at >= float(self.interval) - 1e-9:
            due = True
        if not due:
            return None
        self.travelled, self.shot_at = 0.0, self.now()
        if self.camera == CAMERA_NONE:
            skip_photo(self)
        elif self.camera == CAMERA_VEHICLE:
            self.pending.append(self.drone.take_photo())
        else:
            error = take_photo(self)
            if error:
                return self.fail(error)
        self.taken += 1
        return None

    def on_stop(self, outcome: Outcome) -> None:
        """The photos the vehicle's camera answered by now are said (``photo_taken``); those asked and still
        unanswered when the behavior stops (a halt while a reply is on the way: the vehicle may take them) are said
        once, with their number (``photo_unanswered``), never dropped unsaid."""
        for handle in [h for h in self.pending if h.done]:
            self.pending.remove(handle)
            vehicle_photo(self, handle)  # a refusal now fails nothing: the behavior has ended
        if self.pending:
            count = len(self.pending)
            self.context.log.record("photo_unanswered", self.name,
                                    f"{count} photo{'s' if count != 1 else ''} asked of the vehicle's camera had no "
                                    f"answer when {self.name} stopped: the vehicle may have taken "
                                    f"{'them' if count != 1 else 'it'}", count=count, camera="vehicle")
            self.pending.clear()


# --- video -------------------------------------------------------------------------------------------------

class VideoRecording:
    """One video: every frame as a PNG in ``video_N/``, and shrunk copies for ``video_N.gif`` written at the end.

    When more than ``gif_frames`` frames are kept, every other one is dropped and only every other one is kept
    from then on, so a long recording gives a GIF of bounded size covering all of it.
    """

    def __init__(self, folder: Path, period: float, gif_frames: int) -> None:
        self.gif = next_path(folder, "video", ".gif")
        self.folder = self.gif.with_suffix("")
        self.folder.mkdir(parents=True, exist_ok=True)
        self.period = period
        self.gif_frames = max(2, gif_frames)
        self.frames = 0
        self.missed = 0  # captures that gave no image
        self._thumbs: list[Image.Image] = []  # Pillow is imported when a picture is first taken
        self._stride = 1
        self._last: float | None = None

    def due(self, now: float) -> bool:
        return self._last is None or now - self._last >= self.period - 1e-9

    def capture(self, image: bytes | None, now: float) -> None:
        """Keep one frame (``image`` is a PNG, or None when the camera gave nothing)."""
        self._last = now
        if not image:
            self.missed += 1
            return
        self.missed = 0
        self.frames += 1
        (self.folder / f"frame_{self.frames:05d}.png").write_bytes(image)
        if (self.frames - 1) % self._stride:
            return
        from PIL import Image

        thumb = Image.open(io.BytesIO(image)).convert("RGB")
        thumb.thumbnail(GIF_SIZE)
        self._thumbs.append(thumb.quantize(colors=128))
        if len(self._thumbs) > self.gif_frames:
            self._thumbs = self._thumbs[::2]
            self._stride *= 2

    def finish(self) -> Path | None:
        """Write the GIF; None when no frame was captured."""
        if not self._thumbs:
            return None
        duration = max(20, round(self.period * self._stride * 1000))
        first, rest = self._thumbs[0], self._thumbs[1:]
        first.save(self.gif, save_all=True, append_images=rest, duration=duration, loop=0)
        self._thumbs = []
        return self.gif


@dataclass
class Recordings:
    """What is being recorded in a run: the open video, and the map being built (kept between activations)."""

    video: VideoRecording | None = None
    map: OccupancyMap | None = None
    map_file: Path | None = None  # where the map of the active BUILD_MAP is saved
    map_dimension: str = "THREE"
    unsaved_photos: int = 0  # photos that could not be written (a full disk)
    vehicle_photos: int = 0  # photos the vehicle's own camera took
    map_saved_at: float | None = None


def recordings(context: BehaviorContext) -> Recordings:
    """The run's recordings, created on first use and kept on the behavior context."""
    found = getattr(context, "recordings", None)
    if found is None:
        found = Recordings()
        context.recordings = found  # type: ignore[attr-defined]
    return found


class RecordVideo(BehaviorProcess):
    """RECORD_VIDEO: frames while active (``video_recorder`` captures them), ``video_N.gif`` when stopped."""

    behavior = "RECORD_VIDEO"

    def on_start(self) -> None:
        image, self._error = capture(self.context)
        if image is None:
            return
        rate = _extra(self.context, "video_rate", 2.0)
        video = VideoRecording(output_folder(self.context), 1.0 / max(rate, 1e-3),
                               int(_extra(self.context, "video_gif_frames", 240)))
        video.capture(image, self.now())
        recordings(self.context).video = video
        self.context.log.record("video_started", self.name, str(video.folder), rate=rate)

    def on_run(self) -> Outcome | None:
        if self._error:
            return self.fail(self._error)
        video = recordings(self.context).video
        if video is not None and video.missed >= 3:
            return self.fail("the camera stopped giving images")
        return None

    def on_stop(self, outcome: Outcome) -> None:
        store = recordings(self.context)
        video, store.video = store.video, None
        if video is None:
            return
        gif = video.finish()
        if gif is not None:
            self.result = str(gif)
            self.memory.add(Struct("video", ("self", str(gif))))
        self.context.log.record("video_saved", self.name, str(gif or video.folder), frames=video.frames)


class VideoRecorder(Process):
    """video_recorder: while a video is open, a camera frame every period."""

    def step(self, now: float) -> None:
        video = recordings(self.context).video
        if video is not None and video.due(now):
            video.capture(capture(self.context)[0], now)


# --- map ---------------------------------------------------------------------------------------------------

def new_map(context: BehaviorContext) -> OccupancyMap:
    """An empty map of the obstacle map's bounds (or ``map_extent`` m around home) at ``map_resolution``."""
    resolution = _extra(context, "map_resolution", 0.5)
    bounds = map_bounds(context.obstacles) if context.obstacles is not None else None
    if bounds is None:
        extent = _extra(context, "map_extent", 50.0)
        bounds = ((-extent, -extent, 0.0), (extent, extent, min(extent, 30.0)))
    from aeroexec.engine.planning.mapping import OccupancyMap

    return OccupancyMap(bounds[0], bounds[1], resolution, context.obstacles)


def save_map(context: BehaviorContext, store: Recordings, now: float) -> None:
    """Write the map's images and believe ``map(self, File)``."""
    if store.map is None or store.map_file is None:
        return
    store.map.top_image().save(store.map_file)
    if store.map_dimension == "THREE":
        store.map.height_image().save(store.map_file.with_name(store.map_file.stem + "_height.png"))
    store.map_saved_at = now
    context.memory.add(Struct("map", ("self", str(store.map_file))))
    context.log.record("map_saved", "BUILD_MAP", str(store.map_file), scans=store.map.scans, **store.map.counts())


class BuildMap(BehaviorProcess):
    """BUILD_MAP: the occupancy map of what the camera sees (``map_builder`` scans), saved now and then and on stop."""

    behavior = "BUILD_MAP"

    def on_start(self) -> None:
        store = recordings(self.context)
        if store.map is None:
            store.map = new_map(self.context)
        store.map_dimension = str(self.arguments.get("DIMENSION", "THREE")).upper()
        store.map_file = next_path(output_folder(self.context), "map", ".png")
        store.map_saved_at = self.now()
        MapBuilder.integrate(self.context, store.map)
        self.context.log.record("map_started", self.name, str(store.map_file), dimension=store.map_dimension)

    def on_stop(self, outcome: Outcome) -> None:
        store = recordings(self.context)
        save_map(self.context, store, self.now())
        self.result = str(store.map_file) if store.map_file else None
        store.map_file = None


class MapBuilder(Process):
    """map_builder: while a map is being built, a scan of the camera's view every period, and periodic saves."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self._last: float | None = None

    @staticmethod
    def integrate(context: BehaviorContext, occupancy: OccupancyMap) -> None:
        """One look: what perception sees becomes landmarks, and the camera's rays are cast through the world."""
        telemetry = context.drone.telemetry()
        occupancy.observe(context.drone.observations())
        from aeroexec.engine.planning.mapping import CameraModel

        camera = CameraModel.of(getattr(context.obstacles, "camera", None))
        occupancy.scan(telemetry.position, telemetry.yaw, camera)

    def step(self, now: float) -> None:
        store = recordings(self.context)
        if store.map is None or store.map_file is None:
            return
        if self._last is not None and now - self._last < _extra(self.context, "map_period", 0.5) - 1e-9:
            return
        self._last = now
        self.integrate(self.context, store.map)
        period = _extra(self.context, "map_save_period", 10.0)
        if store.map_saved_at is None or now - store.map_saved_at >= period - 1e-9:
            save_map(self.context, store, now)


RECORDING_BEHAVIORS: list[type[BehaviorProcess]] = [TakePhoto, TriggerCamera, RecordVideo, BuildMap,
                                                     *MANIPULATION_BEHAVIORS]
RECORDING_PROCESSES: dict[str, Callable[[str], Process]] = {"video_recorder": VideoRecorder,
                                                            "map_builder": MapBuilder, **MANIPULATION_PROCESSES}

__all__ = ["RECORDING_BEHAVIORS", "RECORDING_PROCESSES", "Recordings", "output_folder", "recordings"]
