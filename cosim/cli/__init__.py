"""The ``cosim`` command line: argument parsing, the commands and the progress line."""
