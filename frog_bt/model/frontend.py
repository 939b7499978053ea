"""Typed front-end datagrams (CONTRACT §2), as msgspec Structs.

Each message type is a frozen Struct with a class attribute ``type`` (its wire
name); its fields, with their types and ranges, are the datagram's fields
besides ``type`` and ``seq``. This is the front end's half of the wire table
(:mod:`frog_bt.model.wire`): the decoders, the encoders and the recording's schema
all come from these classes. :func:`decode_message` turns a datagram into one
of them or raises :class:`~frog_bt.errors.DecodeError`; :func:`message_fields`
gives the JSON fields of a message (without ``type`` and ``seq``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, Any, ClassVar, Literal, Union

import msgspec

from frog_bt.codec import convert, decoder
from frog_bt.errors import DecodeError
from frog_bt.model.outcomes import TourState
from frog_bt.text import FIELD, inert

Part = Literal["a", "b"]
Level = Annotated[float, msgspec.Meta(ge=-1.0, le=1.0)]
Percent = Annotated[int, msgspec.Meta(ge=0, le=100)]
Seq = Annotated[int, msgspec.Meta(ge=0)]


class FrontendMessage(msgspec.Struct, frozen=True):
    type: ClassVar[str] = ""


# ------------------------------------------------------------------ commands


class StartIntroduction(FrontendMessage, frozen=True):
    icl: bool
    type: ClassVar[str] = "start_introduction"


class AskTour(FrontendMessage, frozen=True):
    engaged: bool | None  # the visitor's engagement, or null: no data
    type: ClassVar[str] = "ask_tour"


class StartPoi(FrontendMessage, frozen=True):
    poi: str
    waypoint: str
    part: Part
    type: ClassVar[str] = "start_poi"


class FinishPoi(FrontendMessage, frozen=True):
    poi: str
    type: ClassVar[str] = "finish_poi"


class Engagement(FrontendMessage, frozen=True):
    level: Level | None
    type: ClassVar[str] = "engagement"


class FollowMe(FrontendMessage, frozen=True):
    on: bool
    type: ClassVar[str] = "follow_me"


class Volume(FrontendMessage, frozen=True):
    percent: Percent
    type: ClassVar[str] = "volume"


class SpecialContent(FrontendMessage, frozen=True):
    spot: str
    type: ClassVar[str] = "special_content"


class Projector(FrontendMessage, frozen=True):
    on: bool
    type: ClassVar[str] = "projector"


class Tour(FrontendMessage, frozen=True):
    state: TourState
    reason: str
    type: ClassVar[str] = "tour"


# ------------------------------------------------------------------ events


class FrontendIdle(FrontendMessage, frozen=True):
    type: ClassVar[str] = "frontend_idle"


class FinishIntroduction(FrontendMessage, frozen=True):
    type: ClassVar[str] = "finish_introduction"


class UserPositive(FrontendMessage, frozen=True):
    type: ClassVar[str] = "user_positive"


class UserNegative(FrontendMessage, frozen=True):
    type: ClassVar[str] = "user_negative"


class ContentDone(FrontendMessage, frozen=True):
    poi: str
    part: Part
    type: ClassVar[str] = "content_done"


COMMANDS: dict[str, type[FrontendMessage]] = {
    cls.type: cls
    for cls in (
        StartIntroduction,
        AskTour,
        StartPoi,
        FinishPoi,
        Engagement,
        FollowMe,
        Volume,
        SpecialContent,
        Projector,
        Tour,
    )
}
EVENTS: dict[str, type[FrontendMessage]] = {
    cls.type: cls
    for cls in (FrontendIdle, FinishIntroduction, UserPositive, UserNegative, ContentDone)
}


class Envelope(msgspec.Struct, frozen=True):
    """What every datagram has: its type and sequence number (any other fields are the
    message's). Read alone only to answer a datagram that did not decode whole."""

    type: str
    seq: Seq


decode_envelope = decoder(Envelope)


class Ack(msgspec.Struct, frozen=True, tag_field="type", tag="ack"):
    seq: Seq


def _datagram(cls: type[FrontendMessage]) -> type[msgspec.Struct]:
    """``cls`` as a whole datagram: its fields, ``seq``, and ``type`` as the union's tag."""
    return msgspec.defstruct(
        f"{cls.__name__}Datagram",
        [("seq", Seq)],
        bases=(cls,),
        tag_field="type",
        tag=cls.type,
        frozen=True,
        kw_only=True,
    )


class DatagramDecoder:
    """Datagrams whose messages are in ``table`` (or acks), decoded in one pass: a msgspec
    tagged union on ``type``. A message comes back as its plain class (without ``seq``)."""

    def __init__(self, table: dict[str, type[FrontendMessage]]) -> None:
        self.table = table
        datagrams = {_datagram(cls): cls for cls in table.values()}
        self._plain = datagrams
        # A Union made at run time is a type form, not a ``type[T]`` (no TypeForm before
        # PEP 747): what it decodes is an Ack or one of the datagram classes.
        self._decode: Callable[[bytes | str], Ack | FrontendMessage] = decoder(
            Union[(Ack, *datagrams)]  # type: ignore[arg-type]
        )

    def decode(self, data: bytes) -> tuple[int, FrontendMessage | None]:
        """``(seq, message)``, ``message`` None for an ack; DecodeError naming the field."""
        datagram = self._decode(data)
        if isinstance(datagram, Ack):
            return datagram.seq, None
        cls = self._plain[type(datagram)]
        seq: int = msgspec.structs.asdict(datagram)["seq"]  # the datagram class's own field
        values = (getattr(datagram, f) for f in cls.__struct_fields__)
        if cls.type in EVENTS:  # the front end's text, as the executive keeps it
            return seq, cls(*map(_inert, values))
        return seq, cls(*values)


def _inert(value: Any) -> Any:
    """A field of a front-end event as the tree may keep it: text bounded and inert."""
    return inert(value, FIELD) if isinstance(value, str) else value


def decode_message(
    obj: dict[str, Any] | bytes, table: dict[str, type[FrontendMessage]]
) -> FrontendMessage:
    """The typed message for a datagram (its bytes, or its JSON object) whose ``type``
    is in ``table``; other fields than the message's own are ignored."""
    type_ = obj.get("type") if isinstance(obj, dict) else decode_envelope(obj).type
    cls = table.get(type_) if isinstance(type_, str) else None
    if cls is None:
        raise DecodeError(f"unknown message type {type_!r}"[:200], ("type",))
    return convert(obj, cls) if isinstance(obj, dict) else _DECODERS[cls](obj)


_DECODERS = {cls: decoder(cls) for cls in (*COMMANDS.values(), *EVENTS.values())}


def message_fields(message: FrontendMessage) -> dict[str, Any]:
    return msgspec.structs.asdict(message)
