"""Optional parts of aeroexec and the ``pip install`` line that adds each one.

``pip install aeroexec`` installs what flying a mission needs (on the simulator or through MAVSDK); fleets, the
web console, the flight report's images, Groot2 live and MCAP recordings are extras (``aeroexec[fleet]``, ...).
Where an extra's modules are imported, :func:`require` turns a missing one into :class:`MissingExtra`: one line
naming the part, what is missing and the exact command that installs it, for this installation (``aeroexec[fleet]``;
``.[fleet]`` in the checkout it was installed from)::

    with require("console"):
        import uvicorn
"""

from __future__ import annotations

import contextlib
import importlib.util
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path


@dataclass(frozen=True)
class Extra:
    """One optional part: what it is for (a plural subject: "... need aeroexec's X extra"), and its modules by
    import name -> distribution name."""

    name: str
    purpose: str
    modules: dict[str, str] = field(default_factory=dict)


#: The extras of pyproject.toml's ``[project.optional-dependencies]`` (a test holds the two equal); ``all`` is
#: every one of them, ``test`` adds the test tools.
EXTRAS = {
    "fleet": Extra("fleet", "fleets (linked over Zenoh, members with certificates)",
                   {"zenoh": "eclipse-zenoh", "cryptography": "cryptography"}),
    "console": Extra("console", "the web console and its replays",
                     {"starlette": "starlette", "uvicorn": "uvicorn", "websockets": "websockets"}),
    "report": Extra("report", "the flight report's images and the autopilot's logs",
                     {"matplotlib": "matplotlib", "pyulog": "pyulog"}),
    "groot": Extra("groot", "Groot2 live views (--groot)", {"zmq": "pyzmq", "msgpack": "msgpack"}),
    "rehearse": Extra("rehearse", "rehearsal campaigns on Dask (--dask, --scheduler)", {"distributed": "distributed"}),
    "ros": Extra("ros", "MCAP recordings (aeroexec export --mcap, run --mcap)",
                 {"mcap": "mcap", "mcap_ros2": "mcap-ros2-support"}),
    "foxglove": Extra("foxglove", "Foxglove live views (--foxglove)",
                      {"foxglove": "foxglove-sdk", "mcap_ros2": "mcap-ros2-support"}),
}


class MissingExtra(ImportError):
    """An extra that is not installed; its message is the one line the user needs (``aeroexec`` exits 2)."""

    def __init__(self, extra: str, missing: list[str]) -> None:
        verb = "is" if len(missing) == 1 else "are"
        super().__init__(f"{EXTRAS[extra].purpose} need aeroexec's {extra} extra ({', '.join(missing)} {verb} not "
                         f"installed): {install_line(extra)}")
        self.extra, self.missing = extra, missing


def install_line(extra: str) -> str:
    """The command that adds ``extra`` to this installation: ``pip install 'aeroexec[fleet]'`` (pip keeps the
    aeroexec installed, wherever it came from, and adds the extra's dependencies), or ``pip install '.[fleet]'``
    in the source folder aeroexec was installed from (``-e`` when editable), the checkout the user works in."""
    import shlex

    source, editable = _installed_from()
    target = shlex.quote(f"{source or 'aeroexec'}[{extra}]")
    return f"pip install {'-e ' if editable else ''}{target}"


def missing(extra: str) -> list[str]:
    """The distributions of ``extra`` that cannot be imported here (none when it is installed)."""
    return [dist for module, dist in EXTRAS[extra].modules.items() if not _importable(module)]


@contextlib.contextmanager
def require(extra: str) -> Iterator[None]:
    """Checks that ``extra`` is installed (raising :class:`MissingExtra` if not), then runs the imports of the
    ``with`` block; a module those imports cannot find (a dependency of the extra) is reported the same way."""
    absent = missing(extra)
    if absent:
        raise MissingExtra(extra, absent)
    try:
        yield
    except ModuleNotFoundError as error:
        raise MissingExtra(extra, [error.name or str(error)]) from None


def _importable(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a parent package that fails, a module set to None in sys.modules
        return False


def _installed_from() -> tuple[str | None, bool]:
    """(".", editable) when aeroexec was installed from the current folder; (None, False) when it came from an
    index, another folder (``.`` would be wrong there, and a path may have moved), or cannot be told."""
    import json
    from importlib import metadata  # here: the message is rare, and metadata costs every command ~10 ms
    from urllib.parse import unquote, urlparse

    try:  # the installation's record, not the egg-info a build leaves in the checkout (on sys.path as the cwd)
        text = next((t for d in metadata.distributions(name="aeroexec") if (t := d.read_text("direct_url.json"))),
                    None)
        origin = json.loads(text) if text else {}
    except (ValueError, OSError):
        return None, False
    url = urlparse(str(origin.get("url", "")))
    if url.scheme != "file" or "dir_info" not in origin:
        return None, False
    folder = Path(unquote(url.path))
    editable = bool(origin["dir_info"].get("editable"))
    with contextlib.suppress(OSError):
        if folder.resolve() == Path.cwd().resolve():
            return ".", editable  # the checkout the user is in
    return None, False
