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

import ipaddress
import re
from collections.abc import Sequence
from typing import Optional

from starlette.types import ASGIApp, Receive, Scope, Send

from .errors import error_body

__all__ = ["LOOPBACK", "PORT_MAX", "HostGuard", "host_name", "parse_authority", "same_origin"]

#: Names of this machine's loopback interface, as a ``Host`` header or an origin gives them.
LOOPBACK = frozenset({"localhost", "127.0.0.1", "[::1]"})


#: A registered name of ``Host``: DNS labels (letters, digits, ``-``, ``_``) joined by dots.
_LABEL = r"[a-z0-9_](?:[a-z0-9_-]*[a-z0-9_])?"
_REG_NAME = re.compile(rf"{_LABEL}(?:\.{_LABEL})*\.?")
#: Largest TCP port.
PORT_MAX = 65535


def parse_authority(authority: str) -> tuple[str, Optional[int]]:
    """Split a ``Host`` header value (``host[:port]``) strictly; host in lower case.

    RFC 9110 section 7.2: ``Host = uri-host [ ":" port ]``, the authority of RFC 3986
    section 3.2 without its userinfo. The host is a bracketed IPv6 address, a dotted IPv4
    address or a DNS name; the port 1 to 5 digits up to 65535. Anything else (``@``,
    a second colon, spaces, a path, an empty host or port) is refused, so a header such as
    ``127.0.0.1:8000@evil.example`` cannot pass for a loopback host.

    Raises
    ------
    ValueError
        What is wrong with the value, in words.

    Examples
    --------
    >>> parse_authority("[::1]:8000"), parse_authority("LocalHost"), parse_authority("127.0.0.1:80")
    (('[::1]', 8000), ('localhost', None), ('127.0.0.1', 80))
    >>> parse_authority("127.0.0.1:8000@evil.example")
    Traceback (most recent call last):
    ...
    ValueError: '@' is not allowed: a Host is host[:port], without user information
    """
    text = authority.lower()
    if not text:
        raise ValueError("it is empty; expected host[:port]")
    for char in "@/?#\\":
        if char in text:
            what = ", without user information" if char == "@" else ", without a path"
            raise ValueError(f"{char!r} is not allowed: a Host is host[:port]{what}")
    if any(c.isspace() or not c.isprintable() or not c.isascii() for c in text):
        raise ValueError("it holds spaces, control or non-ASCII characters; expected host[:port]")
    if text.startswith("["):
        host, sep, rest = text.partition("]")
        host += "]"
        if not sep:
            raise ValueError("the IPv6 address has no closing ']'; expected [address]:port")
        try:
            ipaddress.IPv6Address(host[1:-1])
        except ValueError:
            raise ValueError(f"{host} is not an IPv6 address") from None
        if rest and not rest.startswith(":"):
            raise ValueError(f"{rest!r} follows the IPv6 address; expected [address]:port")
        port_text: Optional[str] = rest[1:] if rest else None
    else:
        if text.count(":") > 1:
            raise ValueError("it has more than one ':'; an IPv6 address goes in brackets, [::1]")
        host, sep, port = text.partition(":")
        port_text = port if sep else None
        if not host:
            raise ValueError("the host name is empty; expected host[:port]")
        if not _REG_NAME.fullmatch(host):
            raise ValueError(
                f"{host!r} is not a host name (letters, digits, '-' and '.') or an IP address"
            )
    if port_text is None:
        return host, None
    if not port_text.isdigit() or len(port_text) > 5 or not 0 < int(port_text) <= PORT_MAX:
        raise ValueError(f"the port {port_text!r} is not a number from 1 to {PORT_MAX}")
    return host, int(port_text)


def host_name(host: str) -> str:
    """Return the host of a ``Host`` header value, without the port, in lower case.

    Raises
    ------
    ValueError
        The value is not ``host[:port]`` (``parse_authority``).

    Examples
    --------
    >>> host_name("[::1]:8000"), host_name("LocalHost:80"), host_name("127.0.0.1")
    ('[::1]', 'localhost', '127.0.0.1')
    """
    return parse_authority(host.strip())[0]


def _host_port(authority: str, scheme: str) -> tuple[str, int]:
    """(host, port) of ``host[:port]``, the port defaulted from the scheme."""
    host, port = parse_authority(authority.strip())
    return host, port or (443 if scheme in ("https", "wss") else 80)


def same_origin(origin: str, scheme: str, host: str) -> bool:
    """Whether the browser ``origin`` is the service's own, reached as ``scheme://host``.

    The loopback names count as one host (``LOOPBACK``). An origin or host that is not
    ``scheme://host[:port]`` (``parse_authority``) is never the service's own.

    Examples
    --------
    >>> same_origin("http://localhost:8000", "http", "127.0.0.1:8000")
    True
    >>> same_origin("http://localhost:8001", "http", "127.0.0.1:8000")
    False
    >>> same_origin("http://evil.example:8000", "http", "127.0.0.1:8000")
    False
    >>> same_origin("http://127.0.0.1:8000@evil.example", "http", "127.0.0.1:8000@evil.example")
    False
    """
    o_scheme, sep, o_authority = origin.strip().lower().rstrip("/").partition("://")
    if not sep or o_scheme != scheme.lower():
        return False
    try:
        o_host, o_port = _host_port(o_authority, o_scheme)
        s_host, s_port = _host_port(host, scheme.lower())
    except ValueError:
        return False
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
                status, kind, message = problem
                body = error_body(kind, message, "Origin" if status == 403 else "Host")
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
    ) -> tuple[int, str, str] | None:
        if host is not None:
            try:
                name = host_name(host)
            except ValueError as exc:
                return 400, "InputError", f"the Host header {host!r} is malformed: {exc}"
            if "*" not in self.hosts and name not in self.hosts:
                return (
                    400,
                    "Forbidden",
                    (
                        f"host {name!r} is not served here; allowed: "
                        f"{', '.join(sorted(self.hosts))} (ROCKMECH_ALLOWED_HOSTS)"
                    ),
                )
        if origin is None or "*" in self.origins:
            return None
        origin = origin.strip().lower().rstrip("/")
        if same_origin(origin, str(scope.get("scheme", "http")), host or "") or (
            origin in self.origins
        ):
            return None
        return (
            403,
            "Forbidden",
            (
                f"requests from the web page origin {origin!r} are refused: a page in a browser "
                "may not use this service (ROCKMECH_ALLOWED_ORIGINS lists the origins allowed)"
            ),
        )
