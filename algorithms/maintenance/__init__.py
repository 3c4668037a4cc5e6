"""Connectivity maintenance: robots that act on their connectivity (seeds 001 and 002).

* :mod:`.regions` -- discs on the plane: exact union area, candidate region centres,
  the move-towards map (seed 002's experiment and MOVE).
* :mod:`.biconnected` -- Ahmadi & Stone (seed 002): adding and removing robots while the
  team stays biconnected.
* :mod:`.roles` -- Kobayashi, Higuchi & Ueno (seed 001): roles, Algorithm 1 role
  switching, motion laws Eq. 1-7, recovery of disconnected explorers.
* :mod:`.gabriel` -- seed 001's Acute Angle Test and Algorithm 2 (Gabriel graph).
"""
