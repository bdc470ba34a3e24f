"""Request body limits: 413 past the size limit, 422 past the count of JSON values.

JSON bodies are also counted as they arrive: a body with more commas than a request can
need (``ROCKMECH_MAX_SAMPLES`` record samples plus ``VALUES_PER_MECHANISM`` per mechanism
and ``VALUES_SLACK``) is refused with 422 before it is decoded, so that a few large record
arrays cannot make the server build hundreds of MB of Python floats.

A pure ASGI middleware: a declared ``Content-Length`` over the limit is refused without
passing the request on; a body without one (chunked) is counted as it arrives and refused as
soon as it passes the limit. The error is an ``HTTPException(413)``, so FastAPI's body parsing
passes it through and the app's handler answers in the service's error format.

Before answering, the rest of the body is read and thrown away (nothing is kept), so that a
client still sending gets the 413 instead of a broken connection. Past ``DRAIN_MAX`` bytes
the connection is closed instead.
"""

from __future__ import annotations

from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from .errors import error_body

__all__ = [
    "DRAIN_MAX",
    "VALUES_PER_MECHANISM",
    "VALUES_SLACK",
    "BodyLimit",
    "BodyTooLarge",
    "TooManyValues",
    "too_large_message",
]

#: Most bytes of an oversized body read and discarded before the 413 [bytes].
DRAIN_MAX = 256 * 1024 * 1024
#: JSON values one mechanism of a constants file may hold (its keys and numbers).
VALUES_PER_MECHANISM = 200
#: JSON values of a request besides record samples and mechanisms (options, scales).
VALUES_SLACK = 10_000


def too_large_message(limit: int) -> str:
    """Return the 413 message for a body limit of ``limit`` bytes."""
    return f"request body larger than the service limit of {limit} bytes (ROCKMECH_MAX_BODY_BYTES)"


class BodyTooLarge(HTTPException):
    """The request body passed the limit while it was being read."""

    def __init__(self, limit: int) -> None:
        super().__init__(413, too_large_message(limit))


class TooManyValues(HTTPException):
    """A JSON body holds more values than any request within the limits can."""

    def __init__(self, limit: int) -> None:
        super().__init__(
            422,
            f"the JSON body holds more than {limit} values; a request carries at most "
            "ROCKMECH_MAX_SAMPLES record samples (and ROCKMECH_MAX_MECHANISMS mechanisms)",
        )


class BodyLimit:
    """Refuse request bodies larger than ``limit`` bytes with 413.

    Parameters
    ----------
    app : ASGI app
        The wrapped application.
    limit : int
        Largest body [bytes].
    max_values : int, optional
        Most commas a JSON body may hold; default: no count.
    """

    def __init__(self, app: ASGIApp, limit: int, max_values: int = 0) -> None:
        self.app = app
        self.limit = limit
        self.max_values = max_values

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Pass the request on, counting its body; answer 413 past the limit."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = None
        is_json = False
        for key, value in scope.get("headers", []):
            if key == b"content-length":
                try:
                    declared = int(value)
                except ValueError:
                    declared = None
            elif key == b"content-type":
                is_json = value.split(b";", 1)[0].strip().lower() == b"application/json"
        count_values = is_json and self.max_values > 0
        if declared is not None and declared > self.limit:
            drained = await _drain(receive, 0)
            body = error_body("HTTPError", too_large_message(self.limit))
            headers = [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
            ]
            if not drained:
                headers.append((b"connection", b"close"))
            await send({"type": "http.response.start", "status": 413, "headers": headers})
            await send({"type": "http.response.body", "body": body})
            return
        received = 0
        values = 0

        async def counted() -> Message:
            nonlocal received, values
            message = await receive()
            if message["type"] == "http.request":
                chunk = message.get("body", b"")
                received += len(chunk)
                if received > self.limit:
                    if message.get("more_body", False):
                        await _drain(receive, received)
                    raise BodyTooLarge(self.limit)
                if count_values:
                    values += chunk.count(b",")
                    if values > self.max_values:
                        if message.get("more_body", False):
                            await _drain(receive, received)
                        raise TooManyValues(self.max_values)
            return message

        await self.app(scope, counted, send)


async def _drain(receive: Receive, already: int) -> bool:
    """Read and discard the rest of a request body; False if it passed ``DRAIN_MAX``."""
    total = already
    while True:
        message = await receive()
        if message["type"] != "http.request":
            return False
        total += len(message.get("body", b""))
        if not message.get("more_body", False):
            return True
        if total > DRAIN_MAX:
            return False
