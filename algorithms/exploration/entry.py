"""Vertex entry: the messages between a robot and the vertex stations.

Nagavarapu et al. emulated beacons with a central station over XBee that kept "separate
information for each vertex"; ours also decides who may enter which vertex area (one
robot per area, :mod:`mjswarm.experiments.stations` explains why no circular wait forms). Robots
reach the stations from anywhere (the station's XBee link), one control tick each way,
and every message is counted with the radio's. The protocol, from the robot's side:

1. On a vertex centre, having decided to leave along the edge at incidence angle ``a``
   (the common frame of the beacons), the robot sends :class:`EntryRequest` ``(a)`` to
   :data:`STATION`. It names the edge by what it knows; the station knows which vertex
   the robot holds (it granted it, or launched the robot there) and its own edges, so it
   finds the vertex ``w`` at the far end.
2. The station answers :class:`EntryGranted` once ``w`` is free (``clear`` False when
   ``w`` was granted with a closed chain of waits and its previous holder has not yet
   left its area; a :class:`VertexClear` follows when it has), or :class:`EntryDenied`
   when no edge lies within tolerance of ``a`` (the robot's frame is broken).
3. The robot leaves; once in its corridor (its left wall seen) it sends
   :class:`LeftVertex`: the station frees the vertex it left. Until ``w`` is clear it
   waits where its lane's wall ends, out of ``w``'s area.
4. A robot that stops for good sends :class:`Halted`: the station drops its request and
   holds (a body left in a vertex area keeps that vertex closed: the station sees it).
   So does a robot cut off from the root that finished its part (``CUT_OFF``): it
   stands on its vertex's centre for good, and a robot of its component that still
   wants that vertex is answered as for any closed vertex (step 7), instead of waiting
   for ever.
5. Relays (rule 6 of :mod:`algorithms.exploration.relay`, ours). A relay's last leg ends
   part-way, where its requester is: its :class:`EntryRequest` says so (``part_way``),
   and the station lets it onto the lane at once without giving it the vertex ahead
   (:class:`EntryGranted` with ``clear`` False: it never enters that area). A robot that
   must walk back sends :class:`TurnedBack`, and the station frees the vertex ahead. Near
   the vertex behind (``from_lane`` False: short of its corridor, or too near for a
   U-turn clear of that area) it asks to return there and turns once it has the grant:
   at once if it never left that area, and no answer if the station gave it to another
   robot meanwhile (a swap: it goes on, and turns farther along); else when the vertex is
   free. Turned on its lane (``from_lane`` True, sent once it follows its new lane, out of
   the area ahead), it waits for the vertex behind where its new lane's wall ends; both
   wait as a request from a centre does. A robot granted a clear vertex while it
   must hold (rule 2 of the tether: it was adopted while it waited) sends :class:`Withdraw`:
   the station takes the grant back, and the robot asks again once it has no children, so
   that it does not keep two vertex areas while it stands in one (a robot granted a
   vertex not yet clear keeps it: a swap needs it to leave as soon as it may). A robot
   that sets out as a relay from a centre where it waits for a grant withdraws too, then
   asks for the way its mission takes. A grant names the request's angle, so that one
   overtaken by a withdrawal is known as such. A withdrawn swap leaves the other robot
   waiting, as before, until this one has left the vertex area it was given.
6. Passing a body that stands on a lane for good has its own protocol
   (:mod:`algorithms.exploration.passing`); a lane held for a pass is granted to nobody.
7. Closed vertices (ours: a body that cannot be passed). A vertex whose area holds
   a robot that stopped for good is *closed*: its station answers every request for it
   with :class:`EntryBlocked` instead of a grant, at once for requests waiting in its
   queue and for new ones when they come, naming the request's angle and never the
   vertex (robots know no true ids). A robot granted the vertex before it closed, on its
   way to it (waiting where its lane's wall ends for :class:`VertexClear`, since the
   body's holder never cleared it), gets :class:`EntryBlocked` too, with the angle it
   had asked for; it marks the edge blocked and walks back to the vertex it left, as in
   step 5 (a tethered robot stops for good there instead, out of the vertex area, on a
   lane that leads only into the closed vertex). A robot on a centre that gets it marks
   the edge blocked
   (:meth:`~algorithms.exploration.base.Strategy.block`) and decides anew.

8. Giving up a place in a queue (ours: not in the paper). Robots heading for one frontier queue
   vertex by vertex for grants (each waits on a centre for the vertex whose holder
   waits for the next), and a queue that reaches back to the root stops the launches. A
   robot on a centre whose request has not been granted for ``GIVE_UP_S`` sends
   :class:`GiveUp`. The station drops the request if it is still waiting and answers
   :class:`EntryBusy` with the request's angle; a request already granted stands (the
   grant is on its way and the robot obeys it), so no grant is ever taken back half-way.
   On ``EntryBusy`` the robot asks its strategy to plan again without leaving by that
   edge (:meth:`~algorithms.exploration.base.Strategy.give_up`) and asks for the way the
   new plan takes; only strategies that can plan round an edge give up (the others wait).

A station serves the beacon of its vertex only to the robot it granted (or launched
there): a robot that arrives anywhere else finds no beacon and stops.
"""

from __future__ import annotations

from typing import NamedTuple

#: The address of the vertex stations.
STATION = "station"
#: How long (s of simulated time) a robot waits on a centre for a grant before it gives
#: up its place (step 8): twice the longest wait measured in a run without a long queue.
#: Waits from a centre to its grant (``python benchmarks/grant_waits.py EXPLORE-ARGS``):
#: the main job (arena2, 4 robots) 0-26 s; a dense team (lattice:6x6, 8 robots, 0.15 m/s,
#: seed 1) median 0, 99th percentile 44 s, longest 58 s; in a long queue (lattice:12x12,
#: 120 robots, 0.15 m/s, kinematic) robots that never gave up would wait for minutes.
#: Queues form in small teams too, behind a hub: some of the stress grid's runs give up
#: places (``python -m mjswarm.experiments.stress``; wheel:8 most), and every run passes
#: (``docs/exploration.md``).
GIVE_UP_S = 120.0


class EntryRequest(NamedTuple):
    """Robot → station: let me leave my vertex along the edge at ``angle_rad``
    (``part_way``: only onto its lane, not into the vertex at the far end)."""

    angle_rad: float
    part_way: bool = False


class Withdraw(NamedTuple):
    """Robot → station: drop my request, or take back the vertex you granted me; I have
    not left my vertex."""


class TurnedBack(NamedTuple):
    """Robot → station: I walk back along my edge; free the vertex ahead, give me the one
    I left (``from_lane``: I turned on my lane; else I am still in its area)."""

    from_lane: bool


class EntryGranted(NamedTuple):
    """Station → robot: go; ``clear`` says whether the vertex ahead is already clear;
    ``angle_rad`` is the request's (None: the vertex it walks back to)."""

    clear: bool
    angle_rad: float | None = None


class EntryDenied(NamedTuple):
    """Station → robot: no edge of the vertex lies along the angle asked for."""

    reason: str


class VertexClear(NamedTuple):
    """Station → robot: the previous holder of the vertex ahead has left its area."""


class LeftVertex(NamedTuple):
    """Robot → station: I am in my corridor; the vertex I left is free."""


class Halted(NamedTuple):
    """Robot → station: I stopped for good (``reason``); release what I hold."""

    reason: str


class GiveUp(NamedTuple):
    """Robot → station: I have waited ``GIVE_UP_S`` for my request; drop it unless it is
    granted (step 8)."""


class EntryBusy(NamedTuple):
    """Station → robot: your request for the edge at ``angle_rad`` was still waiting and
    is dropped (an answer to :class:`GiveUp`, step 8); you have not left."""

    angle_rad: float


class EntryBlocked(NamedTuple):
    """Station → robot: the vertex along the edge at ``angle_rad`` (the request's angle)
    is closed: a body that stopped for good stands in its area (step 7). The station
    learns it from the switch-off in our runs; a real station would from the body's
    silence in its area. The vertex is not named: robots know no true ids."""

    angle_rad: float
