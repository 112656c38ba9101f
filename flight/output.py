"""A flight's output folder, made ready before anything flies: created, a folder, and writable; otherwise a
:class:`FlightError` naming the path (the default place, ``aeroexec_output/<date-time>``, is the engine's
:func:`~aeroexec.engine.supervision.output.choose_output_folder`)."""

from __future__ import annotations

import tempfile
from pathlib import Path

from aeroexec.engine.supervision.output import DEFAULT_BASE, choose_output_folder
from aeroexec.flight.spec import FlightError


def prepare_output(explicit: str | Path | None = None, base: str | Path = DEFAULT_BASE) -> Path:
    """The run's output folder (``explicit``, else a new dated one in ``base``), created and checked writable."""
    folder = choose_output_folder(explicit, base)
    option = f"--output {explicit}" if explicit is not None else f"the output folder {folder}"
    if folder.exists() and not folder.is_dir():
        raise FlightError(f"{option}: not a folder (it is a file); give a folder for the run's files", usage=True)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".aeroexec-", delete=True):
            pass
    except FileExistsError:
        raise FlightError(f"{option}: a file stands in its path; give a folder for the run's files",
                          usage=True) from None
    except OSError as error:
        raise FlightError(f"{option}: cannot write the run's files there: {error.strerror or error}",
                          usage=True) from None
    return folder


__all__ = ["prepare_output"]
