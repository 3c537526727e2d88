"""flexdyn: the Python SDK of the flexdyn dynamics server.

- :mod:`flexdyn.proto`: every wire message as a dataclass, with encode/decode;
- :class:`Client`: a Zenoh session the flexdyn way, typed subscriptions (all telemetry through
  one ``flexdyn/<sc>/tlm/**`` subscriber, in publication order), commands, and the server's
  configuration (:meth:`Client.vehicle`);
- :class:`LockstepParticipant`: answers every lockstep tick with your controller's output,
  computed from the tick's complete telemetry (the state and every sensor sample due at it);
- :mod:`flexdyn.fsw`: the flight code's own telemetry (:meth:`Client.declare_fsw`);
- :mod:`flexdyn.testing`: run a server for the duration of a test.
"""

from . import proto
from .client import Client, Subscription, VehicleInfo, session_config
from .lockstep import Answer, LockstepParticipant, SensorSchedule, Tick
from .proto import (CommandMsg, CssMsg, DecodeError, EffectorInput, EffectorState,
                    EnvironmentMsg, FssMsg, Header, ImuMsg, MagnetometerMsg, OperatorMsg,
                    StarTrackerMsg, StateMsg, StatusMsg, TimeMsg)
from .proto import GpsMsg  # protocol 7
from .proto import FaultCommandMsg, FaultEventMsg  # protocol 8
from .proto import RelativeStateMsg  # protocol 9
from .proto import FswMsg  # protocol 10
from .fsw import FswDeclaration, FswStream  # protocol 10: the flight code's own telemetry

__all__ = [
    "proto", "Client", "Subscription", "VehicleInfo", "session_config", "Answer",
    "LockstepParticipant", "SensorSchedule", "Tick", "CommandMsg", "DecodeError",
    "EffectorInput", "EffectorState", "EnvironmentMsg", "Header", "ImuMsg", "MagnetometerMsg", "StarTrackerMsg",
    "StateMsg",
    "StatusMsg", "TimeMsg", "CssMsg", "FssMsg", "OperatorMsg", "GpsMsg",
    "FaultCommandMsg", "FaultEventMsg", "RelativeStateMsg", "FswMsg", "FswDeclaration",
    "FswStream",
]
__version__ = "0.1.0"
