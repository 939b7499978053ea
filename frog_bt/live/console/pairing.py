"""Phones paired once (:mod:`~.devices`), over HTTP:

* ``POST /api/pair`` ``{"name": NAME}`` — someone signed in (the staff token, or a paired
  device) asks for a one-time pairing link for a new device called NAME: ``{"ok": true,
  "link", "expires_in", "qr": {"size", "path"}}``. The link is ``{console}/pair#CODE``:
  the code is in the fragment, which a browser never sends to a server;
* ``GET /pair`` (and ``/pair.js``) — the page the link opens on the phone: its script
  reads the code from the fragment, removes it from the address bar and claims it;
* ``POST /api/pair/claim`` ``{"code": CODE}`` (no token: the code is the credential) —
  once, within ``staff.pairing_ttl``: ``{"ok": true, "key", "name"}``, the device's own
  key, which the phone keeps in its browser (``localStorage``) and sends from then on as
  ``Authorization: Bearer KEY``. A used, expired or unknown code is 410 and counts as a
  failed attempt (:mod:`~.throttle`);
* ``GET /api/devices`` and ``POST /api/unpair`` ``{"name"}`` — with the staff token only
  (``frog-bt ctl devices``, ``ctl unpair NAME``): the devices (name, paired at, last
  seen), and a device revoked at once.

Keys and codes are never logged; names are plain text, bounded (:func:`~.devices.name_problem`).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from aiohttp import web

from frog_bt.i18n import Msg, say
from frog_bt.live.console.bearer import bearer, matches
from frog_bt.live.console.devices import Device, Devices, Pairings, name_problem
from frog_bt.live.console.throttle import Failures
from frog_bt.text import inert

__all__ = ["DEVICE", "PAIR_DESK", "ROUTES", "PairDesk", "device_of"]

log = logging.getLogger(__name__)
if log.level == logging.NOTSET:  # a device paired or revoked: at INFO, always in the log
    log.setLevel(logging.INFO)
CLAIM = "/api/pair/claim"  # the one /api path that needs no token


@dataclass
class PairDesk:
    """What the pairing routes work with: the devices, the codes waiting, the staff
    token, the failed attempts and who the client is, and the console's address as a
    phone reaches it (``public()``)."""

    devices: Devices
    pairings: Pairings
    token: str | None
    failures: Failures
    client: Callable[[web.Request], str]
    public: Callable[[web.Request], str]
    language: Callable[[web.Request], str]  # the answer's: ?lang=, else the site's


PAIR_DESK = web.AppKey("pair_desk", PairDesk)
DEVICE = web.RequestKey("frog_bt.device", Device)  # the paired device that sent it


def device_of(request: web.Request) -> Device | None:
    """The paired device a request came from (None: the staff token, or no one)."""
    found = request.get(DEVICE)
    return found if isinstance(found, Device) else None


def _refuse(request: web.Request, status: int, reason: Msg) -> web.Response:
    lang = request.app[PAIR_DESK].language(request)
    return web.json_response(
        {"ok": False, "reason": say(reason, lang), "language": lang}, status=status
    )


async def _body(request: web.Request) -> dict[str, Any]:
    try:
        body = json.loads((await request.read()).decode("utf-8"))
    except (ValueError, UnicodeDecodeError, RecursionError):
        return {}
    return body if isinstance(body, dict) else {}


def _staff_token(request: web.Request, desk: PairDesk) -> bool:
    return matches(bearer(request.headers.get("Authorization")), desk.token)


async def post_pair(request: web.Request) -> web.Response:
    try:
        from frog_bt.live.console.qr import svg_path
    except ImportError:  # an install of the console extra from before segno joined it
        return _refuse(request, 409, Msg("pairing needs segno: pip install -e '.[console]'"))
    desk = request.app[PAIR_DESK]
    if desk.devices.path is None:
        return _refuse(
            request, 409, Msg("pairing needs the console's token file (where devices are kept)")
        )
    name = (await _body(request)).get("name")
    problem = name_problem(name)
    if problem:
        return _refuse(request, 400, problem)
    assert isinstance(name, str)
    if name in desk.devices.devices:
        return _refuse(request, 409, _taken(name))
    code = desk.pairings.issue(name)
    link = f"{desk.public(request)}/pair#{code}"
    return web.json_response(
        {
            "ok": True,
            "link": link,
            "expires_in": desk.pairings.ttl,
            "qr": svg_path(link),
            "language": desk.language(request),
        }
    )


async def post_claim(request: web.Request) -> web.Response:
    desk = request.app[PAIR_DESK]
    name = desk.pairings.claim((await _body(request)).get("code"))
    if name is None:
        if desk.failures.failed(desk.client(request)):
            return _refuse(request, 429, Msg("too many failed attempts: wait a minute"))
        return _refuse(
            request,
            410,
            Msg("this pairing link was used already or has expired: ask for a new one"),
        )
    if name in desk.devices.devices:
        return _refuse(request, 409, _taken(name))
    try:
        key = desk.devices.pair(name)
    except ValueError:
        return _refuse(request, 409, Msg("too many devices are paired: unpair one first"))
    except OSError as exc:
        log.warning("paired devices: cannot write %s: %s", desk.devices.path, exc.strerror or exc)
        return _refuse(
            request, 503, Msg("the console cannot keep paired devices (its file cannot be written)")
        )
    log.info("device paired: %s", inert(name, 64))
    lang = desk.language(request)
    said = Msg(
        "This phone is paired as {name}: it opens the console without the staff code.",
        name=name,
    )
    return web.json_response(
        {
            "ok": True,
            "key": key,
            "name": name,
            "said": say(said, lang),
            "open": say(Msg("Open the console"), lang),
            "language": lang,
        }
    )


async def get_devices(request: web.Request) -> web.Response:
    desk = request.app[PAIR_DESK]
    if not _staff_token(request, desk):
        return _refuse(request, 403, Msg("only the staff token (frog-bt ctl) manages devices"))
    return web.json_response(
        {"ok": True, "devices": desk.devices.listed(), "language": desk.language(request)}
    )


async def post_unpair(request: web.Request) -> web.Response:
    desk = request.app[PAIR_DESK]
    if not _staff_token(request, desk):
        return _refuse(request, 403, Msg("only the staff token (frog-bt ctl) manages devices"))
    name = (await _body(request)).get("name")
    problem = name_problem(name)
    if problem:
        return _refuse(request, 400, problem)
    assert isinstance(name, str)
    lang = desk.language(request)
    try:
        gone = desk.devices.unpair(name)
    except OSError as exc:
        log.warning("paired devices: cannot write %s: %s", desk.devices.path, exc.strerror or exc)
        did = Msg(
            "{name} unpaired now, but back after a restart: the devices file cannot be written",
            name=name,
        )
        return web.json_response({"ok": True, "did": say(did, lang), "language": lang})
    if not gone:
        return _refuse(
            request, 409, Msg("no device called {name} (frog-bt ctl devices lists them)", name=name)
        )
    log.info("device unpaired: %s", inert(name, 64))
    did = Msg("{name} unpaired: its key no longer works", name=name)
    return web.json_response({"ok": True, "did": say(did, lang), "language": lang})


def _taken(name: str) -> Msg:
    return Msg("a device called {name} is paired already: unpair it first", name=name)


async def get_pair_page(request: web.Request) -> web.Response:
    from importlib import resources

    page = resources.files("frog_bt.live.console").joinpath("pair.html").read_text("utf-8")
    return web.Response(text=page, content_type="text/html")


async def get_pair_script(request: web.Request) -> web.Response:
    from importlib import resources

    script = resources.files("frog_bt.live.console").joinpath("pair.js").read_text("utf-8")
    return web.Response(text=script, content_type="text/javascript")


ROUTES = [
    web.get("/pair", get_pair_page),
    web.get("/pair.js", get_pair_script),
    web.post("/api/pair", post_pair),
    web.post(CLAIM, post_claim),
    web.get("/api/devices", get_devices),
    web.post("/api/unpair", post_unpair),
]
