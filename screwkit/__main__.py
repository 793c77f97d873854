"""``python -m screwkit``: the same as the ``screwkit`` command (and ``python -m screwkit.cli``)."""

from screwkit.cli import main

main()
