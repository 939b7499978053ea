"""The README's set-up installs what its listed commands need: `frog-bt report` needs
the `report` extra (matplotlib, pyarrow, scipy), and the set-up installs it. (Checked by
hand too: a fresh venv with only the set-up's install ran every command of the table.)"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from frog_bt.offline.report.outputs import EXTRA

ROOT = Path(__file__).resolve().parents[2]


def test_the_readme_set_up_installs_the_report_extra() -> None:
    readme = (ROOT / "README.md").read_text()
    first = re.search(r"```sh\n(.*?)\n```", readme, re.S)
    assert first is not None
    installed = set(re.findall(r"pip install [^&]*'\.\[([a-z,]+)\]'", first.group(1))[0].split(","))
    extra = re.search(r"\[(\w+)\]", EXTRA)
    assert extra is not None and extra.group(1) in installed  # what report says to install
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    names = {re.split(r"[<>=\[ ]", req)[0] for name in installed for req in extras[name]}
    assert {"matplotlib", "pyarrow", "scipy"} <= names
    # the commands that need another extra say which, where they are listed
    assert "needs the `console` extra" in readme
