"""The firmware's sources travel in the wheel: ``ttt-sm arm serve`` builds them from an installed package.

The soak test builds the wheel, installs it into a fresh virtual
environment (its dependencies borrowed from this one's site-packages), and
runs ``arm serve`` there from an empty folder with an empty cache: the
firmware is compiled from the sources the wheel carries, with nothing of
the checkout in reach.  ``.ci/run`` does the same with a full install.
"""

from __future__ import annotations

import json
import os
import site
import subprocess
import sys
from pathlib import Path

import pytest

from ttt_sm.hardware.firmware import PACKAGED_SOURCES, firmware_root

ROOT = Path(__file__).resolve().parents[2]


def _package_data_globs() -> list[str]:
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    return config["tool"]["setuptools"]["package-data"]["ttt_sm.hardware"]


def test_every_firmware_source_is_package_data():
    """A C file or header added to firmware/ is in the wheel without anyone remembering to list it."""
    globs = _package_data_globs()
    base = ROOT / "src" / "ttt_sm" / "hardware"
    packaged = {p.resolve() for g in globs for p in base.glob(g)}
    sources = {p.resolve() for p in [*(ROOT / "firmware" / "src").glob("*.c"),
                                     *(ROOT / "firmware" / "include").rglob("*.h")]}
    assert sources and sources == packaged
    assert firmware_root() == PACKAGED_SOURCES and PACKAGED_SOURCES.resolve() == (ROOT / "firmware").resolve()


@pytest.mark.soak
def test_arm_serve_builds_the_firmware_from_an_installed_wheel(tmp_path):
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp_path / "dist"), str(ROOT)],
                   check=True, capture_output=True)
    [wheel] = (tmp_path / "dist").glob("ttt_sm-*.whl")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps", str(wheel)],
                   check=True, capture_output=True)
    # the dependencies from this environment, after the venv's own site-packages (which hold the wheel)
    venv_site = Path(subprocess.run([str(python), "-c", "import site; print(site.getsitepackages()[0])"],
                                    check=True, capture_output=True, text=True).stdout.strip())
    (venv_site / "deps.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    run = tmp_path / "run"
    run.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "TTT_SM_FIRMWARE"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    where = subprocess.run([str(python), "-c", "import ttt_sm.hardware.firmware as f; print(f.firmware_root())"],
                           check=True, capture_output=True, text=True, cwd=run, env=env).stdout.strip()
    assert where.startswith(str(venv_site)) and not Path(where).is_symlink()  # the wheel's copy, not the checkout
    done = subprocess.run([str(venv / "bin" / "ttt-sm"), "arm", "serve", "--pace", "gated", "--duration", "0",
                           "--json", "--link", str(run / "arm")], capture_output=True, text=True, cwd=run, env=env,
                          timeout=600)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["stats"]["state"] == "idle"
    assert list((tmp_path / "cache" / "ttt_sm" / "firmware").glob("ttt_fw_float_*.so"))
    # and without a compiler: one line that says what to install
    env["XDG_CACHE_HOME"] = str(tmp_path / "empty-cache")
    env["CC"] = "no-such-cc"
    done = subprocess.run([str(venv / "bin" / "ttt-sm"), "arm", "serve", "--duration", "0", "--link",
                           str(run / "arm")], capture_output=True, text=True, cwd=run, env=env, timeout=600)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and "no C compiler 'no-such-cc'" in lines[0], done.stderr
