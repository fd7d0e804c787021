"""``python -m pendverify``: the ``pendverify`` command."""

import sys

from pendverify.cli import main

sys.exit(main())
