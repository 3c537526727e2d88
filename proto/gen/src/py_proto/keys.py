# --------------------------------------------------------------------------------------------
# Key expressions (proto/README.md, "Topics").

def _valid_id(s: str) -> bool:
    return 0 < len(s) <= 64 and all(c.isascii() and (c.isalnum() or c in "_-") for c in s)


def _key(sc: str, suffix: str, name: Optional[str] = None) -> str:
    if not _valid_id(sc):
        raise ValueError(f"invalid spacecraft id {sc!r}: 1-64 characters from [A-Za-z0-9_-]")
    if name is not None and not _valid_id(name):
        raise ValueError(f"invalid name {name!r}: 1-64 characters from [A-Za-z0-9_-]")
    return f"flexdyn/{sc}/{suffix}" + (f"/{name}" if name is not None else "")


def _sender(sender_id: int) -> str:
    if not (isinstance(sender_id, int) and 0 <= sender_id <= 0xFFFFFFFF):
        raise ValueError(f"invalid sender_id {sender_id!r}: an integer 0..4294967295")
    return str(sender_id)


