import os
import shutil
from pathlib import Path

import pytest

import anthesis

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def five_petal():
    """The smallest built-in flower (5 organs of 121 particles)."""
    return anthesis.load("builtin:five-petal")


@pytest.fixture(scope="session")
def anthesis_bin():
    """The `anthesis` command line: $ANTHESIS_BIN, else the repository's
    target/release or target/debug build (.ci/python builds it)."""
    candidates = [os.environ.get("ANTHESIS_BIN")]
    candidates += [str(REPO / "target" / p / "anthesis") for p in ("release", "debug")]
    candidates.append(shutil.which("anthesis"))
    for candidate in candidates:
        if candidate and Path(candidate).is_file():
            return candidate
    pytest.fail("no `anthesis` binary: build it with `cargo build --bin anthesis` or set ANTHESIS_BIN")


@pytest.fixture(scope="session")
def lily():
    """The built-in lily: painted 64x64 maps keyed in time."""
    return anthesis.load("builtin:lily")
