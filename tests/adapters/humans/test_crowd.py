"""The people now (adapters.humans.crowd): what other adapters read after every SUMO step."""

from adapters.humans.crowd import People


def test_before_sumo_places_anyone_the_crowd_is_empty_and_lidars_see_no_disc():
    people = People()
    assert (people.names, people.kinds, people.disc_names) == ([], [], [])
    for column in (people.x_m, people.y_m, people.yaw_rad, people.speed_mps):
        assert column.shape == (0,)
    assert people.discs.shape == (0, 3)  # x_m, y_m, radius_m: stacks with SUMO's discs
    assert (people.forklift_size_m, people.worker_radius_m) == ((0.0, 0.0), 0.0)
