import sys
from pathlib import Path

# Shared test helpers (bench.py, ...) live beside this file.
sys.path.insert(0, str(Path(__file__).parent))

# An executive that connects imports numpy in a thread (frog_bt/runtime/warm.py); a test
# that runs after it in the same process could see numpy half imported (pytest.approx
# looks it up in sys.modules). Imported here first, warm() finds it done.
import numpy  # noqa: F401
