"""The flight code's own telemetry (protocol 10, FswMsg on ``flexdyn/<sc>/fsw/<name>``) end to
end, with the server binary in lockstep and ``--record``:

- A: a participant that publishes one sample of stream ``acs`` for each tick it answers (from
  :meth:`flexdyn.Client.declare_fsw`) gives the same recording twice (the exported fsw CSV
  byte for byte), one row per sample, each holding exactly what was sent, and nothing refused;
- B: a hostile second session putting crafted FswMsg payloads (each wrong in exactly one way,
  stamped so that it would be recorded if the server missed that one check) gets every one
  refused and counted in ``rejected_fsw_refused``, for its own reason, and records nothing: the
  recording is A's;
- C: :class:`flexdyn.fsw.FswStream` refuses what the server would refuse with ``ValueError``
  and sends nothing (nothing refused by the server, the recording is A's, and no ``seq`` was
  spent on a refused sample); ``declare_fsw`` of an undeclared stream is a ``KeyError``.

The server does not wait for an answer to the run's last tick (it ends as soon as it publishes
it), so a sample for that tick would reach the recording only if it beat the recorder's close
(a lockstep server that records no sample of its last tick makes that deterministic): the
participants here publish for every tick but the last, and the recording holds exactly those.
"""

import csv
import math
import re
import struct
import subprocess
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Dict, List, Optional

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import pytest

import flexdyn
from flexdyn import proto
from flexdyn.fsw import FswDeclaration, decode_sample
from flexdyn.proto import FswMsg, Header
from flexdyn.testing import find_binary, flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "reference.toml"
_SIM = tomllib.loads(SCENARIO.read_text())["simulation"]
FRAME_HZ = float(_SIM["frame_hz"])
FRAME_NS = round(1e9 / FRAME_HZ)
assert FRAME_NS * FRAME_HZ == 1e9, "the reference frame rate is a whole number of ns per frame"
DURATION_S = 0.5
LAST = round(DURATION_S * FRAME_HZ)  # the run's last tick: published, never waited for
HOLD = 20  # the tick at which tests B and C do their thing, before the honest sample
SC_ID, SPACECRAFT_ID = "sc1", 1
KEY = proto.fsw_key(SC_ID, "acs")
CSV_NAME = "flexdyn_sc1_fsw_acs.csv"  # `flexdyn export`: the key, '/' -> '_'

STREAM_TOML = """
[[fsw_streams]]
name = "acs"
modes = ["detumble", "point"]
events = [{ name = "gyro_fault", severity = "error" }]
values = [
  { name = "h_b_nms", type = "f64", len = 3, unit = "N·m·s" },
  { name = "fault_word", type = "i64" },
  { name = "ok", type = "bool" },
]
"""

ALL_FLAGS = proto.FSW_MODE | proto.FSW_ESTIMATE | proto.FSW_TARGET | proto.FSW_COVARIANCE
TARGET = (1.0, 0.0, 0.0, 0.0)
VARIANCE = (1e-6,) * 3


REMOVE = object()  # test C: a keyword of honest() to leave out of a sample


def f64_word(x: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def honest(k: int, q_bn) -> dict:
    """What the honest flight code publishes for tick k (mode left out every 5th tick, the
    event raised every 7th)."""
    return dict(mode=None if k % 5 == 4 else ("detumble" if k < 25 else "point"),
                events=["gyro_fault"] if k % 7 == 3 else [],
                estimate=q_bn, target=TARGET, variance=VARIANCE,
                h_b_nms=(k * 0.5, -float(k), 0.25), fault_word=-k, ok=(k % 2 == 1))


# -- running the server ------------------------------------------------------------------------

@dataclass
class Run:
    csv_dir: Path
    fsw_csv: bytes
    sent: List[FswMsg]
    final: proto.StatusMsg
    answered: int
    log: str


def run(config: Path, out: Path, on_hold: Optional[Callable] = None,
        main: Optional[Callable] = None) -> Run:
    """One lockstep run of LAST + 1 ticks recorded to ``out/run.mcap`` and exported to
    ``out/csv``: the participant publishes honest(k) for each tick k < LAST before answering it;
    at tick HOLD it first calls ``on_hold(acs, state)`` (on its callback thread), and
    ``main(server)`` runs on this thread while the run goes on."""
    out.mkdir(parents=True, exist_ok=True)
    rec = out / "run.mcap"
    sent: List[FswMsg] = []
    # A participant timeout long enough for a hold on a loaded machine; status at 50 Hz so the
    # counters are seen soon.
    args = ["--record", str(rec), "--status-hz", "50", "--participant-timeout-s", "60"]
    with flexdyn_server(config=config, mode="lockstep", participants=[1], duration_s=DURATION_S,
                        extra_args=args, timeout_s=60.0) as server:
        with flexdyn.Client(server.endpoint, sc_id=SC_ID, spacecraft_id=SPACECRAFT_ID) as client:
            acs = client.declare_fsw("acs")
            assert acs.key == KEY

            def on_state(state):
                k = state.header.tick
                assert state.header.sim_time_ns == k * FRAME_NS
                if on_hold is not None and k == HOLD:
                    on_hold(acs, state)
                if k < LAST:
                    sent.append(acs.publish(k, state.header.sim_time_ns, **honest(k, state.q_bn)))
                return None

            with flexdyn.LockstepParticipant(client, 1, on_state) as participant:
                if main is not None:
                    main(server)
                final = participant.wait(timeout_s=120.0)
            answered = participant.answered
    assert server.returncode == 0, server.log
    assert proto.RUN_STATE_NAMES[final.run_state] == "Finished", final
    assert final.header.tick == LAST
    assert answered == LAST + 1
    csv_dir = out / "csv"
    subprocess.run([str(find_binary()), "export", "--csv", str(csv_dir), str(rec)],
                   check=True, capture_output=True, timeout=60)
    return Run(csv_dir, (csv_dir / CSV_NAME).read_bytes(), sent, final, answered, server.log)


def read_rows(data: bytes) -> List[Dict[str, str]]:
    lines = [ln for ln in data.decode("utf-8").splitlines() if not ln.startswith("#")]
    return list(csv.DictReader(lines))


def columns(row: Dict[str, str], prefix: str) -> List[str]:
    """The cells of the vector columns `<prefix>_<n>`, in n order (whatever n starts at)."""
    found = sorted((int(m.group(1)), v) for c, v in row.items()
                   if (m := re.fullmatch(re.escape(prefix) + r"_(\d+)", c)))
    return [v for _, v in found]


def msg_of_row(row: Dict[str, str]) -> FswMsg:
    """The FswMsg an exported row holds (every field is a column)."""
    header = Header(int(row["spacecraft_id"]), int(row["tick"]), int(row["sim_time_ns"]),
                    int(row["seq"]), int(row["protocol_version"]))
    return FswMsg(header, int(row["flags"]), int(row["mode"]),
                  tuple(float(x) for x in columns(row, "q_est_bn")),
                  tuple(float(x) for x in columns(row, "q_target_rn")),
                  tuple(float(x) for x in columns(row, "att_var_b_rad2")),
                  int(row["event_count"]), tuple(int(x) for x in columns(row, "events")),
                  [int(x) for x in columns(row, "values")])


def assert_records_exactly(r: Run) -> None:
    """The recording's fsw rows are the samples sent, in order, field for field."""
    rows = read_rows(r.fsw_csv)
    assert [int(row["tick"]) for row in rows] == list(range(LAST))
    assert len(r.sent) == LAST
    for row, sent in zip(rows, r.sent):
        got = msg_of_row(row)
        assert got == sent, (row, sent)
        assert got.encode() == sent.encode()
        assert float(row["t_s"]) == sent.header.sim_time_ns / 1e9


@pytest.fixture(scope="module")
def config(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("fsw_config") / "reference_fsw.toml"
    path.write_text(SCENARIO.read_text() + STREAM_TOML, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def declaration(config) -> FswDeclaration:
    return FswDeclaration.from_config(tomllib.loads(config.read_text(encoding="utf-8")), "acs")


@pytest.fixture(scope="module")
def reference(config, tmp_path_factory) -> Run:
    """The honest run the other runs are compared with."""
    return run(config, tmp_path_factory.mktemp("fsw_reference"))


# -- A: determinism and the API ----------------------------------------------------------------

def test_fsw_recording_is_deterministic_and_holds_what_was_sent(config, declaration, reference,
                                                                 tmp_path):
    again = run(config, tmp_path / "again")
    for r in (reference, again):
        assert r.final.rejected_fsw_refused == 0, r.log
        assert_records_exactly(r)
    assert again.fsw_csv == reference.fsw_csv, "two runs recorded different fsw streams"

    rows = read_rows(reference.fsw_csv)
    # The flags say what each sample set.
    assert [int(row["flags"]) for row in rows] == [
        ALL_FLAGS & ~(proto.FSW_MODE if k % 5 == 4 else 0) for k in range(LAST)]
    # The values, decoded by the declaration, are the values sent, bit for bit.
    for k in (0, 1, 3, 4, 17, 24, 25, LAST - 1):
        row = rows[k]
        words = [int(w) for w in columns(row, "values")]
        assert words == [f64_word(k * 0.5), f64_word(-float(k)), f64_word(0.25),
                         (-k) & 0xFFFF_FFFF_FFFF_FFFF, k % 2]
        s = decode_sample(declaration, msg_of_row(row))
        assert s["tick"] == k
        assert s["mode"] == (None if k % 5 == 4 else ("detumble" if k < 25 else "point"))
        assert s["events"] == (["gyro_fault"] if k % 7 == 3 else [])
        assert s["h_b_nms"] == [k * 0.5, -float(k), 0.25]
        assert s["fault_word"] == [-k]
        assert s["ok"] == [k % 2 == 1]
        assert s["target"] == TARGET
        assert s["variance"] == VARIANCE
        assert s["estimate"] == reference.sent[k].q_est_bn
        assert int(row["mode"]) == (0 if k < 25 or k % 5 == 4 else 1)
    # The estimate is the state's attitude at that tick (the state CSV of the same run).
    states = {int(s["tick"]): s for s in read_rows(
        (reference.csv_dir / "flexdyn_sc1_tlm_state.csv").read_bytes())}
    for row in rows:
        assert columns(row, "q_est_bn") == columns(states[int(row["tick"])], "q_bn")
    assert len({tuple(columns(row, "q_est_bn")) for row in rows}) == LAST  # it moves


# -- B: a hostile sender -----------------------------------------------------------------------

def test_hostile_fsw_samples_are_all_refused_and_none_recorded(config, reference, tmp_path):
    """At tick HOLD, before the honest sample of HOLD, a second session puts crafted samples.
    Each is wrong in one way only and (but for the stale ones) is stamped HOLD at HOLD's time:
    had the server missed its check, it would have been recorded and the honest sample of HOLD
    (or every later one) refused."""
    at_hold, go = threading.Event(), threading.Event()
    held_state: List[proto.StateMsg] = []
    sent_hostile: List[str] = []
    refused_seen = threading.Condition()
    refused = [0]
    server_tick = [-1]

    def on_hold(acs, state):
        held_state.append(state)
        at_hold.set()
        assert go.wait(60), "the hostile sender did not finish"

    def good(tick: int, seq: int = 0, **kw) -> FswMsg:
        m = FswMsg(Header(SPACECRAFT_ID, tick, tick * FRAME_NS, 1000 + seq), ALL_FLAGS, 1,
                   (1.0, 0.0, 0.0, 0.0), TARGET, VARIANCE, 1, (0,) * 8,
                   [f64_word(1.0), f64_word(2.0), f64_word(3.0), 7, 1])
        for name, value in kw.items():
            setattr(m, name, value)
        return m

    def main(server):
        with flexdyn.Client(server.endpoint, sc_id=SC_ID, spacecraft_id=SPACECRAFT_ID) as hostile:
            def on_status(s):
                with refused_seen:
                    refused[0] = max(refused[0], s.rejected_fsw_refused)
                    server_tick[0] = max(server_tick[0], s.header.tick)
                    refused_seen.notify_all()

            hostile.subscribe_status(on_status)
            assert at_hold.wait(60), "the run never reached the hold"
            with refused_seen:
                # Wait until the server's status says HOLD, so that every hostile sample below
                # is judged at tick HOLD (the server notes a tick before it publishes it, so
                # none can be refused as `future_tick` instead of for the defect it carries).
                assert refused_seen.wait_for(lambda: server_tick[0] >= HOLD, 60), (
                    f"the server's status never reached tick {HOLD}")
                assert server_tick[0] == HOLD
                assert refused[0] == 0, "an honest sample was refused before the hold"
            k = HOLD
            # The control: this one passes every check (it is never sent).
            assert good(k).encode() != b""
            cases = {}
            cases["unknown_stream"] = [(proto.fsw_key(SC_ID, "nav"), good(k).encode())]
            cases["unknown_mode"] = [(KEY, good(k, mode=7).encode())]
            cases["unknown_event"] = [(KEY, good(k, events=(3,) + (0,) * 7).encode()),
                                      # an undeclared index after a declared one
                                      (KEY, good(k, event_count=2,
                                                 events=(0, 1) + (0,) * 6).encode())]
            words = good(k).values
            cases["wrong_count"] = [(KEY, good(k, values=words[:4]).encode()),
                                    (KEY, good(k, values=words + [0]).encode()),
                                    (KEY, good(k, values=[]).encode())]
            cases["non_finite"] = [
                (KEY, good(k, values=[f64_word(math.nan)] + words[1:]).encode()),
                (KEY, good(k, values=words[:2] + [f64_word(-math.inf)] + words[3:]).encode()),
                # the estimate itself: the decoder's NonFinite
                (KEY, good(k, q_est_bn=(math.nan, 0.0, 0.0, 0.0)).encode())]
            cases["not_bool"] = [(KEY, good(k, values=words[:4] + [2]).encode())]
            cases["covariance_without_estimate"] = [
                (KEY, good(k, flags=ALL_FLAGS & ~proto.FSW_ESTIMATE).encode())]
            cases["future_tick"] = [(KEY, good(k + 1).encode()),
                                    (KEY, good(k + 1000).encode())]
            cases["wrong_time"] = [
                (KEY, good(k, header=Header(SPACECRAFT_ID, k, k * FRAME_NS + 1, 0)).encode()),
                (KEY, good(k, header=Header(SPACECRAFT_ID, k, (k - 1) * FRAME_NS, 0)).encode())]
            # HOLD - 1 was recorded before the server published HOLD (the honest sample went
            # before the answer that let the server step on, on the same session), and so was
            # HOLD - 5: a repeat, and a flood of an old tick.
            cases["rate_bound"] = [(KEY, good(k - 1).encode())] + [
                (KEY, good(k - 5, seq=i).encode()) for i in range(200)]
            truncated = good(k).encode()[:100]
            too_many_events = bytearray(good(k).encode())
            too_many_events[123] = 9  # event_count > 8
            cases["malformed"] = [(KEY, truncated), (KEY, b""), (KEY, bytes(too_many_events)),
                                  (KEY, good(k).encode() + b"\0")]
            cases["bad_version"] = [
                (KEY, b"garbage \xff\x00 bytes"),
                (KEY, good(k, header=Header(SPACECRAFT_ID, k, k * FRAME_NS, 0,
                                            proto.PROTOCOL_VERSION - 1)).encode())]
            cases["wrong_spacecraft"] = [
                (KEY, good(k, header=Header(SPACECRAFT_ID + 1, k, k * FRAME_NS, 0)).encode())]
            for reason, puts in cases.items():
                for key, payload in puts:
                    hostile.session.put(key, payload)
                    sent_hostile.append(reason)
            n = len(sent_hostile)
            with refused_seen:
                assert refused_seen.wait_for(lambda: refused[0] >= n, 60), (
                    f"the server counted {refused[0]} of {n} refusals")
            go.set()

    try:
        r = run(config, tmp_path, on_hold=on_hold, main=main)
    finally:
        go.set()
    n = len(sent_hostile)
    assert n == 1 + 1 + 2 + 3 + 3 + 1 + 1 + 2 + 2 + 201 + 4 + 2 + 1 == 224
    assert r.final.rejected_fsw_refused == n, r.log
    # Nothing else was refused either: the honest samples were all recorded.
    assert r.final.rejected_malformed == r.final.rejected_wrong_spacecraft == 0
    assert r.fsw_csv == reference.fsw_csv, "a hostile sample reached the recording"
    assert_records_exactly(r)
    # Each refusal for its own reason (the server logs the first of each reason).
    rejections = "\n".join(ln for ln in r.log.splitlines() if "WARN" in ln)
    for reason in set(sent_hostile):
        assert re.search(rf"\b{reason}\b", rejections), (
            f"no `{reason}` refusal in the log:\n{rejections}")
    # The nav key is not a stream: nothing was recorded on it.
    assert not (r.csv_dir / "flexdyn_sc1_fsw_nav.csv").exists()


# -- C: what the SDK refuses -------------------------------------------------------------------

def test_sdk_refuses_what_the_server_would_refuse_and_sends_nothing(config, declaration,
                                                                    reference, tmp_path):
    """At tick HOLD, before the honest sample, the participant tries samples of HOLD that the
    server would refuse: each is a ValueError, sends nothing (had one gone out, the server would
    have refused it or recorded it instead of the honest one) and spends no seq."""
    outcomes: Dict[str, object] = {}
    names: List[str] = []

    def on_hold(acs, state):
        k, t = state.header.tick, state.header.sim_time_ns
        base = honest(k, state.q_bn)

        def attempt(label, **change):
            kw = dict(base, **change)
            for name in [n for n, v in change.items() if v is REMOVE]:
                del kw[name]
            try:
                acs.publish(k, t, **kw)
                outcomes[label] = "sent"
            except Exception as e:  # noqa: BLE001 - the test reports the type
                outcomes[label] = e

        attempt("undeclared mode", mode="cruise")
        attempt("undeclared event", events=["gyro_fault", "sun_lost"])
        attempt("too many events", events=["gyro_fault"] * (proto.MAX_FSW_EVENTS + 1))
        attempt("undeclared value", wheel_speed=1.0)
        attempt("missing value", ok=REMOVE)
        attempt("short vector", h_b_nms=(1.0, 2.0))
        attempt("long vector", h_b_nms=(1.0, 2.0, 3.0, 4.0))
        attempt("vector for a scalar", fault_word=(1, 2))
        attempt("NaN f64", h_b_nms=(0.0, math.nan, 0.0))
        attempt("inf f64", h_b_nms=(math.inf, 0.0, 0.0))
        attempt("i64 too large", fault_word=2**63)
        attempt("i64 too small", fault_word=-2**63 - 1)
        attempt("i64 not an integer", fault_word=1.5)
        attempt("i64 a bool", fault_word=True)
        attempt("bool 2", ok=2)
        attempt("variance without estimate", estimate=None)
        attempt("NaN estimate", estimate=(math.nan, 0.0, 0.0, 0.0))
        attempt("short estimate", estimate=(1.0, 0.0, 0.0))
        attempt("infinite target", target=(math.inf, 0.0, 0.0, 0.0))
        attempt("short variance", variance=(1e-6, 1e-6))
        names.extend(outcomes)

    r = run(config, tmp_path, on_hold=on_hold)
    assert len(names) == 20
    for label in names:
        assert isinstance(outcomes[label], ValueError), f"{label}: {outcomes[label]!r}"
    # The messages name the culprit.
    assert "cruise" in str(outcomes["undeclared mode"])
    assert "sun_lost" in str(outcomes["undeclared event"])
    assert "wheel_speed" in str(outcomes["undeclared value"])
    assert "'ok'" in str(outcomes["missing value"])
    assert "h_b_nms" in str(outcomes["short vector"])
    assert "h_b_nms[1]" in str(outcomes["NaN f64"])
    assert "fault_word" in str(outcomes["i64 too large"])
    # Nothing went out: nothing refused, and the recording is the honest one, seq included.
    assert r.final.rejected_fsw_refused == 0, r.log
    assert r.fsw_csv == reference.fsw_csv
    assert_records_exactly(r)
    assert [m.header.seq for m in r.sent] == list(range(LAST))



def test_sdk_sample_edges(declaration):
    """What the SDK does accept at the edges, without sending: the i64 range's ends, bools as
    0/1, and a declaration without the stream is a KeyError."""
    h = Header(SPACECRAFT_ID, 3, 3 * FRAME_NS, 0)
    assert declaration.words == 5
    lo = declaration.sample(h, h_b_nms=(0, 0, 0), fault_word=-2**63, ok=0)
    hi = declaration.sample(h, h_b_nms=(0, 0, 0), fault_word=2**63 - 1, ok=1)
    assert lo.values[3] == 2**63 and hi.values[3] == 2**63 - 1
    assert (lo.values[4], hi.values[4]) == (0, 1)
    assert lo.flags == 0 and lo.event_count == 0 and lo.q_est_bn == (1.0, 0.0, 0.0, 0.0)
    s = decode_sample(declaration, lo)
    assert s["fault_word"] == [-2**63] and s["mode"] is None and s["estimate"] is None
    assert decode_sample(declaration, hi)["fault_word"] == [2**63 - 1]
    with pytest.raises(KeyError, match="'acs'"):
        FswDeclaration.from_config({"fsw_streams": [{"name": "acs"}]}, "nope")
    with pytest.raises(KeyError, match="none"):
        FswDeclaration.from_config({}, "acs")


def test_declare_fsw_of_an_undeclared_stream_is_a_key_error(config):
    with flexdyn_server(config=config, mode="lockstep", participants=[1],
                        duration_s=DURATION_S, timeout_s=30.0) as server:
        with flexdyn.Client(server.endpoint) as client:
            with pytest.raises(KeyError) as e:
                client.declare_fsw("nope")
            assert "'nope'" in str(e.value) and "'acs'" in str(e.value)
            assert client.declare_fsw("acs").declaration.words == 5
        server.stop()
    assert server.returncode == 0, server.log
