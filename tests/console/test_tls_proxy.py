"""docs/CONSOLE.md's reverse-proxy example is valid nginx: ``nginx -t`` on it, with a
throwaway certificate. Skipped where nginx or openssl is not installed."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

DOC = Path(__file__).parents[2] / "docs" / "CONSOLE.md"
NGINX, OPENSSL = shutil.which("nginx"), shutil.which("openssl")


def example() -> str:
    found = re.findall(r"```nginx\n(.*?)```", DOC.read_text("utf-8"), re.DOTALL)
    assert len(found) == 1, "docs/CONSOLE.md has one nginx example"
    return str(found[0])


def test_the_example_is_there_and_keeps_host_and_the_websocket() -> None:
    text = example()
    for line in ("proxy_set_header Host $host;", "proxy_pass http://127.0.0.1:8080;", "Upgrade"):
        assert line in text


@pytest.mark.skipif(not (NGINX and OPENSSL), reason="nginx and openssl are not installed")
def test_nginx_accepts_the_example(tmp_path: Path) -> None:
    cert, key = tmp_path / "fullchain.pem", tmp_path / "privkey.pem"
    subprocess.run(
        [OPENSSL or "openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
         "-subj", "/CN=frog-1.museum.example", "-keyout", str(key), "-out", str(cert)],
        check=True,
        capture_output=True,
    )  # fmt: skip
    conf = tmp_path / "nginx.conf"
    text = example().replace("/etc/frog-bt/tls/", f"{tmp_path}/")
    conf.write_text(f"pid {tmp_path}/nginx.pid;\nerror_log {tmp_path}/error.log;\n{text}")
    checked = subprocess.run(
        [NGINX or "nginx", "-t", "-c", str(conf), "-p", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert checked.returncode == 0, checked.stderr
