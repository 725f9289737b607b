"""The documentation's references, generated from the code so that they cannot drift.

- :mod:`~cosim.reference.keys_page`: every scenario key of every registered section;
- :mod:`~cosim.reference.tables_page`: every table a run can write, with its columns' meanings;
- :mod:`~cosim.reference.summary_page`: every ``summary.json`` key, its unit, meaning and writer;
- :mod:`~cosim.reference.commands_page`: the command line, from its own parser;
- :mod:`~cosim.reference.registries_page`: every registered implementation.

Each quotes what the code says through :mod:`~cosim.reference.escaping`, so that it shows
as written (``/<robot>/cmd_vel`` is no HTML tag). ``docs/gen_reference.py`` writes them
into the site when ``make docs`` builds it.
"""
