"""Phones paired once, people named (CONTRACT §5: ``frog-bt ctl pair NAME``, ``ctl
devices``, ``ctl unpair NAME``): a phone paired through its one-time link sends a command
that the recording attributes to its name, and the report's "acknowledged by" shows it;
after ``ctl unpair`` its next command gets 401; a used or expired pairing link fails;
keys are kept hashed, 0600, and never logged."""

from __future__ import annotations

import asyncio
import json
import logging
import stat
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from console_tour import TOKEN, auth, console_tour

from frog_bt.cli import main
from frog_bt.live.console.devices import Devices, Pairings
from frog_bt.live.console.handover import who
from frog_bt.model.events import AlertChanged, OperatorDone
from frog_bt.offline.report.alerts import episodes
from frog_bt.offline.report.facts import AlertChange, OperatorCall
from frog_bt.runtime.observer import listen

NAME = "Lucía's phone"


def test_a_paired_phone_is_named_on_what_it_does_until_it_is_unpaired(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    token_file = tmp_path / "console-token"
    token_file.write_text(TOKEN + "\n")
    token_file.chmod(0o600)

    def ctl(*argv: str) -> tuple[int, str]:
        code = main([*argv, "--token-file", str(token_file), "--timeout", "30"])
        return code, capsys.readouterr().out

    async def run() -> dict[str, Any]:
        out: dict[str, Any] = {}
        caplog.set_level(logging.DEBUG)
        async with console_tour({}, once=False, token_file=token_file) as (tour, _p, url):
            exe = tour.executive
            done: list[OperatorDone] = []
            listen(exe, done.append, OperatorDone)
            # ctl pair NAME: a QR code of a one-time link, in the terminal
            out["pair"] = await asyncio.to_thread(ctl, "ctl", "pair", NAME, "--console", url)
            link = out["pair"][1].split("\n")[-3]
            assert link.startswith(f"{url}/pair#"), out["pair"][1]
            code = link.partition("#")[2]
            async with aiohttp.ClientSession() as s:
                async with s.get(f"{url}/pair") as r:  # the page the phone opens
                    out["page"] = (r.status, r.headers["Content-Security-Policy"])
                claim = {"code": code}
                async with s.post(f"{url}/api/pair/claim?lang=es", json=claim) as r:
                    out["claim"] = (r.status, await r.json())
                async with s.post(f"{url}/api/pair/claim?lang=es", json=claim) as r:
                    out["again"] = (r.status, await r.json())
                phone = {"Authorization": f"Bearer {out['claim'][1]['key']}"}
                async with s.post(
                    f"{url}/api/command", json={"command": "service_off"}, headers=phone
                ) as r:
                    out["command"] = (r.status, await r.json())
                # an alert the phone marks seen: the recording and the report name it
                book = exe.staff.book
                changes: list[AlertChanged] = []
                listen(exe, changes.append, AlertChanged)
                book.cfg = book.cfg.model_copy(update={"battery_below": 100.0})
                await tour.executive_ticks_until(lambda: "battery_low" in book.active, 60)
                ack = {"command": "ack_alert", "id": "battery_low"}
                async with s.post(f"{url}/api/command", json=ack, headers=phone) as r:
                    out["ack"] = (r.status, await r.json())
                # a paired phone may show a pairing code, but not manage devices
                async with s.post(f"{url}/api/pair", json={"name": "tablet"}, headers=phone) as r:
                    out["phone pairs"] = (r.status, (await r.json()).get("qr", {}).get("size"))
                async with s.get(f"{url}/api/devices", headers=phone) as r:
                    out["phone lists"] = r.status
                out["devices"] = await asyncio.to_thread(ctl, "ctl", "devices", "--console", url)
                out["unpair"] = await asyncio.to_thread(
                    ctl, "ctl", "unpair", NAME, "--console", url
                )
                async with s.post(
                    f"{url}/api/command", json={"command": "service_on"}, headers=phone
                ) as r:
                    out["after"] = r.status
                async with s.post(
                    f"{url}/api/command", json={"command": "service_on"}, headers=auth()
                ) as r:
                    out["staff token"] = r.status
            out["done"] = done
            out["changes"] = changes
            exe.stop("test over")
        return out

    out = asyncio.run(run())
    assert out["pair"][0] == 0 and "▀" in out["pair"][1]  # the QR code, in half blocks
    assert "5 min" in out["pair"][1]  # staff.pairing_ttl: 300 s
    assert out["page"][0] == 200 and "script-src 'self'" in out["page"][1]
    status, claimed = out["claim"]
    assert status == 200 and claimed["name"] == NAME and len(claimed["key"]) == 43
    assert claimed["said"].startswith(f"Este teléfono está emparejado como {NAME}")
    assert out["again"][0] == 410 and "ya se ha usado" in out["again"][1]["reason"]
    assert out["command"][0] == 200
    assert out["ack"][0] == 200
    by = [(d.command, d.by) for d in out["done"] if d.ok]
    assert ("service_off", f"device:{NAME}") in by and ("ack_alert", f"device:{NAME}") in by
    assert ("service_on", "console") in by  # the shared token still works, for scripts
    assert who(f"device:{NAME}") == NAME
    assert out["phone pairs"] == (200, 41) and out["phone lists"] == 403
    assert out["devices"][0] == 0 and NAME in out["devices"][1]
    assert out["unpair"] == (0, f"hecho: {NAME} desemparejado: su clave ya no sirve\n")
    assert out["after"] == 401 and out["staff token"] == 200

    # the report's "acknowledged by": the episode's acknowledgement names the phone
    calls = [
        OperatorCall(d.t, d.command, d.ok, d.text, d.id, d.by)
        for d in out["done"]
        if d.command == "ack_alert"
    ]
    alerts = [
        AlertChange(c.t, c.alert.id, c.alert.kind, c.alert.state, c.alert.severity)
        for c in out["changes"]
    ]
    [episode] = [e for e in episodes(alerts, calls) if e.kind == "battery_low"]
    assert episode.acknowledged_by == f"device:{NAME}"

    # kept beside the token file, 0600, hashed: no key in it, and none in the log
    kept = token_file.with_name("console-token.devices")
    assert stat.S_IMODE(kept.stat().st_mode) == 0o600
    assert json.loads(kept.read_text())["devices"] == []  # unpaired
    key = out["claim"][1]["key"]
    assert key not in caplog.text and code_not_logged(caplog.text)


def code_not_logged(text: str) -> bool:
    return "/pair#" not in text


def test_a_pairing_code_works_once_and_not_after_it_expires() -> None:
    now = [1000.0]
    codes = Pairings(ttl=300.0, clock=lambda: now[0])
    first = codes.issue(NAME)
    assert codes.claim(first) == NAME
    assert codes.claim(first) is None  # used
    late = codes.issue(NAME)
    now[0] += 300.5
    assert codes.claim(late) is None  # expired
    assert codes.claim("x" * 500) is None and codes.claim(None) is None


def test_devices_are_found_by_their_key_alone(tmp_path: Path) -> None:
    devices = Devices(tmp_path / "devices", clock=lambda: 5.0)
    key = devices.pair(NAME)
    other = devices.pair("tablet")
    assert devices.find(key.encode()).name == NAME  # type: ignore[union-attr]
    assert devices.find(other.encode()).name == "tablet"  # type: ignore[union-attr]
    assert devices.find(key[:-1].encode()) is None
    assert devices.find(b"x" * 10_000) is None and devices.find(None) is None
    again = Devices(tmp_path / "devices")  # read back after a restart
    assert again.find(key.encode()) is not None
    assert key not in (tmp_path / "devices").read_text()
    with pytest.raises(ValueError):
        devices.pair(NAME)
