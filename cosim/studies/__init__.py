"""Studies: sweeps of a scenario over overrides and seeds, on local processes or Dask."""

from cosim.studies.runner import run_study
from cosim.studies.spec import StudySpec
from cosim.studies.validate import load_study

__all__ = ["StudySpec", "load_study", "run_study"]
