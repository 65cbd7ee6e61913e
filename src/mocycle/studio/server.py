"""How ``mocycle studio`` runs its app on uvicorn: connections that never finish their request headers are closed,
at most so many connections are served at once, and a stop (Ctrl-C, SIGTERM) waits for nobody for long.

uvicorn closes a connection idle after a response (``timeout_keep_alive``), but not one that opens and sends its
request headers a byte at a time: every such connection stays open for as long as its client likes (300 of them
stayed open).  :class:`HeaderTimeout` is uvicorn's h11 protocol with one timer more: from the moment a connection
opens, and again after each response, its client has :data:`HEADER_TIMEOUT_S` seconds to send a whole request
head, or the connection is closed.
"""

from __future__ import annotations

import asyncio

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

__all__ = ["GRACEFUL_S", "HEADER_TIMEOUT_S", "MAX_CONNECTIONS", "HeaderTimeout", "config"]

#: seconds a client has to send a request's head (its line and headers)
HEADER_TIMEOUT_S = 10.0
#: connections served at once (more get 503 until some close)
MAX_CONNECTIONS = 128
#: seconds a stop waits for requests still running before it cancels them
GRACEFUL_S = 1


class HeaderTimeout(H11Protocol):
    """uvicorn's h11 protocol; a connection whose client has not sent a whole request head within
    :data:`HEADER_TIMEOUT_S` of opening (or of the last response) is closed."""

    header_timeout_s = HEADER_TIMEOUT_S

    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        self._head_timer: asyncio.TimerHandle | None = None
        self._arm()

    def _arm(self) -> None:
        self._disarm()
        self._head_timer = self.loop.call_later(self.header_timeout_s, self._too_slow)

    def _disarm(self) -> None:
        timer = getattr(self, "_head_timer", None)
        if timer is not None:
            timer.cancel()
            self._head_timer = None

    def _too_slow(self) -> None:
        self._head_timer = None
        if self.conn.their_state is h11.IDLE and not self.transport.is_closing():  # still no whole request head
            self.transport.close()

    def data_received(self, data: bytes) -> None:
        super().data_received(data)
        if self.conn.their_state is not h11.IDLE:  # the head is in: the request runs (bodies have their own limit)
            self._disarm()

    def on_response_complete(self) -> None:
        super().on_response_complete()
        if not self.transport.is_closing() and self.conn.their_state is h11.IDLE:
            self._arm()  # the next request's head, on a kept-alive connection

    def connection_lost(self, exc) -> None:
        self._disarm()
        super().connection_lost(exc)


def config(app, **kwargs):
    """The ``uvicorn.Config`` of the studio: :class:`HeaderTimeout`, :data:`MAX_CONNECTIONS`, a stop that
    cancels requests still running after :data:`GRACEFUL_S` (``kwargs`` passed on)."""
    import uvicorn

    return uvicorn.Config(app, http=HeaderTimeout, limit_concurrency=MAX_CONNECTIONS,
                          timeout_graceful_shutdown=GRACEFUL_S, **kwargs)
