"""A flight's output folder, made ready before anything flies: created, a folder, writable, with room for the run's
first records; otherwise a :class:`FlightError` naming the path, an option that cannot be used (exit status 2):
a disk with no space left is "the output folder ... has no space left" (:func:`no_space`), whichever file finds it
first (this check, the journal, the event log). The default place, ``aeroexec_output/<date-time>``, is the
engine's :func:`~aeroexec.engine.supervision.output.choose_output_folder`."""

from __future__ import annotations

import errno
import os
from pathlib import Path

from aeroexec.engine.supervision.output import DEFAULT_BASE, choose_output_folder
from aeroexec.flight.spec import FlightError

ROOM = 256 * 1024  # bytes a new run must be able to write before it flies (its journal, its first log lines)
NO_SPACE = (errno.ENOSPC, errno.EDQUOT)  # no space left, the user's quota reached


def prepare_output(explicit: str | Path | None = None, base: str | Path = DEFAULT_BASE) -> Path:
    """The run's output folder (``explicit``, else a new dated one in ``base``), created and checked writable."""
    folder = choose_output_folder(explicit, base)
    option = f"--output {explicit}" if explicit is not None else f"the output folder {folder}"
    if folder.exists() and not folder.is_dir():
        raise FlightError(f"{option}: not a folder (it is a file); give a folder for the run's files", usage=True)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        # a probe file of a name no other process makes (tempfile's way, without importing it: ~3 ms of a start)
        probe = folder / f".aeroexec-{os.getpid()}-{os.urandom(8).hex()}"
        descriptor = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        try:
            room = bytes(ROOM)
            while room:  # the run's first records (the journal's schema, the log's first lines) fit
                room = room[os.write(descriptor, room):]
        finally:
            os.close(descriptor)
            os.unlink(probe)
    except FileExistsError:
        raise FlightError(f"{option}: a file stands in its path; give a folder for the run's files",
                          usage=True) from None
    except OSError as error:
        if error.errno in NO_SPACE:
            raise no_space(folder, error.strerror or str(error)) from None
        raise FlightError(f"{option}: cannot write the run's files there: {error.strerror or error}",
                          usage=True) from None
    return folder


def no_space(folder: Path, why: str) -> FlightError:
    """The refusal of a run whose output folder's disk is full (exit status 2, before anything flies)."""
    return FlightError(f"the output folder {folder} has no space left ({why}): free some space on its disk, or give "
                       f"another folder with --output", usage=True)


__all__ = ["NO_SPACE", "no_space", "prepare_output"]
