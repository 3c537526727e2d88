"""`flexdyn.testing.flexdyn_server`: a server that cannot start raises its own error."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from flexdyn.testing import ServerFailed, flexdyn_server


def test_a_bad_config_path_raises_the_servers_own_error():
    with pytest.raises(ServerFailed) as failed:
        with flexdyn_server(config="no/such/scenario.toml", duration_s=1.0):
            pytest.fail("the context must not be entered")
    e = failed.value
    # The server's own line: it names the file; exit code 2 (invalid input).
    assert str(e).startswith("error: "), str(e)
    assert "no/such/scenario.toml" in str(e), str(e)
    assert e.returncode == 2, e.log


def test_the_ci_example_runs_when_copied_elsewhere(tmp_path: Path):
    """`examples/test_acs_lockstep.py`, offered to copy into CI, copied out of the checkout."""
    example = Path(__file__).resolve().parents[1] / "examples" / "test_acs_lockstep.py"
    copy = tmp_path / "test_acs_lockstep.py"
    shutil.copy(example, copy)
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(copy)],
        cwd=tmp_path, env=dict(os.environ), capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
