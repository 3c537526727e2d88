"""Shared paths for the SDK tests."""

import os
from pathlib import Path

import pytest

WORKSPACE = Path(__file__).resolve().parents[3]


@pytest.fixture
def golden_dir() -> Path:
    return WORKSPACE / "proto" / "golden"


@pytest.fixture
def verdicts_bin() -> Path:
    """The Rust decoders' verdict printer (`flexdyn-decode-verdicts`)."""
    env = os.environ.get("FLEXDYN_VERDICTS_BIN")
    path = Path(env) if env else WORKSPACE / "target" / "release" / "flexdyn-decode-verdicts"
    if not path.is_file():
        pytest.fail(f"{path} is missing: run `cargo build --release -p flexdyn-proto` "
                    "(or set FLEXDYN_VERDICTS_BIN)")
    return path
