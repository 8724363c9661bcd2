"""Who may call a live session: this machine's own pages and tools, and holders of the token.

:class:`Guard` is an ASGI middleware that runs before any route (an unknown path too) and refuses:

* a ``Host`` header that is not one of the session's names (:func:`allowed_hosts`: the loopback
  names and the address served) — ``400``.  A page of another site can make its own host name
  resolve to ``127.0.0.1`` (DNS rebinding) and then read and write as if it were the live page;
  its requests still carry its own name in ``Host``.  Starlette's ``TrustedHostMiddleware`` does
  the same check; this one answers in the API's JSON refusal style;
* a request whose ``Origin`` is not the session's own (the scheme it was served over and the
  ``host:port`` of the ``Host`` it was sent to), or ``null`` — ``403``.  Browsers send ``Origin``
  with every cross-origin request and with every ``POST``, ``PATCH`` and ``DELETE``, ``no-cors``
  and bodiless ones too, so a page
  of another origin can neither change the session (a ``text/plain`` ``POST /requests``, a bare
  ``POST /stop``) nor read it.  A state-changing call that a browser marks ``Sec-Fetch-Site:
  cross-site`` or ``same-site`` is refused too.  ``curl`` sends no ``Origin``, the live page its own;
* with a token, a call without it — ``401`` (``Authorization: Bearer TOKEN`` or ``?token=TOKEN``).

docs/serve.md ("Who can drive the robot") is the threat model.
"""

from __future__ import annotations

import hmac
import ipaddress
import json
from collections.abc import Iterable
from urllib.parse import SplitResult, urlsplit

from starlette.datastructures import Headers, QueryParams
from starlette.types import ASGIApp, Receive, Scope, Send

from experiments.serve.strict import cut, shown

LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1")
"""The names by which this machine reaches itself: always allowed in ``Host``."""

UNSAFE = frozenset({"POST", "PUT", "PATCH", "DELETE"})
"""The methods that change the session."""

DEFAULT_PORT = {"http": 80, "https": 443}


def allowed_hosts(host: str) -> frozenset[str] | None:
    """The names a ``Host`` header may give for a server listening on ``host``: the loopback names
    and ``host`` itself; ``None`` (any) for a wildcard address (``0.0.0.0``, ``::``), which any name of
    the machine reaches — the token is then what protects it (``tasker serve`` requires one there)."""
    name = host.strip("[]").lower()
    try:
        if ipaddress.ip_address(name).is_unspecified:
            return None
    except ValueError:
        pass
    return frozenset({*LOOPBACK_NAMES, name})


class Guard:
    """The middleware of the module docstring: ``hosts`` allowed in ``Host`` (``None``: any),
    ``token`` required on every call when given."""

    def __init__(self, app: ASGIApp, *, hosts: Iterable[str] | None, token: str | None) -> None:
        self.app = app
        self.hosts = None if hosts is None else frozenset(h.lower() for h in hosts)
        self.token = token

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        refusal = self.refusal(scope)
        if refusal is None:
            await self.app(scope, receive, send)
            return
        status, field, message = refusal
        where = f"{scope['method']} {cut(scope['path'])}"
        body = json.dumps({"detail": f"{where}: {field}: {message}", "field": field, "message": message}).encode()
        headers = [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]
        if status == 401:
            headers.append((b"www-authenticate", b"Bearer"))
        await send({"type": "http.response.start", "status": status, "headers": headers})
        await send({"type": "http.response.body", "body": body})

    def refusal(self, scope: Scope) -> tuple[int, str, str] | None:
        """``(status, header, why)`` when the call is refused, else ``None``."""
        headers = Headers(scope=scope)
        host = _split(headers.get("host"))
        if host is None:
            return 400, "Host", f"expected this server's host[:port], got {shown(headers.get('host') or '')}"
        if self.hosts is not None and host.hostname not in self.hosts:
            return 400, "Host", (f"{shown(str(host.hostname))} is not a name of this server (DNS rebinding?): "
                                 f"it answers to {', '.join(sorted(self.hosts))}")
        origin = self.origin_refusal(scope, headers, host)
        if origin is not None:
            return origin
        if self.token is not None and not self.has_token(scope, headers):
            return 401, "token", ("missing or wrong token: send Authorization: Bearer TOKEN, or ?token=TOKEN "
                                  "(tasker serve printed it when it started)")
        return None

    @staticmethod
    def origin_refusal(scope: Scope, headers: Headers, host: SplitResult) -> tuple[int, str, str] | None:
        origins = headers.getlist("origin")
        if len(origins) > 1:
            return 403, "Origin", "more than one Origin header"
        if origins:
            origin = _split(origins[0], scheme=True)
            scheme = "https" if scope.get("scheme") in ("https", "wss") else "http"
            ours = (scheme, host.hostname, host.port or DEFAULT_PORT[scheme])
            if origin is None or (origin.scheme, origin.hostname, origin.port or DEFAULT_PORT[origin.scheme]) != ours:
                return 403, "Origin", (f"{shown(origins[0])} is another origin: only this server's own pages "
                                       "may call it")
        site = headers.get("sec-fetch-site", "").strip().lower()
        if scope["method"] in UNSAFE and site in ("cross-site", "same-site"):
            return 403, "Sec-Fetch-Site", f"a {site} request: only this server's own pages may change the session"
        return None

    def has_token(self, scope: Scope, headers: Headers) -> bool:
        assert self.token is not None
        auth = headers.get("authorization", "")
        if auth[:7].lower() == "bearer ":
            given = auth[7:].strip()
        else:
            given = QueryParams(scope.get("query_string", b"")).get("token", "")
        return hmac.compare_digest(given.encode("utf-8", "replace"), self.token.encode("utf-8"))


def _split(value: str | None, *, scheme: bool = False) -> SplitResult | None:
    """``host[:port]`` (or, with ``scheme``, an origin ``http[s]://host[:port]``) split, its host name
    lower-case and without brackets; ``None`` when it is not one (a path, a user, a bad port)."""
    if not value or len(value) > 300 or any(c.isspace() for c in value):
        return None
    try:
        parts = urlsplit(value if scheme else f"//{value}")
        parts.port  # noqa: B018 - a port that is no number, or out of range, raises here
    except ValueError:
        return None
    if (not parts.hostname or parts.username is not None or parts.path or parts.query or parts.fragment
            or parts.scheme not in (("http", "https") if scheme else ("",))):
        return None
    return parts
