"""Requests still running when the shutdown grace ends get 503, not a 500 and a traceback.

On SIGTERM uvicorn stops accepting connections and waits ``ROCKMECH_SHUTDOWN_TIMEOUT_S`` for
the requests in flight; then it cancels them. Without this middleware a cancelled request
reached uvicorn as a ``CancelledError``: the client got uvicorn's plain-text 500 and the log
a 76-line traceback. Here the cancellation is caught where the request entered the app: a
request whose answer has not started gets the service's JSON error, 503 ``ShuttingDown``
with ``Retry-After`` (a fault of the moment, not of the request), and the request ends
normally, so uvicorn logs nothing but its own one line ("Cancel N running task(s)").
"""

from __future__ import annotations

import asyncio

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from .errors import error_body

__all__ = ["RETRY_AFTER_S", "ShutdownAnswer", "shutdown_message"]

#: Seconds a client is told to wait before trying again (the service is restarting).
RETRY_AFTER_S = 5


def shutdown_message(grace_s: float) -> str:
    """Return the message of a request stopped by a shutdown."""
    return (
        f"the service is shutting down and stopped this request after {grace_s:g} s "
        "(ROCKMECH_SHUTDOWN_TIMEOUT_S); nothing is wrong with the request: send it again "
        "once the service is back"
    )


class ShutdownAnswer:
    """Answer 503 to a request cancelled by the server's shutdown.

    Parameters
    ----------
    app : ASGI app
        The wrapped application.
    grace_s : float
        The shutdown grace (``ROCKMECH_SHUTDOWN_TIMEOUT_S``) [s], for the message.
    """

    def __init__(self, app: ASGIApp, grace_s: float) -> None:
        self.app = app
        self.grace_s = grace_s

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Pass the request on; answer 503 if it is cancelled before its answer starts."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        started = False

        async def sending(message: Message) -> None:
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
            await send(message)

        try:
            await self.app(scope, receive, sending)
        except asyncio.CancelledError:
            # The cancellation is answered here (Python 3.11+ counts it; end the count).
            uncancel = getattr(asyncio.current_task(), "uncancel", None)
            if uncancel is not None:
                uncancel()
            if started:
                return  # the answer was on its way; the connection closes with it cut short
            body = error_body("ShuttingDown", shutdown_message(self.grace_s))
            await send(
                {
                    "type": "http.response.start",
                    "status": 503,
                    "headers": [
                        (b"content-type", b"application/json"),
                        (b"content-length", str(len(body)).encode()),
                        (b"retry-after", str(RETRY_AFTER_S).encode()),
                        (b"connection", b"close"),
                    ],
                }
            )
            await send({"type": "http.response.body", "body": body})
