# --------------------------------------------------------------------------------------------
# Hand-written helpers (proto/gen/src/py_proto/tail.py).

# The fault modes by code (proto/README.md, "Fault modes"): name and parameter names.
FAULT_MODES = (
    ("stuck_current", ()), ("stuck_value", ("value",)), ("bias_step", ("value",)),
    ("bias_ramp", ("rate_per_s",)), ("scale", ("factor",)), ("noise", ("sigma",)),
    ("spikes", ("probability", "amplitude")), ("dropout", ()), ("validity_off", ()),
    ("friction_scale", ("factor",)), ("torque_limit", ("fraction",)), ("seized", ()),
    ("command_ignored", ()), ("stuck_on", ()), ("stuck_off", ()), ("thrust_scale", ("factor",)),
    ("dead", ()), ("dipole_scale", ("factor",)),
    # Command links: configuration only (a live fault command with these codes is refused).
    ("dropped", ()), ("delayed", ("frames",)), ("corrupted", ("probability",)),
)

# Names from before the wire table, kept for existing code.
WRENCH, NO_COMMAND_KIND, ACTUATORS = COMMAND_WRENCH, COMMAND_NO_COMMAND, COMMAND_ACTUATORS
PANEL_PAIR, REACTION_WHEEL = EFFECTOR_PANEL_PAIR, EFFECTOR_REACTION_WHEEL
MAGNETORQUER, THRUSTER = EFFECTOR_MAGNETORQUER, EFFECTOR_THRUSTER
STATE_EFFECTOR_COUNT_OFFSET = STATE_EFFECTORS_COUNT_OFFSET
fault_key = fault_command_key
Vec3 = Tuple[float, float, float]


def fault_command(spacecraft_id: int, target: str, mode: str, at_tick: int = AT_NEXT_TICK,
                  duration_ns: int = 0, axes=(), seed: int = 0, seq: int = 0, tick: int = 0,
                  **params: float) -> FaultCommandMsg:
    """An ``Inject`` FaultCommandMsg from a mode name and its parameters by name (as in
    ``[[faults]]``): ``fault_command(1, "imus.hub.gyro", "bias_step", at_tick=40, value=0.01,
    axes=(1, 3))``."""
    codes = [m[0] for m in FAULT_MODES]
    if mode not in codes:
        raise ValueError(f"unknown fault mode {mode!r} (expected one of {', '.join(codes)})")
    code = codes.index(mode)
    names = FAULT_MODES[code][1]
    if set(params) != set(names):
        raise ValueError(f"mode {mode!r} takes {', '.join(names) or 'no parameters'}, "
                         f"got {', '.join(params) or 'none'}")
    values = [float(params[n]) for n in names] + [0.0] * (2 - len(names))
    bits = 0
    for a in axes:
        bits |= 1 << (int(a) - 1)
    return FaultCommandMsg(Header(spacecraft_id, tick, 0, seq), FAULT_INJECT,
                           at_tick, 0, code, (values[0], values[1]), bits, duration_ns, seed,
                           _target_bytes(target))


def fault_clear(spacecraft_id: int, fault_index: int, at_tick: int = AT_NEXT_TICK, seq: int = 0,
                tick: int = 0) -> FaultCommandMsg:
    """A ``Clear`` FaultCommandMsg for fault ``fault_index``."""
    return FaultCommandMsg(Header(spacecraft_id, tick, 0, seq), FAULT_CLEAR,
                           at_tick, fault_index)


def telemetry_key(sc: str) -> str:
    """``flexdyn/<sc>/tlm/**``: the state and every sensor topic. One subscriber on it sees a
    tick's samples in the order the server published them (proto/README.md, "Lockstep
    protocol")."""
    return _key(sc, "tlm/**")


def config_key(sc: str) -> str:
    """``flexdyn/<sc>/config``: the server's configuration queryable (a ``get`` returns UTF-8
    JSON, not a bincode message)."""
    return _key(sc, "config")


def participant_key(sc: str, sender_id: int) -> str:
    return _key(sc, "participant", _sender(sender_id))
