"""Hosts and origins the service answers: a guard against web pages the engineer visits.

The service runs on the engineer's machine. Without this guard a web page open in their
browser could POST to it (a ``text/plain`` form needs no CORS pre-flight) and start
computations, and a DNS-rebinding page (its own name resolving to 127.0.0.1) could read the
answers. So:

* the ``Host`` header must name an allowed host (``ROCKMECH_ALLOWED_HOSTS``; default the
  loopback names ``localhost``, ``127.0.0.1``, ``[::1]``), else 400;
* a request with an ``Origin`` header (browsers send it with cross-site and POST requests)
  must come from the service's own origin or an allowed one (``ROCKMECH_ALLOWED_ORIGINS``,
  default none), else 403. The loopback names (``localhost``, ``127.0.0.1``, ``[::1]``) are
  one host: a page of the service opened as ``http://localhost:8000`` may call it as
  ``127.0.0.1:8000`` (same scheme and port; only this machine can be either).

Requests without ``Origin`` (curl, Grasshopper's Hops, scripts) are not browsers' and pass.
``"*"`` in either list allows any. The check runs before the body is read.
"""

from __future__ import annotations

from collections.abc import Sequence

from starlette.types import ASGIApp, Receive, Scope, Send

from .errors import error_body

__all__ = ["LOOPBACK", "HostGuard", "host_name", "same_origin"]

#: Names of this machine's loopback interface, as a ``Host`` header or an origin gives them.
LOOPBACK = frozenset({"localhost", "127.0.0.1", "[::1]"})


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


def _host_port(authority: str, scheme: str) -> tuple[str, str]:
    """(host, port) of ``host[:port]``, the port defaulted from the scheme."""
    authority = authority.strip().lower()
    host = host_name(authority)
    rest = authority[len(host) :]
    port = rest[1:] if rest.startswith(":") else ""
    return host, port or ("443" if scheme in ("https", "wss") else "80")


def same_origin(origin: str, scheme: str, host: str) -> bool:
    """Whether the browser ``origin`` is the service's own, reached as ``scheme://host``.

    The loopback names count as one host (``LOOPBACK``).

    Examples
    --------
    >>> same_origin("http://localhost:8000", "http", "127.0.0.1:8000")
    True
    >>> same_origin("http://localhost:8001", "http", "127.0.0.1:8000")
    False
    >>> same_origin("http://evil.example:8000", "http", "127.0.0.1:8000")
    False
    """
    o_scheme, sep, o_authority = origin.strip().lower().rstrip("/").partition("://")
    if not sep or o_scheme != scheme.lower():
        return False
    o_host, o_port = _host_port(o_authority, o_scheme)
    s_host, s_port = _host_port(host, scheme.lower())
    if o_port != s_port:
        return False
    return o_host == s_host or (o_host in LOOPBACK and s_host in LOOPBACK)


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
        if same_origin(origin, str(scope.get("scheme", "http")), host or "") or (
            origin in self.origins
        ):
            return None
        return 403, (
            f"requests from the web page origin {origin!r} are refused: a page in a browser "
            "may not use this service (ROCKMECH_ALLOWED_ORIGINS lists the origins allowed)"
        )
