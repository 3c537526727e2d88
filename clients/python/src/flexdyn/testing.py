"""Test helpers: run a flexdyn server for the duration of a test.

    from flexdyn.testing import flexdyn_server

    with flexdyn_server(config="scenarios/reference.toml", mode="lockstep",
                        participants=[1], duration_s=20.0) as server:
        client = flexdyn.Client(server.endpoint)
        ...
    assert server.returncode == 0, server.log

The binary is `$FLEXDYN_BIN`, else the workspace's `target/release/flexdyn` (build it with
`cargo build --release`). The server listens on a free loopback port with multicast scouting
off; the context waits until it accepts connections, and on exit waits for it to end (up to
`timeout_s`; then it is stopped with SIGTERM, and SIGKILL if need be), then fills in
`returncode` and the captured `log` (its stderr and stdout).
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator, List, Optional, Sequence


def find_binary() -> Path:
    """`$FLEXDYN_BIN`, else `target/release/flexdyn` of the workspace above this file or the
    current directory."""
    env = os.environ.get("FLEXDYN_BIN")
    if env:
        return Path(env)
    for start in (Path(__file__).resolve(), Path.cwd().resolve()):
        for d in [start, *start.parents]:
            candidate = d / "target" / "release" / "flexdyn"
            if (d / "Cargo.toml").is_file() and candidate.is_file():
                return candidate
    raise FileNotFoundError(
        "no flexdyn binary: set FLEXDYN_BIN, or run `cargo build --release` in the workspace")


def free_port() -> int:
    """A TCP port on 127.0.0.1 that is free now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@dataclass
class ServerRun:
    """A running (then finished) server: `endpoint` to connect to, and after the context,
    `returncode` and `log`."""

    endpoint: str
    port: int
    process: subprocess.Popen
    returncode: Optional[int] = None
    log: str = ""
    args: List[str] = field(default_factory=list)

    def stop(self) -> None:
        """Asks the server to stop (SIGTERM); it publishes its last frame and exits 0."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)


@contextlib.contextmanager
def flexdyn_server(config: Optional[str] = None, mode: str = "lockstep",
                   participants: Sequence[int] = (1,), duration_s: Optional[float] = None,
                   extra_args: Sequence[str] = (), timeout_s: float = 120.0,
                   ready_timeout_s: float = 30.0) -> Iterator[ServerRun]:
    """Runs `flexdyn run` (see the module docs)."""
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    args = [str(find_binary()), "run", "--mode", mode, "--listen", endpoint,
            "--participants", ",".join(str(p) for p in participants)]
    if config is not None:
        args += ["--config", str(config)]
    if duration_s is not None:
        args += ["--duration-s", repr(float(duration_s))]
    args += list(extra_args)
    log = tempfile.TemporaryFile()
    proc = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT)
    run = ServerRun(endpoint, port, proc, args=args)
    try:
        deadline = time.monotonic() + ready_timeout_s
        while True:
            if proc.poll() is not None:
                break  # ended early: the exit code and log tell why
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=0.2):
                    break
            except OSError:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"flexdyn did not listen on {endpoint} within "
                                       f"{ready_timeout_s} s")
                time.sleep(0.05)
        yield run
        try:
            proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            pass
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        run.returncode = proc.returncode
        log.seek(0)
        run.log = log.read().decode("utf-8", "replace")
        log.close()
