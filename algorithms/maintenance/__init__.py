"""Connectivity maintenance: robots that act on their connectivity 
(Kobayashi et al.; Ahmadi & Stone).

* :mod:`.regions` -- discs on the plane: exact union area, candidate region centres,
  the move-towards map (Ahmadi & Stone's experiment and MOVE).
* :mod:`.biconnected` -- Ahmadi & Stone: adding and removing robots while the
  team stays biconnected.
* :mod:`.roles` -- Kobayashi, Higuchi & Ueno: roles, Algorithm 1 role
  switching, motion laws Eq. 1-7, recovery of disconnected explorers.
* :mod:`.gabriel` -- Kobayashi et al.'s Acute Angle Test and Algorithm 2 (Gabriel graph).
"""
