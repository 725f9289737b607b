"""Scenario presets shipped with cosim (one TOML file each)."""
