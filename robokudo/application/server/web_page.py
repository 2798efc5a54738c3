"""The live view page, served over HTTP on the server's own port (a plain request there; WebSocket upgrades go
to the rosbridge protocol).

``GET /`` is the page (``?token=T`` when the server needs a token: the same token, compared in constant time; the
page then authenticates its socket with it), ``/app.js`` and ``/style.css`` its code and style (public, nothing
secret in them). The files are plain HTML, JavaScript and CSS shipped in ``web/`` (no build step, no CDN: the
machine may be offline). Anything else is 404.
"""

from __future__ import annotations

import hmac
from collections.abc import Callable
from http import HTTPStatus
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.http11 import Request, Response

WEB_FOLDER = Path(__file__).parent / "web"
PAGE = "/"
FILES = {PAGE: "index.html", "/app.js": "app.js", "/style.css": "style.css"}
CONTENT_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8", ".css": "text/css"}

RequestHandler = Callable[[ServerConnection, Request], Response | None]


def _response(status: HTTPStatus, content_type: str, body: bytes) -> Response:
    headers = Headers(
        [("Content-Type", content_type), ("Content-Length", str(len(body))), ("Cache-Control", "no-store")]
    )
    return Response(status.value, status.phrase, headers, body)


def _text(status: HTTPStatus, text: str) -> Response:
    return _response(status, "text/plain; charset=utf-8", text.encode())


def page_handler(token: str | None) -> RequestHandler:
    """The ``process_request`` hook serving the page files (see the module); None lets a WebSocket through."""

    def handle(connection: ServerConnection, request: Request) -> Response | None:
        if request.headers.get("Upgrade", "").lower() == "websocket":
            return None
        url = urlsplit(request.path)
        name = FILES.get(url.path)
        if name is None:
            return _text(HTTPStatus.NOT_FOUND, f"no page {url.path}; the live view is at /")
        if url.path == PAGE and token is not None:
            given = parse_qs(url.query).get("token", [""])[0]
            if not hmac.compare_digest(given.encode(), token.encode()):
                return _text(HTTPStatus.UNAUTHORIZED, "this server needs its token: open /?token=TOKEN")
        path = WEB_FOLDER / name
        return _response(HTTPStatus.OK, CONTENT_TYPES[path.suffix], path.read_bytes())

    return handle
