"""Hosts and origins the service answers: a guard against web pages the engineer visits.

The service runs on the engineer's machine. Without this guard a web page open in their
browser could POST to it (a ``text/plain`` form needs no CORS pre-flight) and start
computations, and a DNS-rebinding page (its own name resolving to 127.0.0.1) could read the
answers. So:

* the ``Host`` header must name an allowed host (``ROCKMECH_ALLOWED_HOSTS``; default the
  loopback names ``localhost``, ``127.0.0.1``, ``[::1]``), else 400;
* a request with an ``Origin`` header (browsers send it with cross-site and POST requests)
  must come from the service's own origin or an allowed one (``ROCKMECH_ALLOWED_ORIGINS``,
  default none), else 403.

Requests without ``Origin`` (curl, Grasshopper's Hops, scripts) are not browsers' and pass.
``"*"`` in either list allows any. The check runs before the body is read.
"""

from __future__ import annotations

from collections.abc import Sequence

from starlette.types import ASGIApp, Receive, Scope, Send

from .errors import error_body

__all__ = ["HostGuard", "host_name"]


def host_name(host: str) -> str:
    """Return the host of a ``Host`` header value, without the port, in lower case.

    Examples
    --------
    >>> host_name("[::1]:8000"), host_name("LocalHost:80"), host_name("127.0.0.1")
    ('[::1]', 'localhost', '127.0.0.1')
    """
    host = host.strip().lower()
    if host.startswith("["):
        return host.split("]", 1)[0] + "]"
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


class HostGuard:
    """Refuse requests for foreign hosts (400) and from foreign origins (403).

    Parameters
    ----------
    app : ASGI app
        The wrapped application.
    hosts : sequence of str
        Allowed host names (no port); ``"*"`` allows any.
    origins : sequence of str
        Allowed origins besides the service's own (``scheme://host[:port]``); ``"*"`` any.
    """

    def __init__(self, app: ASGIApp, hosts: Sequence[str], origins: Sequence[str]) -> None:
        self.app = app
        self.hosts = {h.strip().lower() for h in hosts}
        self.origins = {o.strip().lower().rstrip("/") for o in origins}

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Pass allowed requests on; answer the others at once."""
        if scope["type"] == "http":
            headers = {k.lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}
            problem = self._problem(scope, headers.get(b"host"), headers.get(b"origin"))
            if problem is not None:
                status, message = problem
                body = error_body("Forbidden", message)
                await send(
                    {
                        "type": "http.response.start",
                        "status": status,
                        "headers": [
                            (b"content-type", b"application/json"),
                            (b"content-length", str(len(body)).encode()),
                        ],
                    }
                )
                await send({"type": "http.response.body", "body": body})
                return
        await self.app(scope, receive, send)

    def _problem(
        self, scope: Scope, host: str | None, origin: str | None
    ) -> tuple[int, str] | None:
        if host is not None and "*" not in self.hosts and host_name(host) not in self.hosts:
            return 400, (
                f"host {host_name(host)!r} is not served here; allowed: "
                f"{', '.join(sorted(self.hosts))} (ROCKMECH_ALLOWED_HOSTS)"
            )
        if origin is None or "*" in self.origins:
            return None
        origin = origin.strip().lower().rstrip("/")
        own = f"{scope.get('scheme', 'http')}://{(host or '').strip().lower()}"
        if origin == own or origin in self.origins:
            return None
        return 403, (
            f"requests from the web page origin {origin!r} are refused: a page in a browser "
            "may not use this service (ROCKMECH_ALLOWED_ORIGINS lists the origins allowed)"
        )
