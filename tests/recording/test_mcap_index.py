"""The recorder's packing of a chunk's message index writes mcap's own bytes."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from mcap.data_stream import RecordBuilder
from mcap.records import MessageIndex

from frog_bt.live import mcap_index

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
    mcap_index.original()(index, theirs)
    mcap_index._write(index, ours)
    assert ours.end() == theirs.end()


def test_the_recorder_installs_it() -> None:
    import frog_bt.live.recording  # noqa: F401 - installs it

    assert MessageIndex.write is mcap_index._write
