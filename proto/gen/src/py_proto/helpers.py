_HEADER = struct.Struct("<HIQQQ")


class DecodeError(ValueError):
    """Why a buffer is not a message. ``reason`` is the Rust ``DecodeError`` variant name:
    ``Length`` (``needed``, ``actual``), ``TrailingBytes`` (``expected``, ``actual``),
    ``TooLarge`` (``actual``), ``UnknownVersion`` (``found``), ``NonFinite`` (``field``) or
    ``Malformed`` (``detail``)."""

    def __init__(self, reason: str, **info: object) -> None:
        self.reason = reason
        self.info = info
        super().__init__(f"{reason}: {info}")

    def canonical(self) -> str:
        """The verdict line of ``flexdyn-decode-verdicts`` for this error."""
        i = self.info
        if self.reason == "Length":
            return f"E Length {i['needed']} {i['actual']}"
        if self.reason == "TrailingBytes":
            return f"E TrailingBytes {i['expected']} {i['actual']}"
        if self.reason == "TooLarge":
            return f"E TooLarge {i['actual']}"
        if self.reason == "UnknownVersion":
            return f"E UnknownVersion {i['found']}"
        if self.reason == "NonFinite":
            return f"E NonFinite {i['field']}"
        return "E Malformed"


def _check_size_and_version(buf: bytes, min_len: int) -> None:
    if len(buf) > MAX_MESSAGE_BYTES:
        raise DecodeError("TooLarge", actual=len(buf), max=MAX_MESSAGE_BYTES)
    if len(buf) < 2:
        raise DecodeError("Length", needed=min_len, actual=len(buf))
    (version,) = struct.unpack_from("<H", buf, 0)
    if version != PROTOCOL_VERSION:
        raise DecodeError("UnknownVersion", found=version)


def _check_total(expected: int, buf: bytes) -> None:
    if len(buf) < expected:
        raise DecodeError("Length", needed=expected, actual=len(buf))
    if len(buf) > expected:
        raise DecodeError("TrailingBytes", expected=expected, actual=len(buf))


class _Walker:
    """Bounded cursor over count prefixes (rule 3)."""

    def __init__(self, buf: bytes, at: int) -> None:
        self.buf, self.at = buf, at

    def skip(self, n: int) -> None:
        if self.at + n > len(self.buf):
            raise DecodeError("Length", needed=self.at + n, actual=len(self.buf))
        self.at += n

    def count(self, maximum: int, what: str) -> int:
        if self.at + 8 > len(self.buf):
            raise DecodeError("Length", needed=self.at + 8, actual=len(self.buf))
        (n,) = struct.unpack_from("<Q", self.buf, self.at)
        if n > maximum:
            raise DecodeError("Malformed", detail=f"{what} count {n} exceeds maximum {maximum}")
        self.at += 8
        return n

    def values(self, maximum: int, size: int, what: str) -> None:
        self.skip(size * self.count(maximum, what))


@dataclass
class Header:
    """Common header, the first 30 bytes of every message."""

    spacecraft_id: int = 0
    tick: int = 0
    sim_time_ns: int = 0  # [ns] simulation time of `tick`
    seq: int = 0
    protocol_version: int = PROTOCOL_VERSION

    def encode(self) -> bytes:
        return _HEADER.pack(
            self.protocol_version, self.spacecraft_id, self.tick, self.sim_time_ns, self.seq
        )

    @staticmethod
    def unpack(buf: bytes) -> "Header":
        v, sc, tick, t, seq = _HEADER.unpack_from(buf, 0)
        return Header(sc, tick, t, seq, v)

    @staticmethod
    def decode(buf: bytes) -> "Header":
        """The header of any message (size, version and the first 30 bytes are checked)."""
        _check_size_and_version(buf, HEADER_LEN)
        if len(buf) < HEADER_LEN:
            raise DecodeError("Length", needed=HEADER_LEN, actual=len(buf))
        return Header.unpack(buf)


def _f(buf: bytes, at: int, n: int) -> Tuple[float, ...]:
    return struct.unpack_from(f"<{n}d", buf, at)


def _pack_f(values) -> bytes:
    return struct.pack(f"<{len(values)}d", *values)


def _target_bytes(target: str) -> bytes:
    b = target.encode("utf-8")
    if len(b) > FAULT_TARGET_LEN or b"\0" in b:
        raise ValueError(f"fault target {target!r}: at most {FAULT_TARGET_LEN} bytes, no NUL")
    return b + bytes(FAULT_TARGET_LEN - len(b))


def _target_str(b: bytes) -> str:
    return b.split(b"\0", 1)[0].decode("utf-8", errors="replace")


def _check_text_padded(b: bytes, field: str) -> None:
    """The text rule (README "Decoder rules", step 4): the text ends at its first NUL byte and
    every byte after it is NUL."""
    end = b.find(b"\0")
    if end >= 0 and b[end:].count(0) != len(b) - end:
        raise DecodeError("Malformed", detail=f"{field}: a byte other than NUL after its NUL")


def _check_len(value, n: int, what: str) -> None:
    """An array field must hold exactly its n entries (a clear error instead of struct's)."""
    if len(value) != n:
        raise ValueError(f"{what} has {len(value)} entries, not {n}")


