"""Reading a recording, whole or cut short.

:func:`open_recording` gives a :class:`RecordingFile`: its channels' schema names,
its first and last message times, its ``frog_bt`` metadata (see
:mod:`frog_bt.live.rotation`) and an iterator over its messages in log-time order.

A file frog-bt wrote is read front to back (the recorder writes in log-time order,
and reading in file order skips the reader's merge heap); any other MCAP is read
through its index in log-time order. A file without its summary and footer (the
writer was killed, the power went) is *recovered*: read front to back up to where
it was cut, every complete chunk (the recorder closes one at least every second)
kept. :attr:`RecordingFile.recovered` then says what was found.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Channel, DataEnd, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from frog_bt.errors import FrogError

MCAP_MAGIC = b"\x89MCAP0\r\n"
READ_ERRORS = (
    McapError,
    ValueError,
    EOFError,
    OSError,
    IndexError,
    struct.error,
    KeyError,
    RuntimeError,
)  # what a damaged file makes the mcap reader raise


class RecordingError(FrogError):
    """The file cannot be read as a recording (not a file, not MCAP, nothing in it)."""


@dataclass(slots=True)
class RecordingFile:
    path: Path
    types: dict[str, str]  # channel topic -> schema name
    start: int  # first and last message log times, ns (0 without messages)
    end: int
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    ours: bool = False  # written by frog-bt: file order is log-time order
    recovered: str = ""  # a file cut short: what was recovered from it
    messages_read: int = 0  # recovered files: messages before the cut

    def messages(self) -> Iterator[tuple[str, int, bytes]]:
        """(topic, log time in ns, data) of every message, in log-time order; for a
        recovered file, up to the cut."""
        if self.ours or self.recovered:
            yield from _linear(self.path)
            return
        with open(self.path, "rb") as stream:
            reader = make_reader(stream)
            for _schema, channel, message in reader.iter_messages(log_time_order=True):
                yield channel.topic, message.log_time, message.data


def _linear(path: Path) -> Iterator[tuple[str, int, bytes]]:
    """Messages front to back, stopping quietly where the file is cut or damaged."""
    topics: dict[int, str] = {}
    with open(path, "rb") as stream:
        records = StreamReader(stream, record_size_limit=1 << 30).records
        while True:
            try:
                record = next(records)
            except StopIteration:
                return
            except READ_ERRORS:
                return  # the cut
            if isinstance(record, Message):
                topic = topics.get(record.channel_id)
                if topic is not None:
                    yield topic, record.log_time, record.data
            elif isinstance(record, Channel):
                topics[record.id] = record.topic
            elif isinstance(record, DataEnd):
                return


def open_recording(path: Path) -> RecordingFile:
    """The recording at ``path``; :class:`RecordingError` when it is none."""
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f"{path}: not a file")
    with open(path, "rb") as stream:
        if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            raise RecordingError(f"{path}: not an MCAP file")
        stream.seek(0)
        whole = _summarised(path, stream)
    return whole if whole is not None else _recover(path)


def _summarised(path: Path, stream: IO[bytes]) -> RecordingFile | None:
    """From the summary at the end; None when the file has none (cut short)."""
    try:
        reader = make_reader(stream)
        summary = reader.get_summary()
        header = reader.get_header()
        if summary is None:
            return None
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    except READ_ERRORS:
        return None
    schemas = summary.schemas
    types = {
        ch.topic: schemas[ch.schema_id].name if ch.schema_id in schemas else ""
        for ch in summary.channels.values()
    }
    stats = summary.statistics
    return RecordingFile(
        path,
        types,
        stats.message_start_time if stats else 0,
        stats.message_end_time if stats else 0,
        metadata,
        ours=header.library.startswith("frog-bt"),
    )


def _recover(path: Path) -> RecordingFile:
    """Front to back up to the cut: channels, metadata and the time span found."""
    schemas: dict[int, str] = {}
    types: dict[str, str] = {}
    metadata: dict[str, dict[str, str]] = {}
    start = end = count = 0
    ours = False
    with open(path, "rb") as stream:
        records = StreamReader(stream, record_size_limit=1 << 30).records
        while True:
            try:
                record = next(records)
            except (StopIteration, *READ_ERRORS):
                break
            if isinstance(record, Message):
                count += 1
                start = record.log_time if count == 1 else min(start, record.log_time)
                end = max(end, record.log_time)
            elif isinstance(record, Schema):
                schemas[record.id] = record.name
            elif isinstance(record, Channel):
                types[record.topic] = schemas.get(record.schema_id, "")
            elif isinstance(record, Metadata):
                metadata[record.name] = dict(record.metadata)
            elif isinstance(record, Header):
                ours = record.library.startswith("frog-bt")
            elif isinstance(record, DataEnd):
                break
    if not types:
        raise RecordingError(f"{path}: damaged MCAP file, nothing readable in it")
    seconds = (end - start) / 1e9 if count else 0.0
    return RecordingFile(
        path,
        types,
        start,
        end,
        metadata,
        ours=ours,
        messages_read=count,
        recovered=f"cut short (no summary or footer): recovered {count} messages, {seconds:.1f} s",
    )
