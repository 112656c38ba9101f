"""Who the web console answers, over real HTTP and WebSocket on a free port: the page, its files and its socket need
the run's token (the page hands its files a cookie), and a request from another origin or site is refused with 403
whatever its token."""

from __future__ import annotations

import json
import urllib.error
import urllib.request

import pytest
from aeroexec.console.server import ConsoleServer
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

WAIT = 60.0  # s: any answer on a loaded machine


@pytest.fixture
def console():
    server = ConsoleServer(replay={"mission": "access.xml", "records": []}).start()
    yield server
    server.close()


def get(server: ConsoleServer, path: str, **headers: str) -> tuple[int, str, dict[str, str]]:
    """Status, body and headers of a GET to the console (an HTTP error's too)."""
    request = urllib.request.Request(f"http://127.0.0.1:{server.port}{path}", headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=WAIT) as response:
            return response.status, response.read().decode(), dict(response.headers)
    except urllib.error.HTTPError as error:
        return error.code, error.read().decode(), dict(error.headers)


def test_the_pages_files_need_the_token_or_the_cookie_the_page_set(console):
    for path in ("/static/index.html", "/static/console.js", "/static/console.css", "/static/map.js", "/static/"):
        status, body, _ = get(console, path)
        assert (status, body) == (403, "403: this console needs its token (the URL aeroexec printed)"), path
    assert get(console, "/static/index.html?token=wrong")[0] == 403
    assert get(console, "/static/console.js", Cookie=f"{console.cookie}=wrong")[0] == 403
    assert get(console, "/")[0] == 403
    status, page, headers = get(console, f"/?token={console.token}")
    assert status == 200 and "<title>aeroexec console</title>" in page
    cookie = headers["set-cookie"]
    assert cookie.startswith(f"{console.cookie}={console.token};") and "HttpOnly" in cookie and \
        "SameSite=strict" in cookie
    for path in ("/static/console.js", "/static/console.css", "/static/map.js"):  # as the page loads them
        assert get(console, path, Cookie=f"{console.cookie}={console.token}")[0] == 200, path
    assert get(console, f"/static/console.js?token={console.token}")[0] == 200


def test_a_request_from_another_origin_or_site_is_refused_whatever_its_token(console):
    own = f"http://127.0.0.1:{console.port}"
    page = f"/?token={console.token}"
    assert get(console, page, Origin=own)[0] == 200
    for headers in ({"Origin": "http://evil.example"}, {"Origin": "null"},
                    {"Origin": f"http://127.0.0.1:{console.port + 1}"}, {"Sec-Fetch-Site": "cross-site"},
                    {"Sec-Fetch-Site": "same-site"}):  # another port of this machine is the same site
        status, body, _ = get(console, page, **headers)
        assert status == 403 and "is refused: the console answers its own page only" in body, headers
        assert get(console, "/static/console.js", Cookie=f"{console.cookie}={console.token}", **headers)[0] == 403
    socket = f"ws://127.0.0.1:{console.port}/ws?token={console.token}"
    with pytest.raises(InvalidStatus) as refused:
        connect(socket, origin="http://evil.example", open_timeout=WAIT)
    assert refused.value.response.status_code == 403
    with connect(socket, origin=own, open_timeout=WAIT) as ws:  # the console's own page
        hello = json.loads(ws.recv(timeout=WAIT))
        assert hello["type"] == "hello" and hello["read_only"]
