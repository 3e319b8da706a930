"""``python -m opnav``: the ``opnav`` command (:mod:`opnav.cli`)."""

import sys

from opnav.cli import main

sys.exit(main())
