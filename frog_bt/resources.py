"""Where the packaged tour and site configuration are, installed or in a checkout.

``trees/`` and ``config/`` live at the top of the repository; ``frog_bt/_trees``
and ``frog_bt/_site`` are symbolic links to them, so a wheel carries copies of
the files as package data (``pyproject.toml``) and the same lookup finds them in
a checkout installed editable and in an installed wheel. ``frog-bt init DIR``
copies them out for a site to edit.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

TREE_FILE = "tour.yaml"
SITE_FILE = "site.yaml"


def _folder(name: str) -> Path:
    # A wheel is unpacked on disk and an editable install points at the checkout:
    # either way the package's files are real files.
    return Path(str(resources.files("frog_bt").joinpath(name))).resolve()


def tree_dir() -> Path:
    """The folder of the packaged tree files (``tour.yaml`` and what it includes)."""
    return _folder("_trees")


def site_dir() -> Path:
    """The folder of the packaged site configuration (``site.yaml``)."""
    return _folder("_site")
