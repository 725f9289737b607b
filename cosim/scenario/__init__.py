"""Scenario files: typed sections, validation, presets and overrides."""

from cosim.scenario.loader import (
    dump_scenario,
    load_scenario,
    parse_override,
    preset_names,
    preset_summary,
    scenario_from_text,
)
from cosim.scenario.model import Scenario

__all__ = [
    "Scenario",
    "dump_scenario",
    "load_scenario",
    "parse_override",
    "preset_names",
    "preset_summary",
    "scenario_from_text",
]
