"""``rclpy.executors`` as a mission sees it: executors that run their nodes' timer callbacks on the engine's clock.

``spin()`` runs callbacks until the context is shut down (``rclpy.shutdown()``, from a callback too) or the
executor is; ``spin_once(timeout_sec)`` runs one callback, waiting for it at most ``timeout_sec`` (None: until one
is due); ``spin_until_future_complete(future, timeout_sec)``. Each wait is on the engine's clock, so the run's time
limit (``--max-time``) ends any of them. A spin that nothing can end — its nodes have no timer and no other thread of
the script runs to shut the context down — fails at once, naming why, rather than waiting for the time limit (the
check refuses it before flight where it can see it: :mod:`aeroexec.dialects.aerostack2.ros_nodes`).
``MultiThreadedExecutor`` runs its callbacks one at a time, on the thread that spins it (as one callback group of a
node's, rclpy's default, would have them). A drone interface spun (``rclpy.spin_once(uav)``) always has a callback of
its own to run, the drone's state coming in: a spin_once of it returns after a step of the engine's clock.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from aeroexec.dialects.aerostack2.rclpy import context as contexts
from aeroexec.dialects.aerostack2.rclpy.clock import now_ns
from aeroexec.dialects.aerostack2.rclpy.task import Future
from aeroexec.dialects.aerostack2.rclpy.time import S_TO_NS
from aeroexec.engine import api
from aeroexec.engine.missions.script import MissionThread

#: How often (engine seconds) a spin with no timer due looks whether another thread of the script ended it.
LOOK_AGAIN = 0.1


class ExternalShutdownException(Exception):
    """The context was shut down while the executor waited (rclpy's name)."""


class ShutdownException(Exception):
    """The executor was shut down."""


class SpinNeverEnds(RuntimeError):
    """A spin that nothing can end: no timer of its nodes, no other thread of the script to shut it down."""


class Executor:
    """The executors' common part: nodes added and removed, tasks, and the spins."""

    def __init__(self, *, context: Any = None) -> None:
        self._context = context or contexts.DEFAULT
        self._nodes: list[Any] = []
        self._tasks: list[tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any], Future]] = []
        self._is_shutdown = False
        self._lock = threading.Lock()

    @property
    def context(self) -> Any:
        return self._context

    def add_node(self, node: Any) -> bool:
        with self._lock:
            if node in self._nodes:
                return False
            self._nodes.append(node)
        node.executor = self
        return True

    def remove_node(self, node: Any) -> None:
        with self._lock:
            if node in self._nodes:
                self._nodes.remove(node)

    def get_nodes(self) -> list[Any]:
        return list(self._nodes)

    def create_task(self, callback: Callable[..., Any], *args: Any, **kwargs: Any) -> Future:
        """Run ``callback(*args, **kwargs)`` in the next spin; the future holds its result."""
        future = Future()
        with self._lock:
            self._tasks.append((callback, args, kwargs, future))
        return future

    def wake(self) -> None:
        return None

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        self._is_shutdown = True
        return True

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc_info: Any) -> None:
        self.shutdown()

    # -- spinning -----------------------------------------------------------------------------------------------
    def spin(self) -> None:
        """Run callbacks until the context or the executor is shut down."""
        while self._context.ok() and not self._is_shutdown:
            self.spin_once()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Run one callback, waiting at most ``timeout_sec`` seconds of the engine's clock for one to be due (None
        or a negative timeout: until one is)."""
        self._spin_once(timeout_sec)

    def spin_until_future_complete(self, future: Future, timeout_sec: float | None = None) -> None:
        """Run callbacks until ``future`` is done, the context shut down or ``timeout_sec`` past."""
        if timeout_sec is None or timeout_sec < 0:
            while self._context.ok() and not future.done() and not self._is_shutdown:
                self._spin_once(None, future)
            return
        end = now_ns() + int(timeout_sec * S_TO_NS)
        while self._context.ok() and not future.done() and not self._is_shutdown:
            left = end - now_ns()
            if left <= 0:
                return
            self._spin_once(left / S_TO_NS, future)

    def spin_once_until_future_complete(self, future: Future, timeout_sec: float | None = None) -> None:
        self._spin_once(timeout_sec, future)

    def _spin_once(self, timeout_sec: float | None, future: Future | None = None) -> None:
        start = now_ns()
        deadline = None if timeout_sec is None or timeout_sec < 0 else start + int(timeout_sec * S_TO_NS)
        while self._context.ok() and not self._is_shutdown and not (future is not None and future.done()):
            with self._lock:
                task = self._tasks.pop(0) if self._tasks else None
            if task is not None:
                callback, args, kwargs, done = task
                done.set_result(callback(*args, **kwargs))
                return
            now = now_ns()
            if any(not hasattr(type(node), "create_timer") for node in self._nodes):
                api.wait(LOOK_AGAIN)  # a drone interface: its own callbacks (the drone's state) come all the time
                return
            timers = [t for node in list(self._nodes) for t in list(node.timers) if t.due() is not None]
            if timers:
                first = min(timers, key=lambda t: t.due())
                if first.due() <= now + 1:  # the engine's timers fire within a nanosecond of their time
                    first.call(now)
                    return
            if deadline is not None and now >= deadline:
                return
            due = min((t.due() for t in timers), default=None)
            if due is None and deadline is None and not _others_running():
                several = len(self._nodes) != 1
                raise SpinNeverEnds(
                    f"this spin never ends: its node{'s' if several else ''} "
                    f"({', '.join(_name(n) for n in self._nodes) or 'none'}) ha{'ve' if several else 's'} no timer, "
                    f"and no other thread of the script runs to call rclpy.shutdown()"
                    f"{' or complete the future it waits for' if future is not None else ''}; aeroexec serves no "
                    f"subscriptions, services or actions that could call back")
            ends = [t for t in (due, deadline) if t is not None]
            if not ends or due is None:
                ends.append(now + int(LOOK_AGAIN * S_TO_NS))  # another thread of the script may end it
            api.wait(max(0, min(ends) - now) / S_TO_NS)


def _name(node: Any) -> str:
    return node.get_name() if hasattr(type(node), "get_name") else type(node).__name__


def _others_running() -> bool:
    """True when a thread of the script other than this one runs (it may shut the context down): the script's
    main thread, when this is one of its own threads, or another of its own threads."""
    me = threading.current_thread()
    return isinstance(me, MissionThread) or any(isinstance(t, MissionThread) and t is not me and t.is_alive()
                                                 for t in threading.enumerate())


class SingleThreadedExecutor(Executor):
    """Runs its nodes' callbacks on the thread that spins it."""


class MultiThreadedExecutor(Executor):
    """``MultiThreadedExecutor(num_threads=None)``: its callbacks run one at a time on the spinning thread."""

    def __init__(self, num_threads: int | None = None, *, context: Any = None, **_: Any) -> None:
        super().__init__(context=context)
        self._num_threads = num_threads


_global: Executor | None = None


def get_global_executor() -> Executor:
    """The executor ``rclpy.spin`` uses when given none."""
    global _global
    if _global is None:
        _global = SingleThreadedExecutor()
    return _global


__all__ = ["Executor", "ExternalShutdownException", "MultiThreadedExecutor", "ShutdownException",
           "SingleThreadedExecutor", "SpinNeverEnds", "get_global_executor"]
