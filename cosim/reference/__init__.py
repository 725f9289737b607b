"""The documentation's references, generated from the code so that they cannot drift.

- :mod:`~cosim.reference.keys`: every scenario key of every registered section;
- :mod:`~cosim.reference.tables`: every table a run can write, with its columns' meanings;
- :mod:`~cosim.reference.commands`: the command line, from its own parser;
- :mod:`~cosim.reference.registries`: every registered implementation.

``docs/gen_reference.py`` writes them into the site when ``make docs`` builds it.
"""
