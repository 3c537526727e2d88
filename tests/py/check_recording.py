"""Independent check of a flexdyn MCAP recording with the `mcap` package from PyPI.

Usage:
    python check_recording.py FILE.mcap              # a cleanly closed recording
    python check_recording.py FILE.mcap --truncated  # a recording cut by SIGKILL

Clean file: the summary lists a schema for every channel; every channel decodes (raw ones by
the layout in proto/README.md, JSON ones with json.loads); each decoded StateMsg equals its raw
payload field by field; each foxglove.FrameTransforms N -> B rotation equals [BN]^T computed
from sigma_BN with the MRP formula (Schaub & Junkins, Eq. 3.152) written out here; the
metadata names the flexdyn version and holds the configuration TOML.

Truncated file: read with the non-seeking stream reader until the cut; at least one chunk of
messages must decode.

Prints one line of counts; exits non-zero with a message on any failure.
"""

import json
import struct
import sys

from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader
from mcap.records import Channel, Message, Schema


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def mrp_dcm(s):
    """[BN] from sigma: C = I + (8 S^2 - 4 (1 - s^2) S) / (1 + s^2)^2, S = tilde(sigma)."""
    s2 = sum(x * x for x in s)
    S = [[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]]
    SS = [[sum(S[i][k] * S[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    d = (1.0 + s2) ** 2
    return [
        [(1.0 if i == j else 0.0) + (8.0 * SS[i][j] - 4.0 * (1.0 - s2) * S[i][j]) / d for j in range(3)]
        for i in range(3)
    ]


def active_rotation(q):
    """Rotation matrix of a Hamilton quaternion {x, y, z, w} (child -> parent components)."""
    x, y, z, w = q["x"], q["y"], q["z"], q["w"]
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def decode_state_raw(data):
    """The fixed part of a StateMsg (proto/README.md offsets) and its effectors."""
    version, sc, tick, t_ns, seq = struct.unpack_from("<HIQQQ", data, 0)
    f = lambda off, n: list(struct.unpack_from("<%dd" % n, data, off))
    out = {
        "protocol_version": version,
        "spacecraft_id": sc,
        "tick": tick,
        "sim_time_ns": t_ns,
        "seq": seq,
        "sigma_bn": f(30, 3),
        "q_bn": f(54, 4),
        "omega_bn_b_rad_s": f(86, 3),
        "omega_dot_bn_b_rad_s2": f(110, 3),
        "r_bn_n_m": f(134, 3),
        "v_bn_n_m_s": f(158, 3),
        "nongrav_accel_bn_n_m_s2": f(182, 3),
        "orb_energy_j": f(206, 1)[0],
        "rot_energy_j": f(214, 1)[0],
        "torque_b_nm": f(270, 3),
        "force_b_newton": f(294, 3),
        "command_flags": data[318],
    }
    (n,) = struct.unpack_from("<Q", data, 319)
    off = 327
    effectors = []
    for _ in range(n):
        kind, flags, ns = struct.unpack_from("<HIQ", data, off)
        off += 14
        states = f(off, ns)
        off += 8 * ns
        (no,) = struct.unpack_from("<Q", data, off)
        off += 8
        outputs = f(off, no)
        off += 8 * no
        effectors.append({"kind": kind, "flags": flags, "states": states, "outputs": outputs})
    if off != len(data):
        fail("StateMsg of %d bytes has %d trailing bytes" % (len(data), len(data) - off))
    out["effectors"] = effectors
    return out


def check_state_pair(raw, js):
    h = js["header"]
    for k in ("protocol_version", "spacecraft_id", "tick", "sim_time_ns", "seq"):
        if raw[k] != h[k]:
            fail("header.%s: raw %r, json %r" % (k, raw[k], h[k]))
    for k in ("sigma_bn", "q_bn", "omega_bn_b_rad_s", "omega_dot_bn_b_rad_s2", "r_bn_n_m",
              "v_bn_n_m_s", "nongrav_accel_bn_n_m_s2", "command_flags"):
        if raw[k] != js[k]:
            fail("%s at tick %d: raw %r, json %r" % (k, raw["tick"], raw[k], js[k]))
    for k in ("orb_energy_j", "rot_energy_j"):
        if raw[k] != js["conserved"][k]:
            fail("conserved.%s differs at tick %d" % (k, raw["tick"]))
    for k in ("torque_b_nm", "force_b_newton"):
        if raw[k] != js["wrench_applied"][k]:
            fail("wrench_applied.%s differs at tick %d" % (k, raw["tick"]))
    if raw["effectors"] != js["effectors"]:
        fail("effectors differ at tick %d" % raw["tick"])


ENV_SOURCES = ("gravity_gradient", "drag", "solar_pressure", "residual_dipole")


def decode_environment_raw(data):
    """An EnvironmentMsg (376 bytes, proto/README.md offsets), as the JSON channel names it."""
    if len(data) != 376:
        fail("EnvironmentMsg of %d bytes (expected 376)" % len(data))
    version, sc, tick, t_ns, seq = struct.unpack_from("<HIQQQ", data, 0)
    f = lambda off, n: list(struct.unpack_from("<%dd" % n, data, off))
    out = {
        "header": {"protocol_version": version, "spacecraft_id": sc, "tick": tick,
                   "sim_time_ns": t_ns, "seq": seq},
        "tai_ns_1958": struct.unpack_from("<Q", data, 30)[0],
        "flags": data[38], "eclipse": data[39],
        "b_n_t": f(40, 3), "b_b_t": f(64, 3), "sun_n": f(88, 3), "sun_b": f(112, 3),
        "moon_n": f(136, 3), "shadow_factor": f(160, 1)[0], "density_kg_m3": f(168, 1)[0],
    }
    for i, src in enumerate(ENV_SOURCES):
        out[src] = {"torque_b_nm": f(176 + 48 * i, 3), "force_b_newton": f(200 + 48 * i, 3)}
    out["albedo_nadir_w_m2"] = f(368, 1)[0]  # since protocol 11
    return out


def check_clean(path):
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None:
            fail("no summary section")
        if not summary.chunk_indexes:
            fail("no chunk indexes")
        compressions = {c.compression for c in summary.chunk_indexes}
        if compressions != {"zstd"}:
            fail("chunk compression %r, expected zstd" % compressions)
        for cid, ch in summary.channels.items():
            if ch.schema_id == 0 or ch.schema_id not in summary.schemas:
                fail("channel %s has no schema" % ch.topic)
            sch = summary.schemas[ch.schema_id]
            if ch.message_encoding == "json" and sch.encoding != "jsonschema":
                fail("json channel %s has schema encoding %s" % (ch.topic, sch.encoding))
            if ch.message_encoding == "json":
                json.loads(sch.data)  # the schema itself is JSON
            if ch.message_encoding == "flexdyn-proto":
                text = sch.data.decode()
                if "protocol_version" not in text or "| offset |" not in text:
                    fail("raw schema %s does not describe the layout" % sch.name)
        meta = {m.name: m.metadata for m in reader.iter_metadata()}
        if "flexdyn" not in meta or not meta["flexdyn"].get("flexdyn_version"):
            fail("no flexdyn metadata record: %r" % list(meta))
        vehicles = [k for k in meta if k.startswith("flexdyn/")]
        if not vehicles or "[hub]" not in meta[vehicles[0]].get("config_toml", ""):
            fail("no vehicle metadata with the configuration TOML: %r" % list(meta))

        raw_states, json_states, tfs, scenes, counts = {}, {}, [], 0, {}
        raw_envs, json_envs = {}, {}
        for schema, channel, message in reader.iter_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if channel.message_encoding == "json":
                obj = json.loads(message.data)
                if schema.name == "flexdyn.StateMsg":
                    json_states[obj["header"]["tick"]] = obj
                elif schema.name == "flexdyn.EnvironmentMsg":
                    json_envs[obj["header"]["tick"]] = obj
                elif schema.name == "foxglove.FrameTransforms":
                    tfs.append((message.log_time, obj))
                elif schema.name == "foxglove.SceneUpdate":
                    scenes += 1
                    if not obj["entities"]:
                        fail("empty scene")
            elif channel.message_encoding == "flexdyn-proto" and schema.name == "flexdyn.StateMsg":
                st = decode_state_raw(message.data)
                if message.log_time != st["sim_time_ns"]:
                    fail("log time %d is not the sim time %d" % (message.log_time, st["sim_time_ns"]))
                raw_states[st["tick"]] = st
            elif channel.message_encoding == "flexdyn-proto" and schema.name == "flexdyn.EnvironmentMsg":
                env = decode_environment_raw(message.data)
                if message.log_time != env["header"]["sim_time_ns"]:
                    fail("environment log time %d is not its sim time" % message.log_time)
                raw_envs[env["header"]["tick"]] = env
        if not raw_states or set(raw_states) != set(json_states):
            fail("raw ticks %d, decoded ticks %d" % (len(raw_states), len(json_states)))
        for tick, raw in raw_states.items():
            check_state_pair(raw, json_states[tick])
        if set(raw_envs) != set(json_envs):
            fail("raw environment ticks %d, decoded %d" % (len(raw_envs), len(json_envs)))
        for tick, raw in raw_envs.items():
            if raw != json_envs[tick]:
                fail("EnvironmentMsg at tick %d: raw %r, json %r" % (tick, raw, json_envs[tick]))
        if len(tfs) != len(raw_states) or scenes < 1:
            fail("%d transforms and %d scenes for %d states" % (len(tfs), scenes, len(raw_states)))
        by_time = {s["sim_time_ns"]: s for s in raw_states.values()}
        worst = 0.0
        for t, tf in tfs:
            nb = tf["transforms"][0]
            if not (nb["parent_frame_id"].endswith("N") and nb["child_frame_id"].endswith("B")):
                fail("first transform is %s -> %s" % (nb["parent_frame_id"], nb["child_frame_id"]))
            st = by_time[t]
            C = mrp_dcm(st["sigma_bn"])
            R = active_rotation(nb["rotation"])
            for i in range(3):
                for j in range(3):
                    worst = max(worst, abs(R[i][j] - C[j][i]))
            tr = nb["translation"]
            if [tr["x"], tr["y"], tr["z"]] != st["r_bn_n_m"]:
                fail("N -> B translation is not r_BN at t = %d ns" % t)
        if worst > 1e-12:
            fail("FrameTransform rotation differs from [BN]^T by %.3e" % worst)
        print("OK clean: %d channels, %d states, %d transforms (max |R - [BN]^T| = %.2e), topics %s"
              % (len(summary.channels), len(raw_states), len(tfs), worst, sorted(counts.items())))
        print("environment messages: %d raw = decoded" % len(raw_envs))


def check_truncated(path):
    n_messages, error = 0, None
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f, skip_magic=False).records:
                if isinstance(record, Message):
                    n_messages += 1
        except (McapError, EOFError, ValueError, struct.error) as e:
            error = "%s: %s" % (type(e).__name__, e)
    if n_messages == 0:
        fail("no message could be read before the cut (%s)" % error)
    print("OK truncated: %d messages readable before the cut (%s)" % (n_messages, error))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[2] == "--truncated":
        check_truncated(sys.argv[1])
    elif len(sys.argv) == 2:
        check_clean(sys.argv[1])
    else:
        fail("usage: check_recording.py FILE.mcap [--truncated]")
