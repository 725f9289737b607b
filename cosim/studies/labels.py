"""Axis labels in words and units for study columns (summary metrics and grid keys).

A study's results name their columns as the code does (``tasks_per_min``,
``network.latency_ms``); a figure's reader wants "Tasks per minute" and "Network latency (ms)".
:func:`axis_label` looks a column up in :data:`LABELS` and otherwise builds a label from the
name: the section of a dotted key and the words of the name, the unit suffix in brackets.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

LABELS: Mapping[str, str] = MappingProxyType(
    {
        # throughput, assignment
        "tasks_per_min": "Tasks per minute",
        "tasks_completed": "Tasks completed",
        "mean_task_latency_s": "Mean task latency (s)",
        "mean_convergence_time_s": "Mean convergence time (s)",
        "optimality_gap": "Optimality gap (vs Hungarian optimum)",
        "conflicts": "Conflicts (tasks claimed twice)",
        "epochs_incomplete": "Epochs not converged",
        "messages_sent": "Messages sent",
        "messages_dropped": "Messages dropped",
        "network_messages": "Network messages",
        "network_bytes": "Network bytes (B)",
        # navigation, traffic
        "collisions": "Collisions",
        "min_clearance_m": "Smallest robot clearance (m)",
        "path_length_ratio": "Path length / shortest path",
        "arrivals": "Goals reached",
        "goals_per_min": "Goals reached per minute",
        "agent_arrivals": "Goals reached (learning agents)",
        "agents.policy": "Agents' policy",
        "robots.driver": "Robot software (driver)",
        "goals_missed": "Goals missed",
        "mean_time_to_goal_s": "Mean time to goal (s)",
        "stuck_halted": "Robots halted (stuck)",
        "stuck_detoured": "Robots detoured (stuck)",
        "stuck_slowed": "Robots slowed (stuck)",
        "navigation.controller": "Local controller",
        "navigation.planner": "Global planner",
        "near_misses": "Near misses (robot < 0.1 m from anything)",
        "stuck_s": "Time stuck (s)",
        "time_lost_s": "Time lost vs shortest way at full speed (s)",
        "time_lost_max_s": "Largest time lost, one goal (s)",
        "arrivals_over_twice": "Goals taking over twice their time",
        "mean_abs_jerk_mps3": "Mean jerk (m/s³)",
        "mean_abs_yaw_jerk_radps3": "Mean yaw jerk (rad/s³)",
        "controller_us_per_robot": "Controller time per robot (µs)",
        "controller_ms_per_tick": "Controller time per tick (ms)",
        # people
        "humans_near_misses": "Near misses (person < 0.5 m)",
        "humans_robot_stops": "Robot stops for people",
        "humans_min_distance_m": "Smallest person-robot gap (m)",
        "humans_collisions": "Person-robot contacts",
        "humans_collisions_robot_moving": "Contacts with a moving robot",
        "humans_task_latency_met_people_s": "Task latency, met people (s)",
        "humans_task_latency_clear_s": "Task latency, no people met (s)",
        "humans_yields": "People waiting for a robot",
        "humans_trips": "People's trips done",
        # mapping
        "map_coverage": "Map coverage (share of free space)",
        "map_iou": "Map IoU (vs ground truth)",
        "map_iou_strict": "Map IoU, strict",
        "map_accuracy": "Map cell accuracy",
        "map_ate_m": "Trajectory error, SLAM (m)",
        "map_ate_odom_m": "Trajectory error, odometry (m)",
        "map_merges": "Map merges",
        "map_share_bytes": "Map sharing bytes (B)",
        "map_merge_delay_s_mean": "Mean map merge delay (s)",
        "coverage": "Map coverage (share of free space)",
        "iou": "Map IoU (vs ground truth)",
        "ate_m": "Trajectory error (m)",
        "v_mps": "Robot speed (m/s)",
        "t_s": "Simulated time (s)",
        # cost of the simulation
        "real_time_factor": "Real-time factor (x real time)",
        "wall_time_s": "Wall-clock time (s)",
        "wall_us_per_robot_s": "Wall time per robot-second (µs)",
        # grid keys and derived columns
        "seed": "Seed",
        "loss_rate_configured": "Configured loss rate",
        "network.latency_ms": "Network latency (ms)",
        "network.loss_prob": "Message loss probability",
        "network.loss_model": "Loss model",
        "network.profile": "Network profile",
        "network.bandwidth_mbps": "Network bandwidth (Mbit/s)",
        "network.backend": "Network (backend)",
        "assignment.protocol": "Assignment protocol",
        "humans.workers": "Workers on the floor",
        "mapping.share": "Map sharing",
        "mapping.scan_matching": "Scan matching",
        "robots.count": "Robots",
        "navigation.traffic": "Traffic planner",
        "navigation.robots_layer": "Robots layer (others' footprints)",
        "world.layout": "Shelf layout",
        "world.shelf_count": "Shelves",
    }
)
"""Labels of the columns the shipped studies (``studies/*.toml``) plot, by column name."""

UNITS: tuple[tuple[str, str], ...] = (
    ("_per_min", "per min"),
    ("_mbps", "Mbit/s"),
    ("_mps", "m/s"),
    ("_ms", "ms"),
    ("_us", "µs"),
    ("_hz", "Hz"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_pct", "%"),
    ("_bytes", "B"),
    ("_m2", "m²"),
    ("_m", "m"),
    ("_s", "s"),
)
"""Name suffixes and the unit they carry, longest match first."""

WORDS: Mapping[str, str] = MappingProxyType({"prob": "probability", "p50": "median"})
"""Abbreviations in column names spelt out in labels."""


def axis_label(column: str) -> str:
    """A label in words with its unit for a column of a study's results.

    Known columns (:data:`LABELS`) get their label; others are built from the name:
    ``humans_min_distance_m`` -> ``"Humans min distance (m)"``, ``network.jitter_ms`` ->
    ``"Network jitter (ms)"``, ``foo_per_min`` -> ``"Foo (per min)"``.
    """
    if column in LABELS:
        return LABELS[column]
    name = column.replace(".", "_")
    unit = ""
    for suffix, text in UNITS:
        if name.endswith(suffix) and len(name) > len(suffix):
            name, unit = name[: -len(suffix)], text
            break
    words = [WORDS.get(word, word) for word in name.split("_") if word]
    text = " ".join(words) or column
    text = text[:1].upper() + text[1:]
    return f"{text} ({unit})" if unit else text


def short_label(column: str) -> str:
    """:func:`axis_label` without its unit, for legend titles and panel titles."""
    label = axis_label(column)
    return label.rsplit(" (", 1)[0] if label.endswith(")") else label


def with_unit(column: str, value: str) -> str:
    """``column = value`` in words with the column's unit: ``"Network bandwidth = 1 Mbit/s"``."""
    label = axis_label(column)
    unit = label.rsplit(" (", 1)[1][:-1] if label.endswith(")") and " (" in label else ""
    return f"{short_label(column)} = {value}" + (f" {unit}" if unit else "")
