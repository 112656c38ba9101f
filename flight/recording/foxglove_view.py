"""The live view in Foxglove (``aeroexec run --foxglove [PORT]``): the recording's topics served over the Foxglove
WebSocket protocol by ``foxglove-sdk``'s server, on the loopback by default, each message as the recorder encoded
it for the MCAP file (the same channels, schemas and bytes). Foxglove opens it with *Open connection* →
``ws://127.0.0.1:PORT``; ``docs/foxglove_layout.json`` is a layout for it (map, 3-D scene with the route, plots of
altitude and battery, the events)."""

from __future__ import annotations

from typing import Any

from aeroexec.extras import require

DEFAULT_PORT = 8765  # Foxglove's own default


class FoxgloveView:
    """A sink of a :class:`~aeroexec.flight.recording.recorder.Recorder`: a Foxglove WebSocket server (its own
    context, so nothing else of the process is served) on ``host:port`` (0: a free port; :attr:`port` says which)."""

    def __init__(self, port: int = DEFAULT_PORT, host: str = "127.0.0.1") -> None:
        with require("foxglove"):
            import foxglove
        self._foxglove = foxglove
        self._context = foxglove.Context()
        try:
            self._server = foxglove.start_server(name="aeroexec", host=host, port=port, context=self._context)
        except RuntimeError as error:  # the port is taken, the address is not this machine's
            raise OSError(f"{host}:{port}: {str(error).removeprefix('FoxgloveError: ')}") from None
        self.host, self.port = host, int(self._server.port)
        self._channels: list[Any] = []

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def channel(self, topic: str, schema: str, schema_encoding: str, schema_data: bytes, message_encoding: str,
                metadata: dict[str, str] | None = None) -> Any:
        channel = self._foxglove.Channel(topic, schema=self._foxglove.Schema(name=schema, encoding=schema_encoding,
                                                                              data=schema_data),
                                         message_encoding=message_encoding, context=self._context,
                                         metadata=metadata or {})
        self._channels.append(channel)
        return channel

    def write(self, channel: Any, log_time: int, data: bytes) -> None:
        channel.log(data, log_time=log_time)

    def metadata(self, name: str, values: dict[str, Any]) -> None:
        """Nothing: a live view has no file to keep it in."""

    def close(self, keep: bool = True) -> None:
        for channel in self._channels:
            channel.close()
        self._server.stop()


__all__ = ["DEFAULT_PORT", "FoxgloveView"]
