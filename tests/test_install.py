"""A wheel that runs: built from the project's files, installed alone in a fresh
virtualenv, its ``frog-bt`` renders, inits, checks a copied tree and runs a demo."""

from __future__ import annotations

import shutil
import site
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    src = tmp_path_factory.mktemp("src")
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info")
    for name in ("frog_bt", "trees", "config"):
        shutil.copytree(ROOT / name, src / name, symlinks=True, ignore=ignore)
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            "-w",
            str(out),
            str(src),
        ],
        check=True,
        capture_output=True,
        text=True,
        timeout=120,
    )
    (whl,) = out.glob("frog_bt-*.whl")
    return whl


@pytest.fixture(scope="module")
def installed(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh virtualenv with the wheel alone; its dependencies come from this
    environment's site-packages (no network), but not this checkout's frog_bt."""
    env = tmp_path_factory.mktemp("venv")
    venv.EnvBuilder(with_pip=False).create(env)
    (lib,) = (env / "lib").glob("python3*/site-packages")
    deps = [p for p in site.getsitepackages() if Path(p).is_dir()]
    (lib / "_frog_deps.pth").write_text("\n".join(deps) + "\n")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(env / "bin" / "python"),
            "install",
            "-q",
            "--no-deps",
            "--no-index",
            str(wheel),
        ],
        check=True,
        capture_output=True,
        text=True,
        timeout=120,
    )
    return env / "bin"


def test_the_wheel_carries_the_tour_and_the_site_config(wheel: Path) -> None:
    names = zipfile.ZipFile(wheel).namelist()
    for name in (
        "frog_bt/_trees/tour.yaml",
        "frog_bt/_trees/recruit.yaml",
        "frog_bt/_trees/visit_poi.yaml",
        "frog_bt/_site/site.yaml",
    ):
        assert name in names


def test_the_installed_command_renders_inits_and_runs_a_demo(
    installed: Path, tmp_path: Path
) -> None:
    def frog(*argv: str, timeout: float = 60) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [str(installed / "frog-bt"), *argv],
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=tmp_path,
        )

    where = subprocess.run(
        [str(installed / "python"), "-c", "import frog_bt; print(frog_bt.__file__)"],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    )
    assert Path(where.stdout.strip()).is_relative_to(installed.parent)  # not the checkout

    rendered = frog("render")
    assert rendered.returncode == 0, rendered.stderr
    assert "Location awareness (LocationAware)" in rendered.stdout

    made = frog("init", "site")
    assert made.returncode == 0, made.stderr
    tree, config = (
        tmp_path / "site" / "trees" / "tour.yaml",
        tmp_path / "site" / "config" / "site.yaml",
    )
    assert tree.is_file() and config.is_file()
    recruit = tmp_path / "site" / "trees" / "recruit.yaml"
    recruit.write_text(recruit.read_text().replace("name: Recruit", "name: Find a guest"))
    edited = frog("render", "--tree", str(tree), "--config", str(config))
    assert edited.returncode == 0, edited.stderr
    assert "Find a guest (Retry)" in edited.stdout  # the copy is what runs
    # the copy has its schemas beside it, for an editor, and checks clean
    assert (tree.parent / "tree.schema.json").is_file()
    assert (config.parent / "site.schema.json").is_file()
    checked = frog("check", "--no-verify", "--tree", str(tree), "--config", str(config))
    assert checked.returncode == 0 and checked.stdout.startswith("ok: "), checked.stderr
    listed = frog("leaves", "--format", "json")
    assert listed.returncode == 0 and '"name": "SeekVisitor"' in listed.stdout

    demo = frog(
        "demo",
        "--quiet",
        "--speed",
        "300",
        "--rerun",
        "off",
        "--record",
        "d.mcap",
        "--tree",
        str(tree),
        "--config",
        str(config),
        timeout=120,
    )
    assert demo.returncode == 0, demo.stdout + demo.stderr
    assert "outcome:   tour ended docked, every stop visited" in demo.stdout
