"""Connectivity awareness: per-robot minds that only see their own inbox and neighbours.

* :mod:`.stamps` -- Ahmadi & Stone: stamped-message relay (Algorithm 1),
  CR-FILL, DCR-FILL (Algorithm 2) and the biconnectivity check (Algorithm 3).
* :mod:`.tables` -- Le et al.: connectivity tables of access paths to a
  reference robot (Algorithm 1, New-Access-Path), Link-Broken updates, table exchange
  with new neighbours, the forward-two variant, and the check the tables give.

Every robot object has ``tick(now, inbox, neighbors) -> list[Message]``, driven once per
control tick (one tick is the papers' bound c on a one-hop relay, Ahmadi & Stone Assumption 4;
"a step" in Le et al.): ``now`` is the tick number, ``inbox`` what the radio delivered this
tick (:class:`algorithms.robot.Message` with its sender), ``neighbors`` the ids the robot
hears this tick (both papers take neighbour discovery from the network layer; it costs no
messages). The controllers of :mod:`algorithms.controllers` wrap them.
"""

from algorithms.connectivity.stamps import BiconnectivityCheck, dcr_members, stamp_relay
from algorithms.connectivity.tables import (
    ConnectivityTable,
    Report,
    TableCheck,
    merge_groups,
)

__all__ = [
    "BiconnectivityCheck",
    "ConnectivityTable",
    "Report",
    "TableCheck",
    "dcr_members",
    "merge_groups",
    "stamp_relay",
]
