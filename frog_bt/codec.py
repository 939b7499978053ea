"""msgspec for every wire: typed decoding whose errors are :class:`DecodeError`.

Both wires (rosbridge JSON, front-end datagrams) describe their messages as
msgspec Structs; this module holds what they share: the number types JSON
needs checked (finite floats, ROS integer widths), the decoder and converter
that turn msgspec's errors into a :class:`~frog_bt.errors.DecodeError` with the
path of the bad field (``pose.position.x: expected `float`, got `str```), and
compact encoding (NaN and Infinity are refused rather than sent).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from typing import Annotated, Any, TypeVar

import msgspec

from frog_bt.errors import DecodeError

T = TypeVar("T")

# A JSON number that is a finite float: msgspec turns 1e400 into an error, and these
# bounds refuse the infinities (and NaN) a Python caller could hand to convert().
Finite = Annotated[float, msgspec.Meta(ge=-sys.float_info.max, le=sys.float_info.max)]
Int32 = Annotated[int, msgspec.Meta(ge=-(2**31), le=2**31 - 1)]
UInt32 = Annotated[int, msgspec.Meta(ge=0, le=2**32 - 1)]

_AT = re.compile(r"^(?P<text>.*?)(?: - at `\$(?P<path>[^`]*)`)?$", re.DOTALL)
_STEP = re.compile(r"\.([^.\[]+)|\[(\d+)\]")
_MISSING = re.compile(r"^Object missing required field `(?P<name>[^`]+)`$")


def decode_error(exc: msgspec.MsgspecError) -> DecodeError:
    """msgspec's error as a DecodeError: its text, and its ``$.a[0].b`` path as a tuple.

    A missing field reads ``a.b: missing field`` (the path names the field)."""
    if not isinstance(exc, msgspec.ValidationError):
        return DecodeError(f"not JSON: {exc}"[:200])
    match = _AT.match(str(exc))
    assert match is not None  # the pattern matches any text
    path: list[str | int] = [
        name if name else int(index) for name, index in _STEP.findall(match["path"] or "")
    ]
    text = match["text"]
    missing = _MISSING.match(text)
    if missing:
        return DecodeError("missing field", (*path, missing["name"]))
    return DecodeError((text[:1].lower() + text[1:])[:200], path)


def decoder(type_: type[T]) -> Callable[[bytes | str], T]:
    """A JSON decoder for ``type_`` that raises only DecodeError."""
    decode = msgspec.json.Decoder(type_).decode

    def decode_json(data: bytes | str) -> T:
        try:
            return decode(data)
        except msgspec.MsgspecError as exc:
            raise decode_error(exc) from None
        except UnicodeError as exc:
            raise DecodeError(f"not UTF-8: {exc}"[:200]) from None
        except RecursionError:
            raise DecodeError("nested too deeply") from None

    return decode_json


def convert(obj: Any, type_: type[T]) -> T:
    """``obj`` (JSON-like Python values) as ``type_``; raises only DecodeError."""
    try:
        return msgspec.convert(obj, type_)
    except msgspec.MsgspecError as exc:
        raise decode_error(exc) from None
    except UnicodeError as exc:  # a lone surrogate in a str
        raise DecodeError(f"not valid text: {exc}"[:200]) from None
    except RecursionError:
        raise DecodeError("nested too deeply") from None


_ENCODER = msgspec.json.Encoder()


def encode(obj: Any) -> bytes:
    """Compact JSON of Structs and plain values; NaN and Infinity raise ValueError."""
    data = _ENCODER.encode(obj)
    if b"null" in data and _has_nonfinite(obj):  # msgspec writes NaN/inf as null
        raise ValueError("NaN or Infinity cannot be sent as JSON")
    return data


def _has_nonfinite(obj: Any) -> bool:
    if isinstance(obj, float):
        return obj - obj != 0.0
    if isinstance(obj, dict):
        return any(_has_nonfinite(v) for v in obj.values())
    if isinstance(obj, list | tuple):
        return any(_has_nonfinite(v) for v in obj)
    if isinstance(obj, msgspec.Struct):
        return any(_has_nonfinite(getattr(obj, f)) for f in obj.__struct_fields__)
    return False
