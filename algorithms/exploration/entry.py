"""Vertex entry: the messages between a robot and the vertex stations.

Seed 003 emulated beacons with a central station over XBee that kept "separate
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

A station serves the beacon of its vertex only to the robot it granted (or launched
there): a robot that arrives anywhere else finds no beacon and stops.
"""

from __future__ import annotations

from typing import NamedTuple

#: The address of the vertex stations.
STATION = "station"


class EntryRequest(NamedTuple):
    """Robot → station: let me leave my vertex along the edge at ``angle_rad``."""

    angle_rad: float


class EntryGranted(NamedTuple):
    """Station → robot: go; ``clear`` says whether the vertex ahead is already clear."""

    clear: bool


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
