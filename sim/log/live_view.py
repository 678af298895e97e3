"""A loopback WebSocket server that shows a run in Foxglove while it happens.

The server is a sink of the same ``foxglove.Context`` as the MCAP file (see
:class:`swarmnav.log.writer.McapRecorder`), so a viewer sees exactly the messages the
log gets.  It binds its port when it is created: a busy port is an error before
any file is opened, so a failed ``--live`` leaves nothing behind.
"""

from __future__ import annotations

import threading

import foxglove
from foxglove.websocket import ServerListener

from swarmnav.models.errors import ConfigError

DEFAULT_LIVE_HOST = "127.0.0.1"
DEFAULT_LIVE_PORT = 8765


class _LateSubscribers(ServerListener):
    """Server listener: remembers topics a Foxglove client subscribed to."""

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._topics: set[str] = set()

    def on_subscribe(self, client, channel) -> None:
        with self._lock:
            self._topics.add(channel.topic)

    def take(self) -> set[str]:
        with self._lock:
            topics, self._topics = self._topics, set()
        return topics


class LiveServer:
    """Foxglove's WebSocket server on one context, started at construction.

    The path and the static obstacles are sent once, at t = 0; a client that
    subscribes later would never see them.  :meth:`late_topics` tells the
    recorder which topics were subscribed to since it last asked, so it can
    re-send them (to every sink: the MCAP file gets the extra copy too, but only
    when someone actually watched).

    Args:
        context: the foxglove context whose channels are served.
        name: the server name a client shows.
        host, port: where to listen (port 0 picks a free one, see :attr:`port`).

    Raises:
        ConfigError: the address cannot be served (port in use, bad host).
    """

    def __init__(self, context: foxglove.Context, name: str = "swarmnav", *,
                 host: str = DEFAULT_LIVE_HOST, port: int = DEFAULT_LIVE_PORT):
        self.host = host
        self._listener = _LateSubscribers()
        try:
            self._server = foxglove.start_server(
                name=name, host=host, port=port, context=context, server_listener=self._listener
            )
        except Exception as error:  # foxglove raises its own error types
            raise ConfigError("--live", f"cannot serve on {host}:{port} ({error})") from error

    @property
    def port(self) -> int:
        """The port the server listens on."""
        return self._server.port

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def late_topics(self) -> set[str]:
        """Topics subscribed to since the last call."""
        return self._listener.take()

    def stop(self) -> None:
        if self._server is not None:
            self._server.stop()
            self._server = None
