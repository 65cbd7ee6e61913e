"""The studio's front door: an ASGI middleware that every request passes before a handler sees it.

- **Host**: only the address the server serves (its port; ``localhost``, ``127.0.0.1`` and ``[::1]`` for a
  loopback server) is answered; any other ``Host`` gets 421 (400 without one).  This stops DNS rebinding: a
  page at ``attacker.example`` that resolves to 127.0.0.1 sends ``Host: attacker.example``.
- **State-changing requests** (POST, PUT, PATCH, DELETE) come only from the studio's own page: they carry the
  server's random token in ``X-Mocycle-Token`` (the page reads it from the HTML the server gave it), a POST
  is ``Content-Type: application/json``, an ``Origin`` header when sent is the server's own, and
  ``Sec-Fetch-Site`` when sent is ``same-origin``; else 403 (415 for another content type).  A cross-site
  page can send none of these without a CORS preflight, which the studio never grants.
- **Cross-site reads**: an ``/api/`` request whose ``Sec-Fetch-Site`` says another site sent it is 403.
- **A server on the network** (``--host`` not loopback): every request needs the token, as ``?token=`` in the
  URL the command prints (the page's answer then sets it as a ``SameSite=Strict`` cookie), the header or
  the cookie; else 403.
- **Bodies**: a ``Content-Length`` above ``max_body`` is 413 before the body is read; a body streamed without
  one is cut off at ``max_body`` (413 too).
- **Headers on every answer**: ``Content-Security-Policy`` (own scripts only; the page's two inline scripts
  carry a per-answer nonce), ``frame-ancestors 'none'`` and ``X-Frame-Options: DENY``,
  ``X-Content-Type-Options: nosniff``, ``Referrer-Policy: no-referrer``.
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
from http import HTTPStatus
from http.cookies import SimpleCookie

from starlette.datastructures import MutableHeaders, QueryParams
from starlette.responses import JSONResponse

from .validate import HTTPProblem

#: largest request body, bytes (a 10-minute stroke at 120 Hz is about 3 MB of JSON)
MAX_BODY = 8 << 20
TOKEN_HEADER = "x-mocycle-token"
COOKIE = "mocycle_token"
LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1")
STATE_CHANGING = ("POST", "PUT", "PATCH", "DELETE")

PAGE_CSP = ("default-src 'self'; script-src 'self' 'nonce-{nonce}'; style-src 'self'; img-src 'self' data: blob:; "
            "connect-src 'self'; worker-src 'self' blob:; object-src 'none'; base-uri 'none'; form-action 'none'; "
            "frame-ancestors 'none'; require-trusted-types-for 'script'")
OTHER_CSP = "default-src 'none'; frame-ancestors 'none'; sandbox"
HEADERS = {"X-Frame-Options": "DENY", "X-Content-Type-Options": "nosniff", "Referrer-Policy": "no-referrer",
           "Cross-Origin-Resource-Policy": "same-origin", "Cross-Origin-Opener-Policy": "same-origin"}


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an address, IPv6 with or without brackets) is this machine only."""
    host = host.strip("[]").lower()
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def split_host(value: str) -> tuple[str, int | None]:
    """``Host`` header → (name without brackets, lower case; port or None).  Raises ValueError."""
    value = value.strip().lower()
    if value.startswith("["):
        name, _, rest = value[1:].partition("]")
        port = rest[1:] if rest.startswith(":") else None
        if rest and port is None:
            raise ValueError(value)
    else:
        name, sep, port = value.rpartition(":")
        if not sep:
            name, port = value, None
    if not name or (port is not None and not (port.isdigit() and len(port) <= 5)):
        raise ValueError(value)
    return name, None if port is None else int(port)


class Access:
    """The studio's access rules (see the module), shared by the app (``app.state.access``) and its
    :class:`Guard` middleware.

    ``token``: the server's secret (random when not given); ``host``/``port``: the address served, set again by
    :meth:`bind` once the socket is bound (``port=None``: any port of the allowed names, for tests).
    """

    def __init__(self, token: str | None = None, host: str = "127.0.0.1", port: int | None = None,
                 max_body: int = MAX_BODY):
        self.token = token or secrets.token_urlsafe(32)
        self.max_body = max_body
        self.bind(host, port)

    def bind(self, host: str, port: int | None) -> None:
        self.host, self.port = host.strip("[]").lower(), port
        self.remote = not is_loopback(host)

    # ------------------------------------------------------------ the rules
    def _host_problem(self, headers: dict) -> tuple[int, str] | None:
        value = headers.get("host")
        if not value:
            return 400, "a request needs a Host header"
        try:
            name, port = split_host(value)
        except ValueError:
            return 400, "the Host header is not a host name and port"
        if self.remote:  # every request carries the token; the names the network knows this machine by vary
            return None
        if name not in (*LOOPBACK_NAMES, self.host) or (self.port is not None and port not in (self.port,) and
                                                         not (port is None and self.port == 80)):
            return 421, f"this server answers only for {self.address()}, not {value[:80]!r}"
        return None

    def address(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{host}:{self.port}" if self.port is not None else host

    def _has_token(self, value: str | None) -> bool:
        if not value:
            return False
        return hmac.compare_digest(value.encode("utf-8", "replace"), self.token.encode())

    def _problem(self, scope, headers: dict) -> tuple[int, str] | None:
        problem = self._host_problem(headers)
        if problem:
            return problem
        method, path = scope["method"], scope["path"]
        site = headers.get("sec-fetch-site")
        query_token = QueryParams(scope.get("query_string", b"")).get("token")
        cookie = SimpleCookie()
        try:
            cookie.load(headers.get("cookie", ""))
        except Exception:  # a malformed cookie header is no token
            cookie = SimpleCookie()
        cookie_token = cookie[COOKIE].value if COOKIE in cookie else None
        header_token = headers.get(TOKEN_HEADER)
        if self.remote and not any(map(self._has_token, (header_token, query_token, cookie_token))):
            return 403, "this studio serves the network: open the URL it printed (with ?token=...)"
        if method in STATE_CHANGING:
            if site is not None and site != "same-origin":
                return 403, f"refused: a {method} from another site (Sec-Fetch-Site: {site[:20]})"
            origin = headers.get("origin")
            if origin is not None and origin != f"{scope.get('scheme', 'http')}://{headers['host']}":
                return 403, f"refused: a {method} from another origin ({origin[:80]})"
            if not self._has_token(header_token):
                return 403, f"refused: a {method} without the studio's token (the {TOKEN_HEADER} header)"
            if method == "POST":
                kind = headers.get("content-type", "").split(";")[0].strip().lower()
                if kind != "application/json":
                    return 415, "a POST must be Content-Type: application/json"
        elif path.startswith("/api/") and site in ("cross-site", "same-site"):
            return 403, f"refused: a request from another site (Sec-Fetch-Site: {site})"
        length = headers.get("content-length")
        if length is not None:
            if not length.isdigit():
                return 400, "Content-Length is not a number"
            if int(length) > self.max_body:
                return 413, f"the request body is {int(length)} bytes; at most {self.max_body}"
        return None



class Guard:
    """ASGI middleware: :class:`Access`'s rules before ``app``, its headers on every answer."""

    def __init__(self, app, access: Access):
        self.app, self.access = app, access

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        access = self.access
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        nonce = secrets.token_urlsafe(16)
        scope.setdefault("state", {})["csp_nonce"] = nonce
        set_cookie = access.remote and access._has_token(QueryParams(scope.get("query_string", b"")).get("token"))
        started = False

        async def send_guarded(message):
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
                out = MutableHeaders(scope=message)
                html = out.get("content-type", "").startswith("text/html")
                out["Content-Security-Policy"] = PAGE_CSP.format(nonce=nonce) if html else OTHER_CSP
                for k, v in HEADERS.items():
                    out[k] = v
                if set_cookie:
                    out.append("Set-Cookie", f"{COOKIE}={access.token}; Path=/; HttpOnly; SameSite=Strict")
            await send(message)

        problem = access._problem(scope, headers)
        if problem:
            await JSONResponse({"error": problem[1]}, status_code=problem[0])(scope, receive, send_guarded)
            return
        received = 0

        async def receive_limited():
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > access.max_body:
                    raise HTTPProblem(f"the request body is more than {access.max_body} bytes",
                                      HTTPStatus.REQUEST_ENTITY_TOO_LARGE)
            return message

        try:
            await self.app(scope, receive_limited, send_guarded)
        except HTTPProblem as exc:
            if started:
                raise
            await JSONResponse({"error": str(exc)}, status_code=exc.status)(scope, receive, send_guarded)
