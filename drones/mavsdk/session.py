"""The MAVSDK adapter's I/O side: one thread and asyncio loop owning the mavsdk 4.1 native instance.

It connects, discovers the autopilot, asks for telemetry rates, feeds subscriptions into the latest-value
cache, watches the link, and runs commands as tasks whose outcome completes a :class:`CommandHandle`.
Every MAVSDK call goes through :meth:`MavsdkSession.call`: it is shielded and tracked, so cancelling or timing
out a command never abandons a call in flight, and shutdown destroys MAVSDK only after such calls returned.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import json
import logging
import math
import threading
import time
from collections.abc import Awaitable, Callable, Coroutine
from typing import Any

from aeroexec.drones.interface import CommandHandle, Failure
from aeroexec.drones.mavsdk.connection import (
    TelemetryRates,
    check_url,
    copter_mode_of,
    flight_mode_name,
    forward_native_log,
    landed_state,
)
from aeroexec.drones.mavsdk.errors import AdapterError, describe_failure
from aeroexec.drones.mavsdk.telemetry_cache import TelemetryCache
from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.mavlink_direct import MavlinkDirectAsync
from mavsdk.asyncio.plugins.offboard import OffboardAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync

logger = logging.getLogger(__name__)

MAV_TYPE_CAMERA = 30  # a HEARTBEAT's type: the component is a camera

_WATCHDOG_PERIOD = 0.1  # s between two link checks
_DRAIN_LIMIT = 30.0  # s a shutdown waits for MAVSDK calls still in flight (MAVSDK bounds them itself)
_RATE_RETRY = 5.0  # s without health or position reports before the rates are asked for again

Body = Callable[[], Coroutine[Any, Any, None]]


class MavsdkSession:
    """Owns the MAVSDK instance and its loop thread. Thread-safe: commands come from any thread."""

    def __init__(self, url: str, *, clock: Callable[[], float], rates: TelemetryRates, link_timeout: float) -> None:
        self.url = check_url(url)
        self.cache = TelemetryCache(clock, link_timeout)
        self.rates = rates
        self.link_timeout = link_timeout
        self.error: str | None = None  # why the connection could not be opened
        self.ardupilot = False
        self.system_id = 1  # the autopilot's MAVLink system id, once found
        self.action: ActionAsync | None = None
        self.telemetry: TelemetryAsync | None = None
        self.offboard: OffboardAsync | None = None
        self.direct: MavlinkDirectAsync | None = None
        self._loop = asyncio.new_event_loop()
        self._executor = concurrent.futures.ThreadPoolExecutor(8, thread_name_prefix="aeroexec-mavsdk-call")
        self._loop.set_default_executor(self._executor)
        self._thread = threading.Thread(target=self._run, name="aeroexec-mavsdk", daemon=True)
        self._lock = threading.Lock()
        self._pending: dict[CommandHandle, asyncio.Task | None] = {}
        self._closing = False
        self._closed = threading.Event()
        self._in_flight: set[asyncio.Future] = set()
        self._tasks: set[asyncio.Task] = set()
        # asyncio primitives bind to the loop on first use (Python >= 3.10), which is the adapter's.
        self._stop = asyncio.Event()
        self._found = asyncio.Event()
        self._commands = asyncio.Lock()

    # --- any thread ----------------------------------------------------------------------------------
    def start(self) -> None:
        forward_native_log()
        self._thread.start()

    def submit(self, name: str, body: Body, timeout: float) -> CommandHandle:
        """Run ``body`` (a coroutine function using :meth:`call`) on the loop; its handle completes with it."""
        handle = CommandHandle(name)
        if self._closing:
            handle.fail(Failure.CANCELLED, f"{name} cancelled: the drone was closed")
        elif self.error is not None:
            handle.fail(Failure.LINK_LOST, f"{name} failed: {self.error}")
        elif self.cache.connected and not self.cache.link_ok:
            handle.fail(Failure.LINK_LOST, f"{name} failed: the link to the vehicle is down")
        if handle.done:
            return handle
        with self._lock:
            self._pending[handle] = None
        try:
            self._loop.call_soon_threadsafe(self._start_command, handle, body, timeout)
        except RuntimeError:  # the loop is already closed
            self._finish(handle, Failure.CANCELLED, f"{name} cancelled: the drone was closed")
        return handle

    def wait_ready(self, timeout: float) -> bool:
        """Block until the vehicle is connected, armable, with global and home positions; False on timeout."""
        deadline = time.monotonic() + timeout
        while not (self.cache.link_ok and self.cache.ready()):
            if self.error is not None or self._closing or time.monotonic() >= deadline:
                return False
            time.sleep(0.05)
        return True

    def close(self, timeout: float) -> None:
        """Fail pending commands, stop the loop thread; returns within about ``timeout`` seconds.

        If a MAVSDK call is still in flight then, the thread finishes the shutdown on its own once it returns.
        """
        if not self._closing:
            self._closing = True
            for handle in self._pending_handles():
                self._finish(handle, Failure.CANCELLED, f"{handle.command} cancelled: the drone was closed")
            if self._thread.is_alive():
                with contextlib.suppress(RuntimeError):
                    self._loop.call_soon_threadsafe(self._request_stop)
        if self._thread.ident is None:  # never started
            self._loop.close()
            self._executor.shutdown(wait=False)
            self._closed.set()
        elif self._thread.is_alive():
            self._thread.join(timeout)
            if self._thread.is_alive():
                logger.warning("MAVSDK calls still in flight: the adapter thread will finish closing on its own")

    @property
    def closed(self) -> bool:
        return self._closed.is_set()

    # --- loop side -----------------------------------------------------------------------------------
    async def call(self, awaitable: Awaitable) -> Any:
        """Await one MAVSDK call; cancelling the caller leaves the call running, tracked until it returns."""
        future = asyncio.ensure_future(awaitable)
        self._in_flight.add(future)
        future.add_done_callback(self._call_done)
        return await asyncio.shield(future)

    def _call_done(self, future: asyncio.Future) -> None:
        self._in_flight.discard(future)
        if not future.cancelled() and future.exception() is not None:
            logger.debug("MAVSDK call ended with %r", future.exception())

    async def wait_until(self, predicate: Callable[[], bool], timeout: float) -> bool:
        """Poll ``predicate`` until true or ``timeout`` seconds pass."""
        deadline = self._loop.time() + timeout
        while not predicate():
            if self._loop.time() >= deadline:
                return False
            await asyncio.sleep(0.05)
        return True

    def _pending_handles(self) -> list[CommandHandle]:
        with self._lock:
            return list(self._pending)

    def _finish(self, handle: CommandHandle, failure: Failure | None, reason: str = "") -> None:
        with self._lock:
            task = self._pending.pop(handle, None)
        if failure is None:
            handle.succeed()
        else:
            handle.fail(failure, reason)
        if task is not None and not task.done() and failure is not None:
            with contextlib.suppress(RuntimeError):
                task.get_loop().call_soon_threadsafe(task.cancel)

    def spawn(self, coro: Coroutine) -> asyncio.Task:
        task = self._loop.create_task(coro)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)
        return task

    def _start_command(self, handle: CommandHandle, body: Body, timeout: float) -> None:
        if handle.done:
            return
        task = self.spawn(self._execute(handle, body, timeout))
        with self._lock:
            if handle in self._pending:
                self._pending[handle] = task

    async def _execute(self, handle: CommandHandle, body: Body, timeout: float) -> None:
        name = handle.command
        try:
            async with asyncio.timeout(timeout):
                if not await self.wait_until(lambda: self._found.is_set() or self.error is not None, timeout):
                    raise AdapterError(Failure.LINK_LOST, "no vehicle connected")
                if self.error is not None:
                    raise AdapterError(Failure.LINK_LOST, self.error)
                async with self._commands:  # one command at a time, in the order they were given
                    await body()
        except asyncio.CancelledError:  # failed elsewhere (link lost, closed): the handle says why
            if not handle.done:
                self._finish(handle, Failure.CANCELLED, f"{name} cancelled")
        except TimeoutError:
            failure = Failure.TIMEOUT if self.cache.link_ok else Failure.LINK_LOST
            self._finish(handle, failure, f"{name} failed: not done within {timeout:g} s")
        except Exception as exc:  # every failure becomes the handle's, with a sentence
            failure, reason = describe_failure(name, exc, self.cache.link_ok, self.cache.recent_status_text())
            logger.info("%s", reason)
            self._finish(handle, failure, reason)
        else:
            self._finish(handle, None)

    def _request_stop(self) -> None:
        self._stop.set()

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        try:
            self._loop.run_until_complete(self._main())
        except Exception:
            logger.exception("the MAVSDK adapter loop failed")
        finally:
            try:
                self._loop.run_until_complete(self._loop.shutdown_asyncgens())
            finally:
                self._loop.close()
                self._executor.shutdown(wait=False)
                self._closed.set()

    async def _main(self) -> None:
        if self._closing:
            return
        mavsdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
        try:
            self.spawn(self._connect(mavsdk))
            await self._stop.wait()
        finally:
            await self._shutdown(mavsdk)

    async def _connect(self, mavsdk: Mavsdk) -> None:
        try:
            await self.call(mavsdk.add_any_connection(self.url))
        except Exception as exc:
            self.error = f"cannot open the connection {self.url}: {exc}"
            logger.error("%s", self.error)
            self.cache.add_event("link_lost", self.error)
            for handle in self._pending_handles():
                self._finish(handle, Failure.LINK_LOST, f"{handle.command} failed: {self.error}")
            return
        logger.info("MAVSDK listening on %s", self.url)
        system = None
        while system is None:
            system = await mavsdk.first_autopilot(timeout_s=1.0)
        self.ardupilot = (await system.autopilot_type()).name == "ARDUPILOT"
        self.system_id = int(await system.get_system_id())
        self.action, self.telemetry, self.offboard = ActionAsync(system), TelemetryAsync(system), OffboardAsync(system)
        self.direct = MavlinkDirectAsync(system)
        logger.info("autopilot found on %s (%s)", self.url, "ArduPilot" if self.ardupilot else "PX4 or other")
        self.cache.set_connected(True)
        self._subscribe(system, self.telemetry)
        self.spawn(self._watchdog())
        self.spawn(self._request_rates(self.telemetry))
        self._found.set()

    def _subscribe(self, system, telemetry: TelemetryAsync) -> None:
        cache, ardupilot = self.cache, self.ardupilot

        def position(p):
            if math.isfinite(p.latitude_deg) and math.isfinite(p.longitude_deg):
                cache.set(position=(p.latitude_deg, p.longitude_deg, p.absolute_altitude_m))

        def home(h):
            if math.isfinite(h.latitude_deg) and math.isfinite(h.longitude_deg):
                cache.set(home=(h.latitude_deg, h.longitude_deg, h.absolute_altitude_m))

        def battery(b):
            percent = b.remaining_percent if math.isfinite(b.remaining_percent) else cache.battery[0]
            volts = b.voltage_v if math.isfinite(b.voltage_v) else cache.battery[1]
            cache.set(battery=(percent, volts))

        def accuracy(g):  # GPS_RAW_INT's h_acc: how far the vehicle's own position may be off
            h = g.horizontal_uncertainty_m
            cache.set(position_accuracy=round(float(h), 2) if math.isfinite(h) and 0 < h < 1e4 else None)

        def heartbeat(message):
            try:
                fields = json.loads(message.fields_json or "{}")
                mode = copter_mode_of(fields) if ardupilot else None
            except (ValueError, TypeError, AttributeError):
                return
            if fields.get("type") == MAV_TYPE_CAMERA and cache.camera_component is None:
                cache.set(camera_component=int(message.component_id))
                logger.info("the vehicle has a camera (component %d)", message.component_id)
            if mode is not None:
                cache.set(flight_mode=mode)

        def health(h):
            cache.set(
                armable=h.is_armable, global_position_ok=h.is_global_position_ok, home_position_ok=h.is_home_position_ok
            )

        streams = [
            (telemetry.subscribe_position(), position),
            (telemetry.subscribe_home(), home),
            (
                telemetry.subscribe_velocity_ned(),
                lambda v: cache.set(velocity_ned=(v.north_m_s, v.east_m_s, v.down_m_s)),
            ),
            (
                telemetry.subscribe_attitude_euler(),
                lambda a: cache.set(heading=a.yaw_deg) if math.isfinite(a.yaw_deg) else None,
            ),
            (telemetry.subscribe_battery(), battery),
            (telemetry.subscribe_armed(), lambda armed: cache.set(armed=armed)),
            (telemetry.subscribe_landed_state(), lambda s: cache.set(landed_state=landed_state(s))),
            # a camera's heartbeat; an ArduPilot's mode (MAVSDK says HOLD for both BRAKE and LOITER)
            (self.direct.subscribe_message("HEARTBEAT"), heartbeat),
            (telemetry.subscribe_health(), health),
            (telemetry.subscribe_raw_gps(), accuracy),
            # MAVSDK publishes its health flags even when no SYS_STATUS ever came; the message itself tells.
            (self.direct.subscribe_message("SYS_STATUS"), lambda m: cache.set(health_seen=True)),
            (telemetry.subscribe_status_text(), lambda t: cache.set_status_text(t.type.name, t.text)),
            (system.is_connected_state(), self._connection_changed),
        ]
        if not ardupilot:
            streams.append((telemetry.subscribe_flight_mode(),
                            lambda m: cache.set(flight_mode=flight_mode_name(m, ardupilot))))
        for stream, store in streams:
            self.spawn(self._consume(stream, store))

    async def _consume(self, stream, store: Callable[[Any], None]) -> None:
        """Write each value of a subscription into the cache; nothing blocking happens here."""
        try:
            async for value in stream:
                try:
                    store(value)
                except Exception:
                    logger.exception("bad telemetry value %r", value)
        finally:
            await stream.aclose()  # unsubscribes now, on this thread, before MAVSDK is destroyed

    def _connection_changed(self, connected: bool) -> None:
        if self.cache.set_connected(connected, "MAVSDK reports the vehicle disconnected"):
            self._fail_all(Failure.LINK_LOST, "the link to the vehicle is down")

    def _fail_all(self, failure: Failure, why: str) -> None:
        for handle in self._pending_handles():
            self._finish(handle, failure, f"{handle.command} failed: {why}")

    async def _watchdog(self) -> None:
        """Check the link every period. A check that comes late means this loop itself was held up (a loaded
        machine, a pause of the process): the adapter was not listening, so that time is not counted as the
        vehicle's silence."""
        last = time.monotonic()
        while True:
            await asyncio.sleep(_WATCHDOG_PERIOD)
            now = time.monotonic()
            if now - last > 2 * _WATCHDOG_PERIOD:
                self.cache.not_listening(now - last - _WATCHDOG_PERIOD)
            last = now
            if self.cache.check_link(self.link_timeout):
                logger.warning("link to the vehicle lost: no telemetry for %.1f s", self.link_timeout)
                self._fail_all(Failure.LINK_LOST, "the link to the vehicle was lost")

    async def _request_rates(self, telemetry: TelemetryAsync) -> None:
        """Ask for every stream the adapter reads (SET_MESSAGE_INTERVAL through MAVSDK); again every 5 s while the
        health (SYS_STATUS) or position reports stay away, and whenever the link comes back: ArduPilot streams
        nothing unasked, a request can be lost, and a rebooted autopilot forgets them.
        """
        r = self.rates
        requests = [
            (telemetry.set_rate_health, r.health),  # SYS_STATUS: armable, GPS health (MAVSDK's health)
            (telemetry.set_rate_position, r.position),  # GLOBAL_POSITION_INT, with the velocity
            (telemetry.set_rate_velocity_ned, r.position),
            (telemetry.set_rate_attitude_euler, r.attitude),
            (telemetry.set_rate_landed_state, r.landed_state),  # EXTENDED_SYS_STATE
            (telemetry.set_rate_battery, r.battery),
            (telemetry.set_rate_gps_info, r.gps_info),
            (telemetry.set_rate_home, r.home),
        ]
        cache, asked_at, restores = self.cache, -math.inf, self.cache.restores
        while True:
            silent = not (cache.health_seen and cache.position is not None)
            now = self._loop.time()
            # Again after the link came back (a rebooted autopilot forgets them) or while reports stay away.
            if cache.connected and (cache.restores != restores or (silent and now - asked_at >= _RATE_RETRY)):
                if asked_at > -math.inf:
                    logger.info("asking for the telemetry rates again (%s)", "no health report or position yet"
                                if cache.restores == restores else "the link came back")
                restores, asked_at = cache.restores, now
                for setter, hz in requests:
                    if hz > 0:
                        try:
                            await self.call(setter(hz))
                        except Exception as exc:  # a vehicle may refuse a rate; the stream may come at its own
                            logger.info("telemetry rate %s(%g Hz) not applied: %s", setter.__name__, hz, exc)
            await asyncio.sleep(0.5)

    async def _shutdown(self, mavsdk: Mavsdk) -> None:
        self._fail_all(Failure.CANCELLED, "the drone was closed")
        tasks = [t for t in self._tasks if not t.done()]
        for task in tasks:
            task.cancel()
        if tasks:
            await asyncio.wait(tasks, timeout=5.0)
        if self._in_flight:
            logger.info("waiting for %d MAVSDK call(s) in flight before closing", len(self._in_flight))
            await asyncio.wait(set(self._in_flight), timeout=_DRAIN_LIMIT)
        if self._in_flight:
            logger.error("MAVSDK calls still in flight after %g s: MAVSDK is left alive", _DRAIN_LIMIT)
            return
        mavsdk.destroy()
        logger.info("MAVSDK connection %s closed", self.url)
