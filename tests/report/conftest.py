import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from robot_day import KINDS, Seen, record_day


@pytest.fixture(scope="session")
def robot_day(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Seen]]:
    """One robot's recordings (`--record DIR`, rotating) of a tour of every kind in
    robot_day.KINDS, one a day, and what the simulator received during each."""
    directory = tmp_path_factory.mktemp("fleet") / "frog1"
    seen = record_day(directory, list(KINDS))
    for kind, s in seen.items():
        assert s.code == (1 if kind in ("fault", "declined_then_home") else 0), (kind, s.reason)
    return directory, seen
