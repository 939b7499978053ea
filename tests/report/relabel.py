"""A recording copied with its run metadata changed: another robot's run, or a file from
before run ids (``frog_bt_run`` left out)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from mcap.reader import make_reader
from mcap.writer import Writer

from frog_bt.model.run import RUN_METADATA

Run = dict[str, str]


def relabel(src: Path, dst: Path, run: Callable[[Run], Run | None]) -> None:
    """Copy ``src`` to ``dst``, its ``frog_bt_run`` metadata replaced by ``run(old)``
    (None: left out), every other record as it was."""
    with open(src, "rb") as f_in, open(dst, "wb") as f_out:
        reader = make_reader(f_in)
        writer = Writer(f_out)
        writer.start(library=reader.get_header().library)
        for m in reader.iter_metadata():
            data = dict(m.metadata)
            if m.name == RUN_METADATA:
                new = run(data)
                if new is not None:
                    writer.add_metadata(m.name, new)
            else:
                writer.add_metadata(m.name, data)
        summary = reader.get_summary()
        assert summary is not None, f"{src}: no summary"
        schemas = {
            sid: writer.register_schema(s.name, s.encoding, s.data)
            for sid, s in summary.schemas.items()
        }
        channels = {
            cid: writer.register_channel(
                c.topic, c.message_encoding, schemas.get(c.schema_id, 0), dict(c.metadata)
            )
            for cid, c in summary.channels.items()  # those without messages too
        }
        for _, channel, message in reader.iter_messages(log_time_order=False):
            writer.add_message(
                channels[channel.id],
                message.log_time,
                message.data,
                message.publish_time,
                message.sequence,
            )
        writer.finish()
