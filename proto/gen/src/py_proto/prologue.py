"""The flexdyn wire protocol, version {VERSION}, in pure Python.

{GENERATED}

Every message of ``proto/README.md`` as a dataclass with ``encode()`` and ``decode(bytes)``.
Decoding follows the README's decoder rules in the same order and raises :class:`DecodeError`
with the same reasons as the Rust crate's ``DecodeError``:

1. more than ``MAX_MESSAGE_BYTES`` -> ``TooLarge``;
2. fewer than 2 bytes -> ``Length``; first two bytes (u16 LE) != ``PROTOCOL_VERSION`` ->
   ``UnknownVersion``;
3. the total length from the layout (fixed; command tag at 34; walked counts, each bounded
   first) -> ``Length`` (needed = length implied by the counts read so far), ``Malformed``
   (unknown tag, count above its maximum), ``TrailingBytes``;
4. fields in wire order: an enum tag out of range, a bool byte other than 0/1, or a bounded
   count above its bound (a CssMsg's detectors above ``MAX_CSS_DETECTORS``) -> ``Malformed``;
   a text field (a fault ``target``) with a byte other than NUL after its first NUL ->
   ``Malformed``;
5. the fields the table marks finite (CommandMsg's torque, force and input values,
   FaultCommandMsg's parameters), in wire order: a NaN or infinite value -> ``NonFinite``
   naming the field.

Units are in the field names (SI; ``_nm`` newton-metres, ``_newton`` newtons); frames too
(``_b`` body, ``_n`` inertial, ``_p`` IMU platform, ``_c`` star-tracker case).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import ClassVar, List, Optional, Tuple

