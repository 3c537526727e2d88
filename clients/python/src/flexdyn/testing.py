"""Test helpers: run a flexdyn server for the duration of a test.

    from flexdyn.testing import flexdyn_server

    with flexdyn_server(config="scenarios/reference.toml", mode="lockstep",
                        participants=[1], duration_s=20.0) as server:
        client = flexdyn.Client(server.endpoint)
        ...
    assert server.returncode == 0, server.log

The binary is `$FLEXDYN_BIN`, else the workspace's `target/release/flexdyn` (build it with
`cargo build --release`). The server listens on `tcp/127.0.0.1:0` with multicast scouting off:
the OS gives it a free port, and the context waits until the server logs `Zenoh listening on
ENDPOINT` and takes the endpoint from that line. On exit it waits for it to end (up to
`timeout_s`; then it is stopped with SIGTERM, and SIGKILL if need be), then fills in
`returncode` and the captured `log` (its stderr and stdout).

A server that exits before it is reachable (a bad configuration path, a bad setting) raises
`ServerFailed` with the server's own `error: …` line, its exit code and its whole log, instead
of handing the test an endpoint that nothing listens on.
"""

from __future__ import annotations

import contextlib
import os
import signal
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


LISTENING = "Zenoh listening on "
"""The start of the line the server logs once it is reachable (`flexdyn_proto::client::transport::log_listening`)."""


def reported_endpoint(log: str) -> Optional[str]:
    """The endpoint a complete `Zenoh listening on tcp/127.0.0.1:PORT` line of `log` names."""
    complete = log[: log.rfind("\n") + 1]
    for line in complete.splitlines():
        i = line.find(LISTENING)
        if i >= 0:
            return line[i + len(LISTENING):].split()[0].rstrip(",")
    return None


class ServerFailed(RuntimeError):
    """The server exited before it was reachable. `str()` is the server's own error line;
    `returncode` and `log` are its exit code and everything it wrote."""

    def __init__(self, returncode: Optional[int], log: str):
        errors = [line for line in log.splitlines() if line.startswith("error: ")]
        message = errors[-1] if errors else f"flexdyn exited with {returncode} before listening"
        super().__init__(f"{message} (exit code {returncode})")
        self.returncode = returncode
        self.log = log


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
    # Port 0: the OS gives the server a free port and the server reports it (no port is picked
    # here and hoped to be still free when the server binds it).
    args = [str(find_binary()), "run", "--mode", mode, "--listen", "tcp/127.0.0.1:0",
            "--participants", ",".join(str(p) for p in participants)]
    if config is not None:
        args += ["--config", str(config)]
    if duration_s is not None:
        args += ["--duration-s", repr(float(duration_s))]
    args += list(extra_args)
    log = tempfile.TemporaryFile()
    env = dict(os.environ, RUST_LOG="info")
    proc = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, env=env)
    run = ServerRun("", 0, proc, args=args)
    try:
        deadline = time.monotonic() + ready_timeout_s
        while True:
            log.seek(0)
            endpoint = reported_endpoint(log.read().decode("utf-8", "replace"))
            if endpoint is not None:
                run.endpoint = endpoint
                run.port = int(endpoint.rsplit(":", 1)[1])
                break
            if proc.poll() is not None:
                # Ended before it was reachable: its own error, not a connection failure later.
                log.seek(0)
                raise ServerFailed(proc.returncode, log.read().decode("utf-8", "replace"))
            if time.monotonic() > deadline:
                raise TimeoutError(f"flexdyn reported no endpoint within {ready_timeout_s} s")
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
