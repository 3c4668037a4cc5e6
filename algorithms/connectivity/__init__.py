"""Connectivity awareness: per-robot minds that only see their own inbox and neighbours.

* :mod:`.stamps` -- Ahmadi & Stone (seed 002): stamped-message relay (Algorithm 1),
  CR-FILL, DCR-FILL (Algorithm 2) and the biconnectivity check (Algorithm 3).
* :mod:`.tables` -- Le et al. (seed 004): connectivity tables of access paths to a
  reference robot (Algorithm 1, New-Access-Path), Link-Broken updates, table exchange
  with new neighbours, the forward-two variant, and the check the tables give.

Every robot object has ``tick(now, inbox, neighbors) -> list[Outgoing]`` (see
:mod:`.base`); the static harness and the embodied world drive it the same way.
"""

from algorithms.connectivity.base import Outgoing, Received
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
    "Outgoing",
    "Received",
    "Report",
    "TableCheck",
    "dcr_members",
    "merge_groups",
    "stamp_relay",
]
