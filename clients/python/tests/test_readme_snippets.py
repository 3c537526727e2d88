"""The code in the READMEs and the book runs. Every fenced block of clients/python/README.md, and
every Python block of README.md, of proto/README.md and of every page of the book (the pages
docs/SUMMARY.md lists, as tests/cli/readme_snippets.rs reads them), carries a marker on the line
before it:

- ``<!-- snippet: run -->``: a test here runs it (below, one per document that has one);
- ``<!-- snippet: excerpt of PATH -->``: its lines appear, in order, in PATH (a file a test runs);
- ``<!-- snippet: install (...) -->``: shell commands that install from PyPI, which no test can
  run offline; the reason names what does the same.

A block without a marker, or with one that does not hold, fails here. (The SDK README's first
snippet used to end in ``...``: nothing waited, and it timed out at tick 0.)"""

import os
import re
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from flexdyn import proto
from flexdyn.proto import StateMsg
from flexdyn.testing import find_binary, flexdyn_server

WORKSPACE = Path(__file__).resolve().parents[3]
SDK_README = WORKSPACE / "clients" / "python" / "README.md"
# The book's page that holds the Zenoh session snippet (README.md's until issue 36).
FLIGHT_CODE = WORKSPACE / "docs" / "guides" / "flight-code.md"


def book_pages():
    """The pages docs/SUMMARY.md lists (``- [Title](path.md)``), in its order."""
    docs = WORKSPACE / "docs"
    pages = []
    for line in (docs / "SUMMARY.md").read_text().splitlines():
        m = re.match(r"^\s*[-*] \[[^\]]*\]\(([^)]+\.md)\)", line)
        if m:
            pages.append(docs / m.group(1))
    return pages


# Document -> the languages whose blocks must be marked (None: all).
COVERED = {SDK_README: None, WORKSPACE / "README.md": {"python"},
           WORKSPACE / "proto" / "README.md": {"python"},
           **{page: {"python"} for page in book_pages()}}
MARKER = re.compile(r"^<!-- snippet: (run|excerpt of (\S+)|install \(.+\)) -->$")


def blocks(path):
    """(line number, language, marker or None, text) of each fenced block of `path`."""
    out, lines, i = [], path.read_text().splitlines(), 0
    while i < len(lines):
        if lines[i].startswith("```"):
            lang, start = lines[i][3:].strip(), i
            j = i + 1
            while not lines[j].startswith("```"):
                j += 1
            marker = MARKER.match(lines[i - 1]) if i > 0 else None
            out.append((start + 1, lang, marker, "\n".join(lines[i + 1:j]) + "\n"))
            i = j
        i += 1
    return out


def marked(path, kind="run", lang="python"):
    return [text for _, l, m, text in blocks(path) if l == lang and m and m.group(1) == kind]


def test_every_covered_snippet_is_run_or_an_excerpt():
    problems = []
    for path, langs in COVERED.items():
        for line, lang, m, text in blocks(path):
            if langs is not None and lang not in langs:
                continue
            where = f"{path.relative_to(WORKSPACE)}:{line} ({lang})"
            if m is None:
                problems.append(f"{where}: no <!-- snippet: ... --> marker")
            elif m.group(2):
                source = WORKSPACE / m.group(2)
                if not source.is_file():
                    problems.append(f"{where}: {m.group(2)} does not exist")
                    continue
                rest = source.read_text()
                for l in (l.strip() for l in text.splitlines()):
                    at = rest.find(l)
                    if l and at < 0:
                        problems.append(f"{where}: {l!r} is not in {m.group(2)} (in order)")
                        break
                    rest = rest[at + len(l):] if l else rest
            elif m.group(1).startswith("install") and lang != "sh":
                problems.append(f"{where}: only shell blocks can be install commands")
    assert not problems, "\n".join(problems)
    # Each document's run blocks are the ones the tests below run, and no other has one.
    assert FLIGHT_CODE in COVERED, "docs/SUMMARY.md does not list the flight-code guide"
    runs = {p: len(marked(p)) for p in COVERED if marked(p)}
    assert runs == {SDK_README: 2, FLIGHT_CODE: 1, WORKSPACE / "proto" / "README.md": 1}, runs


@pytest.mark.parametrize("index", [0, 1])
def test_sdk_readme_snippets_run_as_written(index):
    """Each snippet as a script from the checkout's root, as the README says."""
    code = marked(SDK_README)[index]
    env = dict(os.environ, FLEXDYN_BIN=str(find_binary()))
    r = subprocess.run([sys.executable, "-c", code], cwd=WORKSPACE, env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, f"snippet {index} failed:\n{r.stdout}\n{r.stderr}"


def test_the_zenoh_session_snippet_receives_the_state():
    """The flight-code guide's session options, pointed at a test server (it names the default
    port)."""
    (code,) = marked(FLIGHT_CODE)
    assert '"tcp/127.0.0.1:7447"' in code
    got = threading.Event()
    with flexdyn_server(mode="realtime", duration_s=3.0) as server:
        ns = {}
        exec(code.replace("tcp/127.0.0.1:7447", server.endpoint), ns)
        session = ns["session"]
        try:
            sub = session.declare_subscriber(proto.state_key("sc1"), lambda s: got.set())
            assert got.wait(30), "no StateMsg through the guide's session"
            sub.undeclare()
        finally:
            session.close()
    assert server.returncode == 0, server.log


def test_the_protocol_readme_python_example_matches_the_golden_vectors(golden_dir):
    """proto/README.md's hand-written decoder and encoders against the golden files (the
    values of tests/test_proto_golden.py)."""
    (code,) = marked(WORKSPACE / "proto" / "README.md")
    ns = {}
    exec(code, ns)
    golden = (golden_dir / "state.bin").read_bytes()
    got, want = ns["decode_state_header"](golden), StateMsg.decode(golden)
    h = want.header
    assert (got["spacecraft_id"], got["tick"], got["sim_time_ns"], got["seq"]) == (
        h.spacecraft_id, h.tick, h.sim_time_ns, h.seq)
    assert (got["sigma_bn"], got["q_bn"], got["omega_bn_b_rad_s"]) == (
        want.sigma_bn, want.q_bn, want.omega_bn_b_rad_s)
    assert [(e["kind"], e["flags"], e["states"], e["outputs"]) for e in got["effectors"]] == [
        (e.kind, e.flags, tuple(e.states), tuple(e.outputs)) for e in want.effectors]
    sc = 0x11223344
    assert ns["encode_wrench_command"](
        sc, 42, 420_000_000, 7, 0xDEADBEEF, (0.0625, -0.125, 0.25), (-1.0, 0.0, 0.5)
    ) == (golden_dir / "command_wrench.bin").read_bytes()
    assert ns["encode_actuators_command"](
        sc, 44, 440_000_000, 9, 7, (0.5, -0.25, 0.0), (0.0, 0.0, -0.0),
        [(2, [0.0625]), (5, [-0.03125])]) == (golden_dir / "command_actuators.bin").read_bytes()
    assert ns["encode_no_command"](sc, 43, 430_000_000, 8, 5) == (
        golden_dir / "command_no_command.bin").read_bytes()
