import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from recorded_tour import RecordedTour, record_tour


@pytest.fixture(scope="session")
def tour(tmp_path_factory: pytest.TempPathFactory) -> RecordedTour:
    """One whole simulated tour (default scenario, fast), recorded; shared by the tests."""
    recorded = record_tour(tmp_path_factory.mktemp("recording") / "tour.mcap")
    assert recorded.outcome.code == 0, recorded.outcome.reason
    return recorded
