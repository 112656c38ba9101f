"""The control socket of a run: ``aeroexec ctl`` sends the operator's commands from another terminal.

Protocol (JSON lines over TCP on 127.0.0.1 only): each request is one line
``{"token": T, "command": C, "argument": A}``; each answer is one line ``{"ok": bool, "message": text}``
(plus ``"status": {...}`` for ``status``). A connection may send several requests. A wrong or missing token gets
``{"ok": false, "error": "wrong token"}`` and nothing else (not which run this is) and the connection is closed; an
answer to the token names its run (``run``: mission, pid, folder). The port and the token (random,
one per run) are written to ``control.json`` in the run's output folder, readable by its owner only.

Every live run is also listed in the user's runtime directory (``$XDG_RUNTIME_DIR/aeroexec/``, else
``<tmp>/aeroexec-<uid>/``, mode 0700): one ``run-<pid>-<port>.json`` (mode 0600) with the port, the token, the
output folder and the mission, so ``aeroexec ctl`` finds a run wherever it was started.

Commands go to :meth:`Supervisor.submit`, so they execute on the engine's thread; a connection waits for
the result at most ``COMMAND_TIMEOUT`` seconds. Every thread here is a daemon with timeouts: the server
closes itself when the engine stops and never holds up the process.
"""

from __future__ import annotations

import contextlib
import datetime
import json
import logging
import os
import socket
import sys
import threading
from dataclasses import dataclass
from pathlib import Path

from aeroexec.limits import MAX_NESTING, nesting_beyond

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

logger = logging.getLogger(__name__)

HOST = "127.0.0.1"
CONTROL_FILE = "control.json"
COMMAND_TIMEOUT = 5.0  # wall seconds a connection waits for the engine to execute a command
IDLE_TIMEOUT = 30.0  # wall seconds a connection may stay silent
MAX_LINE = 64 * 1024
WRONG_TOKEN = "wrong token"  # all a request without this run's token learns (nothing of the run)


class ControlServer:
    """Serves one engine's supervisor on a free loopback port; ``start()``, then ``close()`` (or stop the engine).

    It may start before the engine exists (``engine=None``: the run is starting, e.g. waiting for its vehicle):
    ``status`` then says so, ``abort`` calls ``on_abort`` (the start is given up), other commands are refused
    until :attr:`engine` is set. Every answer to the run's token names the run
    (``run``: mission, pid, folder); a wrong token learns nothing of it."""

    def __init__(self, engine: Any, folder: str | Path | None = None, port: int = 0, name: str = "",
                 register: bool = True, on_abort: Any = None) -> None:
        self.engine = engine
        self.on_abort = on_abort
        self.starting = "starting"  # what a run without its engine yet is doing, in words
        self.token = os.urandom(16).hex()  # secrets.token_hex(16), without importing secrets (~3 ms)
        self.file: Path | None = None
        self.entry: Path | None = None  # this run's file in the runtime directory
        self.name, self._register = name, register
        self._folder = Path(folder) if folder is not None else None
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._socket.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._socket.bind((HOST, port))
        self._socket.listen(8)
        self._socket.settimeout(0.2)
        self.port: int = self._socket.getsockname()[1]
        self._closed = threading.Event()
        self._thread = threading.Thread(target=self._accept, name="aeroexec-control", daemon=True)

    def start(self) -> ControlServer:
        """List the run in the runtime directory, accept connections in a daemon thread, and with the engine
        there, write ``control.json`` (mode 0600) in the folder (:meth:`attach` does it for a run that starts)."""
        if self._folder is not None and self.engine is not None:
            self.file = write_control_file(self._folder, self.port, self.token)
        if self._register:
            try:
                self.entry = register_run(self.port, self.token, self._folder, self.name)
            except OSError as error:  # ctl --run DIR still works
                logger.warning("the run cannot be listed in the runtime directory: %s", error)
        self._thread.start()
        logger.info("control socket on %s:%d", HOST, self.port)
        return self

    def attach(self, engine: Any) -> None:
        """The run's engine is built: commands go to it, and ``control.json`` says where the run flies."""
        self.engine = engine
        if self._folder is not None and self.file is None and not self._closed.is_set():
            self.file = write_control_file(self._folder, self.port, self.token)

    def close(self) -> None:
        """Stop accepting and remove ``control.json``; returns promptly."""
        if self._closed.is_set():
            return
        self._closed.set()
        with contextlib.suppress(OSError):
            self._socket.shutdown(socket.SHUT_RDWR)  # wakes the accepting thread now, not at its next timeout
        with contextlib.suppress(OSError):
            self._socket.close()
        for path in (self.file, self.entry):
            if path is not None:
                with contextlib.suppress(OSError):
                    path.unlink()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=1.0)

    @property
    def closed(self) -> bool:
        return self._closed.is_set()

    def __enter__(self) -> ControlServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the threads ---------------------------------------------------------------------------
    def _accept(self) -> None:
        while not self._closed.is_set():
            if self.engine is not None and self.engine.stopped:
                break
            try:
                connection, _ = self._socket.accept()
            except TimeoutError:
                continue
            except OSError:
                break
            threading.Thread(target=self._serve, args=(connection,), name="aeroexec-control-client",
                             daemon=True).start()
        self.close()

    def _serve(self, connection: socket.socket) -> None:
        try:
            self._conversation(connection)
        except Exception as exc:  # a bug, not the client's input: logged with its reason, never a thread traceback
            logger.error("control socket: a request could not be answered (%s: %s); please report it",
                         type(exc).__name__, exc)

    def _conversation(self, connection: socket.socket) -> None:
        connection.settimeout(IDLE_TIMEOUT)
        with connection, contextlib.suppress(OSError):
            reader = connection.makefile("rb")
            while not self._closed.is_set():
                line = reader.readline(MAX_LINE + 1)
                if not line:
                    return
                try:
                    answer, keep = self._answer(line)
                except Exception as exc:  # a bug, not the client's input: answered, logged, the connection kept
                    logger.error("control socket: a request could not be answered (%s: %s); please report it",
                                 type(exc).__name__, exc)
                    answer, keep = {"ok": False, "error": f"internal error ({type(exc).__name__}): please report "
                                                          f"it"}, True
                if answer.pop("authenticated", False):  # only who holds the token learns which run answers
                    answer["run"] = self.identity
                connection.sendall((json.dumps(answer) + "\n").encode())
                if not keep:
                    return

    def _answer(self, line: bytes) -> tuple[dict[str, Any], bool]:
        """The reply to one request line, and whether the connection stays open."""
        if len(line) > MAX_LINE:
            return {"ok": False, "error": "request too long"}, False
        deep = nesting_beyond(line.decode("utf-8", "replace"), MAX_NESTING, "[{", "]}", quotes='"')
        if deep is not None:
            logger.warning("control socket: a request nested more than %d levels deep was refused", MAX_NESTING)
            return {"ok": False, "error": f"bad request: nested more than {MAX_NESTING} levels deep "
                                          f"(at character {deep + 1})"}, False
        try:
            request = json.loads(line)
            if not isinstance(request, dict):
                raise ValueError("not an object")
        except (ValueError, RecursionError):
            return {"ok": False, "error": "bad request: expected one JSON object per line"}, False
        token = str(request.get("token", ""))
        import hmac  # here: a client asking (hmac imports hashlib and its OpenSSL, ~3 ms of every run's start)

        if not hmac.compare_digest(token.encode(), self.token.encode()):
            logger.warning("control socket: a request with a wrong token was refused")
            return {"ok": False, "error": WRONG_TOKEN}, False
        command, argument = str(request.get("command", "")), str(request.get("argument", "") or "")
        if self.engine is None:
            return {**self._starting(command), "authenticated": True}, True
        if self.engine.stopped:
            return {"ok": False, "error": "the engine has stopped", "authenticated": True}, False
        ticket = self.engine.supervisor.submit(command, argument, origin="ctl")
        result = ticket.wait(COMMAND_TIMEOUT)
        if result is None:
            return {"ok": False, "error": f"the engine did not run {command!r} within {COMMAND_TIMEOUT:g} s "
                                          f"(it is not ticking)", "authenticated": True}, True
        answer: dict[str, Any] = {"ok": result.ok, "message": result.message, "authenticated": True}
        if not result.ok:
            answer["error"] = result.message
        if command == "status":
            answer["status"] = result.data
        if command == "query":
            answer["answers"] = result.data.get("answers", [])
        if command == "items":
            answer["items"] = result.data.get("items", [])
        if result.data.get("problems"):
            answer["problems"] = result.data["problems"]
        return answer, True


    @property
    def identity(self) -> dict[str, Any]:
        """The run this server belongs to, as every answer names it."""
        return {"mission": self.name, "pid": os.getpid(),
                "folder": str(self._folder.resolve()) if self._folder is not None else ""}

    def _starting(self, command: str) -> dict[str, Any]:
        """The answer of a run whose engine is not built yet."""
        if command == "status":
            return {"ok": True, "message": f"the run is {self.starting}", "status": {"state": "starting"}}
        if command == "abort" and self.on_abort is not None:
            self.on_abort()
            return {"ok": True, "message": f"the run's start is given up (it was {self.starting}); nothing flew"}
        return {"ok": False, "error": f"the run is {self.starting}: {command!r} can be sent once it flies"}


def write_control_file(folder: Path, port: int, token: str) -> Path:
    """``folder/control.json`` with the port and token, created readable and writable by its owner only."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / CONTROL_FILE
    with contextlib.suppress(FileNotFoundError):
        path.unlink()
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(descriptor, "w", encoding="utf-8") as file:
        json.dump({"host": HOST, "port": port, "token": token, "pid": os.getpid()}, file)
    return path


def runtime_dir() -> Path:
    """The per-user folder listing live runs: ``$XDG_RUNTIME_DIR/aeroexec``, else ``<tmp>/aeroexec-<uid>``."""
    base = os.environ.get("XDG_RUNTIME_DIR")
    path = Path(base) / "aeroexec" if base else Path(temporary_folder()) / f"aeroexec-{os.getuid()}"
    path.mkdir(mode=0o700, parents=True, exist_ok=True)
    info = path.stat()
    if info.st_uid != os.getuid() or info.st_mode & 0o077:
        raise PermissionError(f"{path} must belong to this user and be private (mode 0700)")
    return path


def temporary_folder() -> str:
    """The folder :func:`tempfile.gettempdir` answers: the first of ``$TMPDIR``, ``$TEMP``, ``$TMP`` and /tmp that is a
    folder this user may write in, found without importing :mod:`tempfile` (it imports shutil, bz2, lzma, random...:
    ~3 ms of a run's start without a runtime directory); otherwise, or when something imported it already (a caller
    may have set ``tempfile.tempdir``), tempfile's own answer."""
    imported = sys.modules.get("tempfile")
    if imported is None:
        for folder in (*filter(None, map(os.environ.get, ("TMPDIR", "TEMP", "TMP"))), "/tmp"):
            if os.path.isdir(folder) and os.access(folder, os.W_OK | os.X_OK):
                return os.path.abspath(folder)
        import tempfile as imported
    return str(imported.gettempdir())


@dataclass(frozen=True)
class LiveRun:
    """A run listed in the runtime directory."""

    pid: int
    port: int
    token: str
    folder: str
    mission: str
    started: str
    path: Path

    def __str__(self) -> str:
        return f"{self.mission or '?'} (pid {self.pid}, port {self.port}, since {self.started}): {self.folder}"


def register_run(port: int, token: str, folder: Path | None, mission: str) -> Path:
    """List this process's run in the runtime directory (0600); the path to remove when the run ends."""
    path = runtime_dir() / f"run-{os.getpid()}-{port}.json"
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(descriptor, "w", encoding="utf-8") as file:
        json.dump({"host": HOST, "port": port, "token": token, "pid": os.getpid(), "mission": mission,
                   "folder": str(folder.resolve()) if folder is not None else "",
                   "started": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}, file)
    return path


def live_runs() -> list[LiveRun]:
    """The runs of this user still going, oldest first; entries of processes that died are removed."""
    runs = []
    for path in sorted(runtime_dir().glob("run-*.json"), key=lambda p: p.stat().st_mtime):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            run = LiveRun(int(data["pid"]), int(data["port"]), str(data["token"]), str(data.get("folder", "")),
                          str(data.get("mission", "")), str(data.get("started", "")), path)
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if _alive(run.pid):
            runs.append(run)
        else:
            with contextlib.suppress(OSError):
                path.unlink()
    return runs


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def read_control_file(folder: str | Path) -> tuple[int, str]:
    """The port and token of the run whose output folder is ``folder``; raises ``ValueError`` with a sentence."""
    path = Path(folder) / CONTROL_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return int(data["port"]), str(data["token"])
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file (is the run still going? it is removed when the run ends)") \
            from None
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ValueError(f"{path}: not a control file ({error})") from None


def send_command(port: int, token: str, command: str, argument: str = "", timeout: float = 10.0) -> dict[str, Any]:
    """Send one command to a run's control socket and return its answer; raises ``OSError`` when unreachable."""
    request = json.dumps({"token": token, "command": command, "argument": argument}) + "\n"
    with socket.create_connection((HOST, port), timeout=timeout) as connection:
        connection.sendall(request.encode())
        reader = connection.makefile("rb")
        line = reader.readline(MAX_LINE + 1)
    if not line:
        raise ConnectionError("the run closed the connection without answering")
    try:
        return json.loads(line)
    except ValueError:
        raise ConnectionError("the run answered something that is not JSON") from None
