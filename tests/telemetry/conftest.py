import sys
from pathlib import Path

import pytest

# Helpers (telemetry_tour.py) live beside this file.
sys.path.insert(0, str(Path(__file__).parent))
from telemetry_tour import Recorded, record_tour


@pytest.fixture(scope="session")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    """A whole simulated tour recorded to an .rrd and read back."""
    return record_tour(tmp_path_factory.mktemp("telemetry") / "tour.rrd")
