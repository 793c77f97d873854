"""``python -m screwkit.cli``: the same as the ``screwkit`` command."""

from screwkit.cli import main

main()
