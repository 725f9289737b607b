"""Running a scenario: assembling its adapters, running the kernel, writing the run folder."""
