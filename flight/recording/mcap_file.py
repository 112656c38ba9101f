"""An MCAP file written as a recording goes (the ``mcap`` package's writer): each schema registered once, a channel
per topic, messages in chunks (zstd). Written to ``FILE.part`` and renamed when finished, so a recording that fails
half-way never leaves a file that looks whole."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path
from typing import Any

from aeroexec import __version__
from aeroexec.extras import require


class McapFile:
    """A sink of a :class:`~aeroexec.flight.recording.recorder.Recorder`: messages into the MCAP file ``path``."""

    def __init__(self, path: str | Path) -> None:
        with require("ros"):
            import mcap
            from mcap.writer import Writer
        self.path = Path(path)
        self.part = self.path.with_name(self.path.name + ".part")
        self._file = open(self.part, "wb")  # noqa: SIM115 -- closed by close()
        self._writer = Writer(self._file)
        # no profile: the file holds ROS 2 messages (CDR) and aeroexec's own records (JSON) side by side
        self._writer.start(profile="", library=f"aeroexec {__version__}; mcap {getattr(mcap, '__version__', '')}")
        self._schemas: dict[str, int] = {}
        self.closed = False

    def channel(self, topic: str, schema: str, schema_encoding: str, schema_data: bytes, message_encoding: str,
                metadata: dict[str, str] | None = None) -> int:
        """The channel of ``topic`` (registered now, with its schema if not yet)."""
        if schema not in self._schemas:
            self._schemas[schema] = self._writer.register_schema(schema, schema_encoding, schema_data)
        return self._writer.register_channel(topic, message_encoding, self._schemas[schema], metadata or {})

    def write(self, channel: int, log_time: int, data: bytes) -> None:
        self._writer.add_message(channel, log_time=log_time, data=data, publish_time=log_time)

    def metadata(self, name: str, values: dict[str, Any]) -> None:
        self._writer.add_metadata(name, {str(k): str(v) for k, v in values.items()})

    def close(self, keep: bool = True) -> None:
        """Finish the file (its summary and index) and put it in place; ``keep=False`` removes it instead."""
        if self.closed:
            return
        self.closed = True
        try:
            if keep:
                self._writer.finish()
        finally:
            self._file.close()
        if keep:
            os.replace(self.part, self.path)
        else:
            with contextlib.suppress(OSError):
                self.part.unlink()


__all__ = ["McapFile"]
