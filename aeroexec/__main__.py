"""``python -m aeroexec``: the ``aeroexec`` command."""

import sys

from aeroexec.cli.main import main

sys.exit(main())
