import itertools
import threading

import numpy as np
import pytest

from adapters.humans.session import SumoSession, angle_of_yaw, yaw_of_angle
from cosim.core.errors import BridgeError


def _trajectories(config, steps=200):
    session = SumoSession(config, seed=5)
    try:
        seen = []
        for k in range(1, steps + 1):
            session.step(k * 0.1)
            assert session.time_s == pytest.approx(k * 0.1)  # lockstep: no lookahead
            people, vehicles = session.people(), session.vehicles()
            seen.append((people.names, people.x_m.copy(), people.y_m.copy(), vehicles.names))
        return session.in_process, seen
    finally:
        session.close()


def _same(a, b):
    assert len(a) == len(b)
    for (na, xa, ya, va), (nb, xb, yb, vb) in zip(a, b, strict=True):
        assert na == nb and va == vb
        np.testing.assert_array_equal(xa, xb)
        np.testing.assert_array_equal(ya, yb)


def test_people_and_forklifts_move_and_the_same_seed_repeats_them_exactly(sumo_files):
    in_process, first = _trajectories(sumo_files)
    assert in_process
    names, _, _, vehicles = first[-1]
    assert len(names) == 6 and sorted(vehicles) == ["forklift_0", "forklift_1"]
    assert not np.allclose(first[10][1], first[-1][1])  # they walked
    _same(first, _trajectories(sumo_files)[1])


@pytest.mark.slow
def test_a_second_simulation_at_once_runs_sumo_in_a_child_process_with_the_same_result(sumo_files):
    results = {}

    def go(key):
        results[key] = _trajectories(sumo_files)

    threads = [threading.Thread(target=go, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(r[0] for r in results.values()) == [False, True]
    _same(results[0][1], results[1][1])
    # libsumo is free again afterwards
    assert _trajectories(sumo_files, steps=1)[0]


def test_a_demand_sumo_refuses_is_one_line_with_sumos_reason_and_frees_libsumo(sumo_files):
    routes = sumo_files.with_name("humans.rou.xml")
    routes.write_text(routes.read_text().replace('from="e', 'from="nowhere', 1))
    with pytest.raises(BridgeError) as error:
        SumoSession(sumo_files, seed=1)
    message = str(error.value)
    assert message.startswith("SUMO failed to load: ")
    assert "nowhere" in message and "\n" not in message
    routes.write_text(routes.read_text().replace('from="nowhere', 'from="e', 1))
    session = SumoSession(sumo_files, seed=1)
    assert session.in_process
    session.close()


def test_a_missing_person_is_a_bridge_error_not_a_libsumo_exception(sumo_files):
    session = SumoSession(sumo_files, seed=1)
    try:
        with (
            pytest.raises(BridgeError, match="SUMO failed to read"),
            session.errors("read a person"),
        ):
            session._api.person.getPosition("nobody")
    finally:
        session.close()


@pytest.mark.parametrize("yaw", [0.0, 0.5, np.pi / 2, -np.pi / 2, 3.0, -3.0])
def test_sumo_headings_and_yaw_convert_both_ways(yaw):
    assert yaw_of_angle(np.array([angle_of_yaw(yaw)]))[0] == pytest.approx(yaw)


def test_sumo_north_is_yaw_pi_over_two():
    assert yaw_of_angle(np.array([0.0, 90.0]))[:] == pytest.approx([np.pi / 2, 0.0])


def test_a_robot_far_from_every_lane_is_still_mirrored_where_it_is(sumo_files):
    session = SumoSession(sumo_files, seed=1)
    try:
        session.add_robots(["robot_1", "robot_2"], "e0")
        x, y = np.array([-6.0, 15.0]), np.array([5.0, 2.0])  # 6 m outside the hall; an aisle
        for k in range(1, 40):  # placed every step: a mirror left alone would drive off
            session.move_robots(x, y, np.array([0.0, np.pi / 2]))
            session.step(k * 0.1)
        for i, name in enumerate(["robot_1", "robot_2"]):
            px, py = session._api.vehicle.getPosition(name)
            assert (px, py) == pytest.approx((x[i], y[i]), abs=0.05)
        assert not {"robot_1", "robot_2"} & set(session.vehicles().names)  # not forklifts
    finally:
        session.close()


def test_a_paced_walker_stops_at_zero_and_walks_on_at_their_own_speed_when_freed(
    walkers_only,
):
    session = SumoSession(walkers_only, seed=1)
    try:
        for k in range(1, 60):
            session.step(k * 0.1)
        people = session.people()
        k_walking = int(np.argmax(people.speed_mps))
        name = people.names[k_walking]
        assert people.speed_mps[k_walking] > 0.5
        assert people.staying is not None and not people.staying[k_walking]
        own = session._api.person.getMaxSpeed(name)
        session.pace([name], np.array([0.01]))  # below the pace step: standing
        for k in range(60, 90):
            session.step(k * 0.1)
        held = session.people()
        at = held.names.index(name)
        assert held.speed_mps[at] == 0.0
        assert (held.x_m[at], held.y_m[at]) == (people.x_m[k_walking], people.y_m[k_walking])
        session.pace([name], np.array([0.4]))
        paced = []
        for k in range(90, 96):
            session.step(k * 0.1)
            paced.append(session._api.person.getSpeed(name))
        assert 0.25 < max(paced) <= 0.4 + 1e-9, paced  # never faster than the limit
        session.pace([name], np.array([np.inf]))
        assert session._api.person.getMaxSpeed(name) == pytest.approx(own)
        speeds = []
        for k in range(96, 110):
            session.step(k * 0.1)
            speeds.append(session._api.person.getSpeed(name))
        assert max(speeds) > 0.5, speeds
    finally:
        session.close()


def test_a_paced_forklift_brakes_to_a_stop_and_drives_on_when_freed(sumo_files):
    session = SumoSession(sumo_files, seed=1)
    try:
        k = 1
        while k < 300:  # until some forklift drives
            session.step(k * 0.1)
            k += 1
            drivers = session.vehicles()
            if len(drivers.names) and drivers.speed_mps.max() > 1.0:
                break
        fast = int(np.argmax(drivers.speed_mps))
        name = drivers.names[fast]
        assert drivers.speed_mps[fast] > 1.0
        session.pace_vehicles([name], np.array([0.0]))
        speeds = []
        for j in range(k, k + 20):
            session.step(j * 0.1)
            speeds.append(session._api.vehicle.getSpeed(name))
        assert speeds[-1] == 0.0, speeds
        # braking within the type's 2 m/s^2: no step loses more than 0.2 m/s
        assert all(a - b <= 0.2 + 1e-9 for a, b in itertools.pairwise(speeds)), speeds
        session.pace_vehicles([name], np.array([np.inf]))
        freed = []
        for j in range(k + 20, k + 50):
            session.step(j * 0.1)
            if name in session.vehicles().names:
                freed.append(session._api.vehicle.getSpeed(name))
        assert max(freed) > 0.5, freed
    finally:
        session.close()
