"""A pairing link as a QR code (segno, pure Python: the ``console`` extra): for a terminal
(``frog-bt ctl pair``) and for the page, as the data of one SVG path, which the page sets
as an attribute (text-safe under its strict policy: no markup is parsed)."""

from __future__ import annotations

import io
import re
from typing import Any

import segno  # ImportError here: the console extra lacks it (pairing.py, ctl.py say so)

_SVG_PATH = re.compile(r'<path[^>]* d="([^"]+)"')
_SIZE = re.compile(r'<svg[^>]* width="(\d+)" height="(\d+)"')


def _code(text: str) -> Any:
    return segno.make(text, error="m", micro=False)


def svg_path(text: str) -> dict[str, Any]:
    """``{"size": N, "path": D}``: segno's SVG of ``text`` (scale 1, a quiet zone of 4)
    as its viewBox size and the ``d`` of its one path (dark modules, drawn with a
    stroke of 1)."""
    out = io.BytesIO()
    _code(text).save(out, kind="svg", xmldecl=False, svgns=True, nl=False, scale=1, border=4)
    svg = out.getvalue().decode("ascii")
    size, path = _SIZE.search(svg), _SVG_PATH.search(svg)
    if size is None or path is None:  # segno's SVG writer changed its shape
        raise ValueError("segno gave an SVG without one path")
    return {"size": int(size.group(1)), "path": path.group(1)}


def terminal(text: str) -> str:
    """``text`` as a QR code of half blocks, for a terminal (dark on light)."""
    out = io.StringIO()
    _code(text).terminal(out=out, compact=True, border=2)
    return out.getvalue()
