"""flexdyn: the Python SDK of the flexdyn dynamics server.

- :mod:`flexdyn.proto`: every wire message as a dataclass, with encode/decode;
- :class:`Client`: a Zenoh session the flexdyn way, typed subscriptions, commands;
- :class:`LockstepParticipant`: answers every lockstep tick with your controller's output;
- :mod:`flexdyn.testing`: run a server for the duration of a test.
"""

from . import proto
from .client import Client, LockstepParticipant, session_config
from .proto import (CommandMsg, DecodeError, EffectorInput, EffectorState, Header, ImuMsg,
                    StarTrackerMsg, StateMsg, StatusMsg)

__all__ = [
    "proto", "Client", "LockstepParticipant", "session_config", "CommandMsg", "DecodeError",
    "EffectorInput", "EffectorState", "Header", "ImuMsg", "StarTrackerMsg", "StateMsg",
    "StatusMsg",
]
__version__ = "0.1.0"
