import sys
from pathlib import Path

# Shared helpers of these tests (harness.py, garbage.py) live beside this file.
sys.path.insert(0, str(Path(__file__).parent))
