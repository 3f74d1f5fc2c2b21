"""``python -m hrgtc.cli``: the ``hrgtc`` command."""

from hrgtc.cli import main

main()
