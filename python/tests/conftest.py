"""Where the tactex command line is: TACTEX_BIN, else the workspace's debug or release build
(`cargo test` in CI builds the debug one). The tests compare the package with it."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def tactex_bin() -> Path:
    given = os.environ.get("TACTEX_BIN")
    candidates = [Path(given)] if given else [ROOT / "target/debug/tactex", ROOT / "target/release/tactex"]
    for c in candidates:
        if c.is_file():
            return c
    pytest.fail(f"no tactex binary at {', '.join(map(str, candidates))}: build it (cargo build) or set TACTEX_BIN")


@pytest.fixture(scope="session")
def cli(tactex_bin):
    def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
        out = subprocess.run([str(tactex_bin), *args], cwd=ROOT, capture_output=True, text=True)
        if check and out.returncode != 0:
            raise AssertionError(f"tactex {' '.join(args)} failed: {out.stderr}")
        return out

    return run
