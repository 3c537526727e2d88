"""A Python lockstep participant gets the magnetometer, sun-sensor and GPS samples of each tick
in its ``Tick`` (``scenarios/leo_environment.toml``: a magnetometer, a coarse-sun-sensor array and
a fine sun sensor at 10 Hz), every due sample present, and each reads what its documented model
says of the environment truth the server publishes at the same tick (``tlm/env``)."""

import math
from pathlib import Path

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import flexdyn
from flexdyn.testing import flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "leo_environment.toml"
CONFIG = tomllib.loads(SCENARIO.read_text())
DURATION_S = 2.0
LAST = int(DURATION_S * CONFIG["simulation"]["frame_hz"])


def test_a_lockstep_tick_carries_the_magnetometer_and_sun_sensors():
    ticks, envs = [], {}
    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=DURATION_S) as server:
        with flexdyn.Client(server.endpoint) as client:
            client.subscribe_environment(lambda m: envs.__setitem__(m.header.tick, m))
            with flexdyn.LockstepParticipant(client, 1,
                                             on_tick=lambda t: ticks.append(t)) as p:
                final = p.wait(timeout_s=120)
                schedule = p.schedule
    assert server.returncode == 0, server.log
    assert final.header.tick == LAST

    # The schedule, from the configuration: each at 10 Hz of the 100 Hz frames.
    assert schedule.others == (("mag/mag1", 10), ("css/css", 10), ("fss/fss", 10))
    assert [t.tick for t in ticks] == list(range(LAST + 1))
    assert all(t.missing == () for t in ticks)
    with_mag = [t for t in ticks if t.magnetometers]
    assert [t.tick for t in with_mag] == list(range(0, LAST + 1, 10))
    assert all(set(t.coarse_sun_sensors) == {"css"} and set(t.fine_sun_sensors) == {"fss"}
               for t in with_mag)
    assert all(not t.coarse_sun_sensors for t in ticks if t.tick % 10)
    # The GPS receiver (1 Hz, 0.2 s latency = 20 frames) measures at ticks 0 and 100 and
    # publishes at 20 and 120; its solution says when it was valid.
    gps = CONFIG["gps_receivers"][0]
    latency = round(gps["latency_s"] * CONFIG["simulation"]["frame_hz"])
    assert schedule.delayed == ((f"gps/{gps['name']}", 100, latency),)
    with_gps = [t for t in ticks if t.gps]
    assert [t.tick for t in with_gps] == [latency, 100 + latency]
    frame_ns = round(1e9 / CONFIG["simulation"]["frame_hz"])
    for t in with_gps:
        g = t.gps[gps["name"]]
        assert g.valid_sim_time_ns == (t.tick - latency) * frame_ns
        assert t.samples[f"gps/{gps['name']}"] is g

    mag = CONFIG["magnetometers"][0]
    css = CONFIG["coarse_sun_sensors"][0]
    assert mag["dcm_sb"] == [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    # Magnetometer error budget (scenario values): scale |s|·|B| ≤ 2e-3 · 60 µT, bias
    # |b| = 3.7e-7 T, noise 5 σ = 2.5e-7 T, quantisation lsb/2 = 5e-9 T.
    b_bound = 2e-3 * 60e-6 + math.sqrt(sum(x * x for x in mag["bias_s_t"])) \
        + 5 * mag["noise_sigma_t"] + mag["lsb_t"] / 2
    # Coarse detectors: cos θ · ν (scale 1) ± 5 σ noise ± lsb/2, where cos θ is clear of the
    # 80° field-of-view edge (cos 80° = 0.17).
    css_bound = 5 * css["noise_sigma"] + css["lsb"] / 2
    compared = 0
    for t in with_mag:
        env = envs.get(t.tick)
        if env is None:
            continue  # the environment subscriber may join after the first ticks
        compared += 1
        b = t.magnetometers["mag1"].b_s_t
        err = math.sqrt(sum((b[i] - env.b_b_t[i]) ** 2 for i in range(3)))
        assert err <= b_bound, f"tick {t.tick}: magnetometer off by {err} T"
        readings = t.coarse_sun_sensors["css"].readings
        for i, n in enumerate(css["normals_b"]):
            c = sum(n[j] * env.sun_b[j] for j in range(3))
            if c > 0.25:
                expected = c * env.shadow_factor
                assert abs(readings[i] - expected) <= css_bound, (t.tick, i, readings[i])
            elif c < 0.1:  # outside the field of view: zero plus noise, clamped at 0
                assert 0.0 <= readings[i] <= css_bound, (t.tick, i, readings[i])
    assert compared >= 15, f"only {compared} ticks had their environment message"
