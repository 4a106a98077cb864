"""``python -m trials.cli ...``: the ``mmg`` command without the console script."""
import sys

from trials.cli import main

sys.exit(main())
