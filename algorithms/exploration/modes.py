"""The embodied explorer's modes (:class:`~algorithms.exploration.explorer.Explorer`): one at
a time, moved only along :data:`TRANSITIONS`, the table this diagram draws; every mode
that is not terminal may also end in HALTED (it stops for good) or INFEASIBLE (its
tether's stall verdict, rule 5)::

    SCANNING   --ARRIVED------------------------------> DECIDING
    DECIDING   --go------------------------------------> ASKING  (ON_LANE without entry)
               --idle----------------------------------> IDLE
               --done, cut off-------------------------> FINISHED
    IDLE       --idle_wait_s, a relay mission----------> DECIDING
    ASKING     --EntryGranted--------------------------> LEAVING
               --EntryGranted clear, must hold---------> WITHDRAWN  (Withdraw)
               --ungranted GIVE_UP_S-------------------> GIVING_UP  (GiveUp)
               --EntryBlocked, a relay mission---------> DECIDING
    GIVING_UP  --EntryGranted--------------------------> LEAVING
               --EntryBusy, EntryBlocked---------------> DECIDING
    WITHDRAWN  --free to move--------------------------> ASKING     (EntryRequest)
               --EntryBlocked, a relay mission---------> DECIDING
    LEAVING    --in its corridor-----------------------> ON_LANE    (LeftVertex)
               --must walk back, no room to turn-------> TURN_ASKED_LEAVING (TurnedBack)
    ON_LANE    --ARRIVED-------------------------------> DECIDING
               --must walk back, no room to turn-------> TURN_ASKED (TurnedBack)
               --must walk back, room to turn----------> WALKING_BACK_UNTOLD (U-turn)
               --must walk back, no vertex entry-------> WALKING_BACK
    TURN_ASKED_LEAVING --in its corridor---------------> TURN_ASKED (LeftVertex)
                       --EntryGranted------------------> WALKING_BACK
    TURN_ASKED --EntryGranted--------------------------> WALKING_BACK
               --room to turn first--------------------> WALKING_BACK_UNTOLD (U-turn)
               --ARRIVED (a swap gave the vertex away)-> DECIDING
    WALKING_BACK_UNTOLD --on its new lane, EntryGranted-> WALKING_BACK (TurnedBack)
    WALKING_BACK --ARRIVED-----------------------------> DECIDING

"Must walk back" is rule 6's (a relay's plan, :meth:`~algorithms.exploration.relay.
ConnectedExplorer.direction`) or a vertex ahead that closed (EntryBlocked on the way).
Besides its mode a robot keeps what the stations last said of the vertex ahead (clear
of its previous holder or not), and, on a lane, its pass
(:class:`~algorithms.exploration.passing.BodyWatch`); in a terminal mode it hears the
stations no more.
"""

from __future__ import annotations

from enum import Enum


class Mode(Enum):
    """What an :class:`~algorithms.exploration.explorer.Explorer` is doing: one mode at a time
    (the module docstring's diagram; :data:`TRANSITIONS` lists every move). The navigator's
    own states (:class:`~algorithms.navigation.NavigatorState`) say how its body moves
    meanwhile; a pass (:class:`~algorithms.exploration.passing.Pass`) runs beside a mode on
    a lane."""

    SCANNING = "scanning"  # on a vertex centre, its navigator measuring the edges
    DECIDING = "deciding"  # the vertex call: beacon in, decision out (within a tick)
    IDLE = "idle"  # its strategy answered idle: it asks again after ``idle_wait_s``
    ASKING = "asking to enter"  # decided to leave; its EntryRequest is out
    GIVING_UP = "giving up"  # sent GiveUp for its request; no answer yet
    WITHDRAWN = "withdrawn"  # gave a clear grant back (rule 2): asks again once free to move
    LEAVING = "leaving"  # on its way, holding the vertex it left until in its corridor
    ON_LANE = "on the lane"  # on its way, clear of the vertex it left
    TURN_ASKED_LEAVING = "asking to turn, leaving"  # as TURN_ASKED, in the area it left
    TURN_ASKED = "asking to turn"  # to walk back, asked for the vertex behind; goes on
    WALKING_BACK_UNTOLD = "walking back, untold"  # U-turned; tells once on its new lane
    WALKING_BACK = "walking back"  # to the vertex it left, the stations told
    FINISHED = "finished"  # declared the exploration complete, or its part (cut off)
    HALTED = "halted"  # stopped for good (``Explorer.halted`` says why)
    INFEASIBLE = "infeasible"  # its tether's stall verdict (rule 5): stands for good


#: Modes a robot never leaves.
TERMINAL = frozenset({Mode.FINISHED, Mode.HALTED, Mode.INFEASIBLE})
#: On a centre, decided to leave, waiting for the stations.
WAITING = frozenset({Mode.ASKING, Mode.GIVING_UP, Mode.WITHDRAWN})
#: Between a departure and the next arrival.
ON_LEG = frozenset({Mode.LEAVING, Mode.ON_LANE, Mode.TURN_ASKED_LEAVING, Mode.TURN_ASKED,
                    Mode.WALKING_BACK_UNTOLD, Mode.WALKING_BACK})
#: Holding the vertex it left as well as the one ahead (it owes the stations LeftVertex).
HOLDS_BEHIND = frozenset({Mode.LEAVING, Mode.TURN_ASKED_LEAVING})
#: Walking back along its leg (rule 6, or from a vertex that closed).
RETURNING = frozenset({Mode.WALKING_BACK_UNTOLD, Mode.WALKING_BACK})
#: Every move between modes, with what makes it. Besides these, every mode not in
#: :data:`TERMINAL` may end in HALTED (it stops for good) or INFEASIBLE (rule 5).
TRANSITIONS: dict[Mode, dict[Mode, str]] = {
    Mode.SCANNING: {Mode.DECIDING: "its navigator measured the edges (ARRIVED)"},
    Mode.DECIDING: {
        Mode.ASKING: "go: it asks the stations for the lane (EntryRequest)",
        Mode.ON_LANE: "go, without vertex entry: it departs at once",
        Mode.IDLE: "idle",
        Mode.FINISHED: "done, or cut off with its part finished"},
    Mode.IDLE: {Mode.DECIDING: "idle_wait_s passed (at once on a relay mission)"},
    Mode.ASKING: {
        Mode.LEAVING: "EntryGranted: it departs",
        Mode.WITHDRAWN: "EntryGranted clear while it must hold for a child (rule 2): Withdraw",
        Mode.GIVING_UP: "ungranted for GIVE_UP_S: GiveUp",
        Mode.DECIDING: "EntryBlocked, or it sets out as a relay (Withdraw)"},
    Mode.GIVING_UP: {
        Mode.LEAVING: "EntryGranted (the grant overtook its GiveUp): it departs",
        Mode.DECIDING: "EntryBusy (it plans round that edge) or EntryBlocked"},
    Mode.WITHDRAWN: {
        Mode.ASKING: "no child to hold for (none, or all held by the world): it asks again",
        Mode.DECIDING: "EntryBlocked, or it sets out as a relay"},
    Mode.LEAVING: {
        Mode.ON_LANE: "in its corridor, or calling a relay clear of the centre: LeftVertex",
        Mode.TURN_ASKED_LEAVING: "it must walk back, short of room to turn: TurnedBack"},
    Mode.ON_LANE: {
        Mode.DECIDING: "arrived at the vertex ahead",
        Mode.TURN_ASKED: "it must walk back, short of room to turn: TurnedBack",
        Mode.WALKING_BACK_UNTOLD: "it must walk back, with room: a U-turn",
        Mode.WALKING_BACK: "it must walk back, without vertex entry"},
    Mode.TURN_ASKED_LEAVING: {
        Mode.TURN_ASKED: "in its corridor: LeftVertex",
        Mode.WALKING_BACK: "EntryGranted: the vertex behind is its own"},
    Mode.TURN_ASKED: {
        Mode.WALKING_BACK: "EntryGranted: the vertex behind is its own",
        Mode.WALKING_BACK_UNTOLD: "room to turn before the answer: a U-turn",
        Mode.DECIDING: "arrived at the vertex ahead (a swap gave the one behind away)"},
    Mode.WALKING_BACK_UNTOLD: {
        Mode.WALKING_BACK: "on its new lane: TurnedBack; or EntryGranted"},
    Mode.WALKING_BACK: {Mode.DECIDING: "arrived back"},
}
