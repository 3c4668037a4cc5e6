"""Kobayashi et al.'s role switching (Algorithm 1), recovery and the patrol mission."""

from __future__ import annotations

import json
import math

import networkx as nx
import numpy as np
import pytest

from algorithms.maintenance.roles import (
    ChildAt,
    Connections,
    Detected,
    Lead,
    LeaderInfo,
    Query,
    Role,
    RoleParams,
    RoleSwitchingRobot,
    State,
    Target,
    TargetReached,
)
from algorithms.robot import Detection, Message, Observation
from mjswarm.cli import main
from mjswarm.experiments.patrol import run_trial

P = RoleParams()


def _state(role, x, degree):
    return State(role, tuple(x), (0.0, 0.0), degree, None, None, None, -1)


def _leader(parent_role=Role.REPEATER, parent_at=(0.0, 0.0)):
    ll = RoleSwitchingRobot(1, Role.LOCAL_LEADER, P, parent=0, connections={0})
    return ll, {0: Detected(np.array(parent_at), parent_role)}


def test_far_leader_hands_its_role_to_the_child_with_most_connections():
    ll, detected = _leader()
    x = np.array([0.9 * P.d_c, 0.0])
    kids = {2: (3.0, 0.5), 3: (3.2, -0.4), 4: (2.5, 0.8)}
    for k, xy in kids.items():
        detected[k] = Detected(np.array(xy), Role.EXPLORER)
    ll.connections |= set(kids)
    inbox = [(2, _state(Role.EXPLORER, kids[2], 2)), (3, _state(Role.EXPLORER, kids[3], 5)),
             (4, _state(Role.EXPLORER, kids[4], 4))]
    _, out = ll.tick(1, x, detected, inbox)
    assert ll.role is Role.REPEATER and ll.child == 3
    assert (3, Lead(1)) in out
    assert ll.connections == {0, 3}


def test_far_leader_without_children_holds_still():
    ll, detected = _leader()
    u, _ = ll.tick(1, np.array([0.9 * P.d_c, 0.0]), detected, [])
    assert ll.role is Role.LOCAL_LEADER and not np.any(u)


def test_near_leader_returns_the_role_to_its_repeater_parent_once_armed():
    ll, detected = _leader()
    ll.tick(1, np.array([1.0, 0.0]), detected, [])  # arms line 5
    _, out = ll.tick(2, np.array([0.3, 0.0]), detected, [])
    assert ll.role is Role.EXPLORER and (0, Lead(None)) in out
    assert 0 in ll.connections  # kept through the hand-over


def test_a_fresh_leader_near_its_parent_does_not_hand_straight_back():
    ll, detected = _leader()
    ll.tick(1, np.array([0.3, 0.0]), detected, [])
    assert ll.role is Role.LOCAL_LEADER


def test_leader_next_to_the_base_station_keeps_its_role():
    ll, detected = _leader(Role.BASE_STATION)
    ll.tick(1, np.array([1.0, 0.0]), detected, [])
    ll.tick(2, np.array([0.3, 0.0]), detected, [])
    assert ll.role is Role.LOCAL_LEADER


def test_disconnected_explorer_heads_for_the_origin_then_for_the_repeaters_child():
    ex = RoleSwitchingRobot(5, Role.EXPLORER, P)
    ex.leader = LeaderInfo(0, (9.0, 9.0), (0.0, 0.0))
    x = np.array([4.0, 3.0])
    detected = {7: Detected(np.array([2.0, 2.0]), Role.REPEATER),
                0: Detected(np.array([1.5, 0.5]), Role.BASE_STATION)}
    u, out = ex.tick(P.leader_expiry_steps + 5, x, detected, [])
    assert ex.disconnected(P.leader_expiry_steps + 5)
    assert (7, Query()) in out  # the nearest of the chain
    assert np.allclose(u, -P.v_max * x / np.linalg.norm(x))
    u, _ = ex.tick(P.leader_expiry_steps + 6, x, detected, [(7, ChildAt((6.0, 3.0)))])
    assert np.allclose(u, [P.v_max, 0.0])


def test_repeater_answers_where_its_child_is():
    rp = RoleSwitchingRobot(7, Role.REPEATER, P, parent=0, child=8)
    detected = {0: Detected(np.zeros(2), Role.BASE_STATION),
                8: Detected(np.array([4.0, 2.0]), Role.LOCAL_LEADER)}
    _, out = rp.tick(3, np.array([2.0, 1.0]), detected, [(5, Query())])
    assert (5, ChildAt((4.0, 2.0))) in out


def test_the_base_station_takes_the_next_target_the_tick_after_it_hears_the_arrival():
    """Targets come as messages, one ahead; the arrival goes out as an event (Sect. IV-B)."""
    first, second = Target(0, (4.0, 4.0)), Target(1, (1.0, 5.0))
    base = RoleSwitchingRobot(0, Role.BASE_STATION, P, child=1, connections={1}, target=first)
    leader = {1: Detection(math.sqrt(2.0), math.pi / 4, Role.LOCAL_LEADER)}

    def step(tick, *inbox):
        command = base.step(Observation(0, tick * base.step_s, pose=(0.0, 0.0, 0.0),
                                        detections=leader, inbox=inbox))
        return [m.payload.target for m in command.messages], command.events

    assert step(0, Message(second, 0, "control")) == ([first], (Connections(frozenset({1})),))
    arrived = Message(State(Role.LOCAL_LEADER, (4.0, 4.0), (0.0, 0.0), 1, None, None, first, 0),
                      0, 1)
    assert step(1, arrived) == ([first], (TargetReached(0),))
    assert step(2, arrived) == ([second], ())  # reported once, switched the tick after
    done = arrived._replace(payload=arrived.payload._replace(target=second, arrived=1))
    assert step(3, done) == ([second], (TargetReached(1),))
    assert step(4) == ([None], ())  # no target sent yet: none


@pytest.mark.parametrize("seed", range(4))
def test_patrol_leader_stays_connected_to_the_base_station_but_for_short_gaps(seed):
    result = run_trial(10, seed, "point", steps=600, keep_history=True)
    assert result.targets_reached >= 1
    assert max(result.leader_gaps, default=0) <= 3  # hand-over latency only
    assert max(result.recovery_steps, default=0) <= 60
    roles = result.history["roles"]
    assert all(r.count("local leader") <= 1 and r[0] == "base station" for r in roles)
    assert any("repeater" in r for r in roles)
    g = nx.Graph(result.history["edges"][-1])
    g.add_nodes_from(range(10))
    assert nx.is_connected(g) or result.recovery_steps  # a late cut is counted, not hidden


def test_patrol_cli_json_and_errors(capsys):
    assert main(["experiment", "patrol", "--world", "point", "--robots", "6",
                 "--steps", "120", "--json", "-"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("disconnections_per_trial", "mean_recovery_steps",
                "processing_s_per_robot_step", "messages_per_robot_step",
                "algebraic_connectivity", "aat_robots", "aat_every_step"):
        assert key in data
    assert data["aat_robots"]["angle_tests_per_robot_step"] <= \
        data["aat_every_step"]["angle_tests_per_robot_step"]
    assert main(["experiment", "patrol", "--world", "point", "--robots", "2"]) == 2
    assert "--robots must be a whole number >= 3" in capsys.readouterr().err


@pytest.mark.slow
def test_embodied_patrol_keeps_the_leader_connected():
    result = run_trial(6, 0, "embodied", steps=400)
    assert max(result.leader_gaps, default=0) <= 3
    assert max(result.recovery_steps, default=0) <= 60
