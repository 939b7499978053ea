"""The page a notification's acknowledgement link opens, and the button on it.

``GET /ack/{alert_id}?at=&exp=&sig=`` changes nothing: it checks the link
(:mod:`~frog_bt.live.console.acklink`) and shows, in the site's language, which robot's
alert it would acknowledge, with one button. Only that button's ``POST`` (the same URL:
the link's signature is the capability, and the console's ``Origin`` check refuses other
sites' pages) acknowledges, through the staff queue like ``ack_alert``, and only the raise
the link names: a later raise of the same alert, another robot's alert, a used, expired or
tampered link acknowledge nothing. So a chat app's link preview, a mail scanner or a
link checker acknowledge nothing either.

A link works once: its signature is kept as used (until it expires, at most
:data:`MAX_USED`), and the raise it names is acknowledged. Bad links count as failed
attempts (:class:`~frog_bt.live.console.throttle.Failures`).

The pages are plain: no script, no style, nothing fetched, never cached; the policy
allows only a form posting back here.
"""

from __future__ import annotations

import html
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from aiohttp import web

from frog_bt.engine.operator import Command
from frog_bt.i18n import Msg, language, say
from frog_bt.live.console.acklink import Verdict, verify
from frog_bt.live.console.throttle import Failures, Rates

if TYPE_CHECKING:
    from frog_bt.model.channels import Alert
    from frog_bt.runtime.executive import Executive

MAX_USED = 1024  # used links remembered (each until it expires); the oldest go first
PAGE_HEADERS = {
    # the one form posts back here; a same-origin POST carries its Origin (not "null")
    "Content-Security-Policy": "default-src 'none'; form-action 'self'; frame-ancestors 'none'",
    "X-Content-Type-Options": "nosniff",
    "X-Frame-Options": "DENY",
    "Cache-Control": "no-store",
    "Referrer-Policy": "same-origin",
}


@dataclass
class AckDesk:
    """What the acknowledgement pages need: the executive (its alerts, its staff queue,
    the site's language and robot), the links' key (None: no token, no link is valid),
    the console's throttles and a way to tell its pages that something changed."""

    executive: Executive
    key: bytes | None
    failures: Failures
    rates: Rates
    client: Callable[[web.Request], str]
    changed: Callable[[], None]
    wall: Callable[[], float] = time.time
    used: OrderedDict[str, int] = field(default_factory=OrderedDict)  # sig -> its expiry

    def spend(self, sig: str, exp: int) -> None:
        now = self.wall()
        for old in [s for s, e in self.used.items() if e <= now]:
            del self.used[old]
        self.used[sig] = exp
        while len(self.used) > MAX_USED:
            self.used.popitem(last=False)


ACK_DESK = web.AppKey("ack_desk", AckDesk)


def page(
    status: int, lang: str, title: Msg, text: str | Msg, button: Msg | None = None
) -> web.Response:
    """A small page of text in ``lang``; with ``button``, one form posting back here."""
    title_text = html.escape(say(title, lang))
    form = (
        f'\n<form method="post"><button type="submit">{html.escape(say(button, lang))}'
        "</button></form>"
        if button is not None
        else ""
    )
    body = (
        f'<!doctype html>\n<html lang="{lang}"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width">'
        f"<title>{title_text}</title></head>\n<body><h1>{title_text}</h1>"
        f"\n<p>{html.escape(say(text, lang))}</p>{form}</body></html>\n"
    )
    return web.Response(status=status, text=body, content_type="text/html", headers=PAGE_HEADERS)


@dataclass(frozen=True, slots=True)
class Link:
    alert_id: str
    at: str
    exp: str
    sig: str

    @classmethod
    def of(cls, request: web.Request) -> Link:
        q = request.query
        return cls(
            request.match_info["alert_id"], q.get("at", ""), q.get("exp", ""), q.get("sig", "")
        )


def _check(desk: AckDesk, request: web.Request, link: Link) -> web.Response | Alert:
    """The alert raise ``link`` acknowledges, or the page that says why none."""
    lang = language(desk.executive.site.language)
    robot = desk.executive.site.alerts.robot
    verdict = (
        verify(desk.key, robot, link.alert_id, link.at, link.exp, link.sig, desk.wall())
        if desk.key is not None
        else Verdict.BAD
    )
    if verdict is Verdict.EXPIRED:
        return page(
            403,
            lang,
            Msg("Link expired"),
            Msg(
                "This link has expired: nothing was acknowledged. "
                "Open the console to see the alerts."
            ),
        )
    if verdict is not Verdict.VALID:
        throttled = desk.failures.failed(desk.client(request))
        return page(
            429 if throttled else 403,
            lang,
            Msg("Not a valid link"),
            Msg("This link is not valid: nothing was acknowledged."),
        )
    if link.sig in desk.used:
        return page(
            409,
            lang,
            Msg("Link already used"),
            Msg("This link was used already: nothing more was acknowledged."),
        )
    alert = desk.executive.staff.book.unacknowledged.get(link.alert_id)
    if alert is None or alert.occurrence != link.at:
        return page(
            409,
            lang,
            Msg("Nothing to acknowledge"),
            Msg(
                "This alert was acknowledged already, or raised again since (its new "
                "notification carries a new link): nothing was acknowledged."
            ),
        )
    return alert


async def get_ack(request: web.Request) -> web.Response:
    """``GET``: what the link would acknowledge, and one button. Changes nothing."""
    desk = request.app[ACK_DESK]
    link = Link.of(request)
    alert = _check(desk, request, link)
    if isinstance(alert, web.Response):
        return alert
    site = desk.executive.site
    return page(
        200,
        language(site.language),
        Msg("Acknowledge this alert?"),
        Msg("Robot {robot}: {text}", robot=site.alerts.robot, text=alert.text),
        button=Msg("Acknowledge"),
    )


async def post_ack(request: web.Request) -> web.Response:
    """``POST``: the button. Acknowledges the raise the link names, once."""
    desk = request.app[ACK_DESK]
    lang = language(desk.executive.site.language)
    link = Link.of(request)
    alert = _check(desk, request, link)
    if isinstance(alert, web.Response):
        return alert
    if not desk.rates.take(desk.client(request)):
        return page(429, lang, Msg("Too many requests"), Msg("Wait a second, then try again."))
    answer = await desk.executive.staff.submit(
        Command.ACK_ALERT, link.alert_id, by="link", occurrence=link.at
    )
    desk.changed()
    if not answer.ok:
        return page(
            409, lang, Msg("Nothing acknowledged"), Msg("Not done: {why}.", why=answer.words)
        )
    desk.spend(link.sig, int(link.exp))
    return page(200, lang, Msg("Acknowledged"), Msg("Done: {what}. Thank you.", what=answer.words))
