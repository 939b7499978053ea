"""The recorder's speed-ups of mcap's writer write mcap's own bytes."""

from __future__ import annotations

import io

import mcap.writer
import zstandard
from hypothesis import given
from hypothesis import strategies as st
from mcap.data_stream import RecordBuilder
from mcap.reader import make_reader
from mcap.records import MessageIndex
from mcap.writer import CompressionType, Writer

from frog_bt.live import mcap_speed

U64 = st.integers(min_value=0, max_value=2**64 - 1)


@given(
    channel=st.integers(min_value=0, max_value=2**16 - 1),
    entries=st.lists(st.tuples(U64, U64), max_size=300),
)
def test_the_packed_index_is_byte_for_byte_mcaps(
    channel: int, entries: list[tuple[int, int]]
) -> None:
    index = MessageIndex(channel_id=channel, records=entries)
    theirs, ours = RecordBuilder(), RecordBuilder()
    mcap_speed.original()(index, theirs)
    mcap_speed._write(index, ours)
    assert ours.end() == theirs.end()


@given(st.lists(st.binary(max_size=2000), min_size=1, max_size=20))
def test_the_reused_compressor_writes_what_zstandard_compress_does(chunks: list[bytes]) -> None:
    mcap_speed.install()
    for data in chunks:  # one compressor, many chunks: each frame as a fresh one's
        assert getattr(mcap.writer, "zstandard").compress(data) == zstandard.compress(  # noqa: B009
            data, level=mcap_speed.ZSTD_LEVEL
        )


def test_the_recorder_installs_them_and_its_files_read_back() -> None:
    import frog_bt.live.recording  # noqa: F401 - installs them

    assert MessageIndex.write is mcap_speed._write
    stream = io.BytesIO()
    writer = Writer(stream, chunk_size=1 << 62, compression=CompressionType.ZSTD)
    writer.start()
    channel = writer.register_channel("/t", "json", writer.register_schema("s", "jsonschema", b""))
    for i in range(3):
        for n in range(50):
            writer.add_message(channel, log_time=i * 100 + n, data=b'{"n":%d}' % n, publish_time=0)
        writer.flush()  # a chunk each, as the recorder ends them
    writer.finish()
    stream.seek(0)
    reader = make_reader(stream)
    assert [m.log_time for _, _, m in reader.iter_messages()] == [
        i * 100 + n for i in range(3) for n in range(50)
    ]
    assert reader.get_summary().statistics.chunk_count == 3  # type: ignore[union-attr]
